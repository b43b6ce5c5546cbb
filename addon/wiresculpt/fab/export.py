"""Fabrication files for a finished design (Sec. 5.1), for machines and for people, separately:

    svg/NN-name.svg        machine file: the rest shape as one path, mm, origin at the start
    dxf/NN-name.dxf        machine file: DXF R2000, $INSUNITS mm, one layer, one LWPOLYLINE, origin at the start
    dxf/sculpture.dxf      every wire on its own layer, side by side without overlap
    templates/NN-name.svg  the annotated 1:1 print template (bends, crossings, label)
    templates/sheet.svg    every template on one sheet
    templates/pages/NN-name-A1.svg ...  each template tiled onto A4 (or Letter) pages, 1:1, with a
                           100 mm scale bar and overlap marks (fab/tiles.py)
    gcode/NN-name.gcode    the bend program for a GRBL bender
    bends/NN-name.csv      the bend table
    bendlist/NN-name.txt   the bend list for a DIWire-class machine (FabMo Bend List app; fab/bendlist.py)

A wire longer than the profile's stock_length is bent in pieces (fab/pieces.py): each piece gets
these files under NN-name-piece-K-of-N instead of the wire's.

Free of bpy: the batch run and the add-on's Export operator both call it. Every file is written
atomically by the native writers.
"""
import os
import re
import xml.etree.ElementTree as ET

import numpy as np

from .. import native
from . import bendlist, pieces, tiles
from .pieces import with_overlap  # noqa: F401 (export's name for it)
from ..core.calibration import closed_overlap, machine_dict
from ..core.design import setup_problem
from ..core.files import write_atomic
from ..core import sizes
from ..core.sizes import stock_warnings
from ..core.polylines import self_crossings

# Each folder with the file types an export writes there (and removes from an earlier export).
FOLDER_TYPES = {"svg": (".svg",), "dxf": (".dxf",), "templates": (".svg",),
                os.path.join("templates", "pages"): (".svg",), "gcode": (".gcode",), "bends": (".csv",),
                "bendlist": (".txt",)}
FOLDERS = tuple(FOLDER_TYPES)


# The machine limits a design records, each with the function that picks the stricter of two values.
LIMITS = (("min_segment", max), ("max_bend_deg", min), ("min_bend_deg", max))


def _limit_text(key, value):
    return f"{value * 1000:g} mm" if key == "min_segment" else f"{value:g}°"


def machine_profile(design, profile=None):
    """(native profile dict, notes) for bending the design's wires on a machine.

    `profile`: a machine profile as core.calibration.load_profile returns it (spring-back fit,
    axes, serial settings, its own limits), or None for the default profile. The three machine
    limits (min_segment, max_bend_deg, min_bend_deg) are the stricter of the design's and the
    profile's: the design's target shape was solved against the design's limits, so a looser
    machine changes nothing, while a machine stricter than the design must never be commanded
    beyond what it can do. Each limit where the profile is stricter gives a note (the wires
    that break it are then refused by the bend program, naming the bend or step)."""
    out = native.default_machine_profile()
    notes = []
    if profile is not None:
        out.update(machine_dict(profile))
    name = out.get("name") or "machine profile"
    for key, stricter in LIMITS:
        ours = float(design["machine"][key])
        theirs = float(out[key]) if profile is not None and key in profile else ours
        out[key] = stricter(ours, theirs)
        if abs(out[key] - ours) <= 1e-9 * max(abs(ours), 1.0):  # equal but for a unit round trip
            out[key] = ours
        else:
            notes.append(f"{name}: {key} {_limit_text(key, theirs)} is stricter than the design's "
                         f"{_limit_text(key, ours)} (the shape was solved for {_limit_text(key, ours)}); "
                         f"the machine's limit is used; optimize again with it to fit every wire")
    return out, notes


def file_stem(wire):
    """A wire's file name: its id, then its name made safe ("Equator/0", id 3 -> "03-Equator-0").
    The id keeps names unique where the safe names of two wires would be the same."""
    safe = re.sub(r"[^A-Za-z0-9._-]+", "-", wire["name"]).strip("-")
    return f"{wire['id']:02d}-{safe}" if safe else f"{wire['id']:02d}-wire"


def clear(out_dir):
    """Removes the fabrication files of an earlier export from out_dir's folders (the types an
    export writes in each), so what is there always belongs to the design written beside it.
    Other files are left alone."""
    for folder, types in FOLDER_TYPES.items():
        path = os.path.join(out_dir, folder)
        if os.path.isdir(path):
            for name in os.listdir(path):
                if name.endswith(types):
                    os.remove(os.path.join(path, name))


def crossing_indices(design, wire):
    """Indices into the wire's rest polyline of its crossings (rest starts at the cut)."""
    m = len(wire["target"])
    cut = max(wire["cut"], 0)
    out = []
    for c in design.get("crossings", []):
        for k in (0, 1):
            if c["wires"][k] == wire["id"]:
                out.append((c["vertices"][k] - cut) % m)
    return sorted(out)


def no_rest_reason(design):
    """Why no wire has a rest shape, matching the design's state: a setup problem (fewer than two
    wires, core/design.setup_problem) and an unstable result point at the Stability report, an
    unfinished one at Optimize."""
    if setup_problem(design):
        return f"the design cannot be solved as set up: see Stability ({design['reason']})"
    if design.get("stable") is False and design.get("reason"):
        return f"the design is not stable: see Stability ({design['reason']})"
    return "no wire has a rest shape yet: optimize until the rest shape stage has run"


def made_of(design, wire, plan, overlap):
    """What the machine bends for `wire`: one item, the whole rest shape, or one per piece when
    `plan` (fab/pieces.wire_plan) splits it. Each {"rest" (with a closed wire's overlap on its last
    item), "own" (without it), "closed", "name", "stem", "crossing_points" (indices into "rest"),
    "overlap"}; a piece's also "piece", "pieces", "from" and "to" (m from the cut)."""
    closed = bool(wire.get("closed"))
    if not plan or "pieces" not in plan:
        return [{"rest": with_overlap(wire["rest"], closed, overlap), "own": wire["rest"], "closed": closed,
                 "name": wire["name"], "stem": file_stem(wire), "crossing_points": crossing_indices(design, wire),
                 "overlap": overlap if closed else 0.0}]
    rest = np.asarray(wire["rest"], dtype=np.float64)
    s = pieces.arc_lengths(rest)
    at = [float(s[i]) for i in crossing_indices(design, wire)]
    out, count = [], len(plan["pieces"])
    for k, piece in enumerate(plan["pieces"]):
        line = pieces.piece_polyline(rest, s, piece["from"], piece["to"])
        last = closed and k + 1 == count
        ps = pieces.arc_lengths(line) + piece["from"]
        points = [int(np.argmin(np.abs(ps - a))) for a in at if piece["from"] < a < piece["to"]]
        marks = []  # (from, to) mm along the piece where it overlaps its neighbour at a joint
        length_mm = 1000.0 * (piece["to"] - piece["from"])
        for joint in plan.get("joints") or []:
            if joint["pieces"][1] == k + 1:  # the joint at its start
                marks.append((0.0, 1000.0 * (joint["to"] - piece["from"]), joint["pieces"][0], joint["kind"]))
            if joint["pieces"][0] == k + 1:  # at its end
                marks.append((1000.0 * (joint["from"] - piece["from"]), length_mm, joint["pieces"][1], joint["kind"]))
        out.append({"rest": with_overlap(line, last, overlap), "own": line, "closed": False, "joints": marks,
                    "name": pieces.piece_name(wire, k + 1, count), "stem": f"{file_stem(wire)}-piece-{k + 1}-of-{count}",
                    "crossing_points": points, "overlap": overlap if last else 0.0, "piece": k + 1, "pieces": count,
                    "from": piece["from"], "to": piece["to"]})
    return out


JOINT_COLOUR = "#c06000"  # the joint bands on a piece's template


def mark_joints(path, svg, marks):
    """The template SVG text `svg` with, on each wire group named in `marks` ({piece name:
    ([(from mm, to mm, other piece, kind)], piece count)}), a wide band over each stretch where the
    piece overlaps its neighbour at a joint, labelled; written atomically to `path` (None: not
    written). Returns the text."""
    root = ET.fromstring(svg, parser=ET.XMLParser(target=ET.TreeBuilder(insert_comments=True)))
    ns = "{http://www.w3.org/2000/svg}"
    groups = [g for g in root.iter(f"{ns}g") if g.get("class") == "wire" and g.get("data-name") in marks]
    if not groups:  # nothing to mark: the native's text as it is
        if path is not None:
            write_atomic(path, svg)
        return svg
    for group in groups:
        stretches, count = marks[group.get("data-name")]
        path_el = next(e for e in group if e.get("class") == "wire-path")
        q = np.array([[float(v) for v in pair.split(",")] for pair in path_el.get("points").split()])
        s = pieces.arc_lengths(q)
        for a, b, other, kind in stretches:
            band = pieces.piece_polyline(q, s, max(a, 0.0), min(b, float(s[-1])))
            mark = ET.SubElement(group, f"{ns}g", {"class": "joint", "data-mm": f"{b - a:.4f}", "data-kind": kind,
                                                     "data-other": str(other)})
            ET.SubElement(mark, f"{ns}polyline", {
                "fill": "none", "stroke": JOINT_COLOUR, "stroke-opacity": "0.45", "stroke-width": "2.0000",
                "stroke-linecap": "butt", "points": " ".join(f"{x:.4f},{y:.4f}" for x, y in band)})
            label = ET.SubElement(mark, f"{ns}text", {"x": f"{band[0][0] + 1.5:.4f}", "y": f"{band[0][1] - 1.5:.4f}",
                                                      "font-family": "sans-serif", "font-size": "2.4000",
                                                      "fill": JOINT_COLOUR})
            label.text = f"joint ({kind}): overlaps piece {other} of {count} by {b - a:.1f} mm"
    text = '<?xml version="1.0" encoding="UTF-8" standalone="no"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
    if path is not None:
        write_atomic(path, text)
    return text


def preview_model(native_profile):
    """The words for a spring-back line: "measured = a x commanded + b deg (name)"."""
    return (f"measured = {float(native_profile['springback_a']):.4f} × commanded "
            f"{float(native_profile['springback_b_deg']):+.3f}° ({native_profile.get('name') or 'machine profile'})")


def export(design, out_dir, profile=None, paper=None, machine=None):
    """Writes the fabrication files of every wire that has a rest shape into out_dir/{svg, dxf,
    templates, templates/pages, gcode, bends, bendlist} (see the module's text), with the machine `profile`
    (None: the default; see machine_profile; its "closed_overlap" lengthens every closed wire's
    last feed, with_overlap), the template pages on `paper` ("A4" or "Letter";
    None: the profile's key "paper", else A4). Returns
    {"files": [paths], "wires": [per-wire program summary], "errors": [one sentence per wire that
    cannot be bent], "notes": [limits where the profile is stricter than the design],
    "preview_model": the spring-back line of the preview in words, "preview_springback": its (a, b in
    degrees)}.

    The preview: each wire's program run forward through `machine`'s spring-back
    line (a profile as for `profile`, e.g. the fit the Calibration panel loaded; None: the export
    profile itself, so only the small-bend rule shows), drawn dashed on the annotated template; each
    wire's summary has "predicted" ((k, 2) m, in the rest shape's frame) and "preview_distance" (m,
    the largest distance from the rest shape by arc length)."""
    paper = paper or (profile or {}).get("paper") or "A4"
    tiles.layout(1.0, 1.0, paper)  # an unknown paper is refused before anything is written
    overlap = closed_overlap(profile)  # refused before anything is written
    stock_length, stock_name = sizes.stock(profile or {})
    profile, notes = machine_profile(design, profile)  # and a missing module (RuntimeError)
    made_by = profile if machine is None else machine_profile(design, machine)[0]
    native.validate_machine_profile(made_by)  # a bad model is one message before anything is written
    split = pieces.plans(design, stock_length, overlap, profile)
    planned = {**design, "wires": [{**{k: v for k, v in w.items() if k not in pieces.KEYS}, **(split.get(w["id"]) or {})}
                                   for w in design["wires"]]}
    notes += stock_warnings(planned, stock_length, stock_name)  # a split wire: its pieces; else why not
    clear(out_dir)
    material = design["material"].get("name", "")
    files, summaries, errors, templates = [], [], [], []
    joint_marks = {}  # piece name: its joints' stretches, marked on the templates
    wires = [x for x in design["wires"] if "rest" in x]
    for wire in wires:
        for item in made_of(design, wire, split.get(wire["id"]), overlap):
            rest, name, stem = item["rest"], item["name"], item["stem"]
            try:
                program = native.make_bend_program(rest, profile, made_by)
            except ValueError as exc:
                errors.append(f"wire {name}: {exc}")
                continue
            template = {"name": name, "points": rest, "bend_points": list(program["bend_vertices"]),
                        "crossing_points": item["crossing_points"],
                        "preview": program["predicted"], "preview_distance": program["preview_distance"],
                        "overlap": item["overlap"]}
            crosses = self_crossings(np.asarray(item["own"], dtype=np.float64), item["closed"])  # not the overlap
            if crosses:  # marked on the template: the wire must pass over itself there
                template["self_crossings"] = np.array([c[2] for c in crosses], dtype=np.float64)
            templates.append(template)
            if item.get("joints"):
                joint_marks[name] = (item["joints"], item["pieces"])
            for folder, file_name, write in (
                ("svg", f"{stem}.svg", lambda p: native.write_machine_svg(p, {"name": name, "points": rest})),
                ("dxf", f"{stem}.dxf", lambda p: native.write_dxf(p, [template], layout="start_at_origin")),
                ("templates", f"{stem}.svg", lambda p: mark_joints(p, native.write_svg(None, [template], False),
                                                                   joint_marks)),
                ("gcode", f"{stem}.gcode", lambda p: native.write_gcode(p, rest, profile, name, material)),
                ("bends", f"{stem}.csv", lambda p: native.write_bend_table(p, rest, profile)),
                ("bendlist", f"{stem}.txt",
                 lambda p: bendlist.write_bend_list(p, program, bool(profile.get("left_is_positive", True)))),
            ):
                path = os.path.join(out_dir, folder, file_name)
                os.makedirs(os.path.dirname(path), exist_ok=True)
                text = write(path)
                files.append(path)
                if folder == "templates":
                    files += tiles.write_pages(text, os.path.join(out_dir, "templates", "pages"), stem, name, paper)
            summary = {"id": wire["id"], "name": name, "bend_count": program["bend_count"],
                       "wire_length": program["wire_length"], "machine_seconds": program["machine_seconds"],
                       "shape_error": program["shape_error"], "predicted": np.asarray(program["predicted"]),
                       "preview_distance": program["preview_distance"], "overlap": item["overlap"]}
            if item.get("piece"):
                summary.update(piece=item["piece"], pieces=item["pieces"], **{"from": item["from"], "to": item["to"]})
            summaries.append(summary)
    if templates:
        for folder, name, write in (("templates", "sheet.svg",
                                     lambda p: mark_joints(p, native.write_svg(None, templates, True), joint_marks)),
                                    ("dxf", "sculpture.dxf",
                                     lambda p: native.write_dxf(p, templates, layout="side_by_side"))):
            path = os.path.join(out_dir, folder, name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            write(path)
            files.append(path)
    return {"files": files, "wires": summaries, "errors": errors, "notes": notes, "pieces": split,
            "empty_reason": "" if wires else no_rest_reason(design), "preview_model": preview_model(made_by),
            "preview_springback": (float(made_by["springback_a"]), float(made_by["springback_b_deg"]))}


def summary(result, out_dir):
    """(level, one message) of an export: counts per folder, then each wire's bends, length and
    machine time or the reason it cannot be bent, then the profile notes. level is "INFO",
    "WARNING" (some wire refused or a note) or "ERROR" (no wire written)."""
    counts = {folder: sum(1 for p in result["files"] if os.path.relpath(os.path.dirname(p), out_dir) == folder)
              for folder in FOLDERS}
    done, refused = result["wires"], result["errors"]
    if not done and not refused:
        reason = result.get("empty_reason") or "no wire has a rest shape yet: optimize until the rest shape stage has run"
        return "ERROR", "Nothing to export: " + reason
    parts = [f"{w['name']}: {w['bend_count']} bends, {w['wire_length'] * 1000:.0f} mm, "
             f"about {w['machine_seconds']:.0f} s, predicted within {w['preview_distance'] * 1000:.1f} mm"
             for w in done]
    if done and result.get("preview_model"):
        parts.append(f"prediction by spring-back {result['preview_model']}")
    head = (f"Exported {len(done)} of {len(done) + len(refused)} wires to {out_dir} ("
            + ", ".join(f"{counts[f]} {f}" for f in FOLDERS) + " files)")
    text = "; ".join([head] + parts + [f"not bendable: {e}" for e in refused] + list(result.get("notes", [])))
    level = "ERROR" if not done else "WARNING" if refused or result.get("notes") else "INFO"
    return level, text
