"""Fabrication files for a finished design (Sec. 5.1): per wire a bend program, a 1:1 SVG
template, G-code and a CSV bend table, plus one SVG sheet and one DXF with a layer per wire.
Free of bpy: the batch run and the add-on's Export operator both call it. Every file is written
atomically by the native writers.
"""
import os
import re

import numpy as np

from .. import native
from ..core.calibration import machine_dict
from ..core.polylines import self_crossings

FOLDERS = ("svg", "dxf", "gcode", "bends")


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
    out = native.require().default_machine_profile()
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


EXTENSIONS = (".svg", ".dxf", ".gcode", ".csv")


def file_stem(wire):
    """A wire's file name: its id, then its name made safe ("Equator/0", id 3 -> "03-Equator-0").
    The id keeps names unique where the safe names of two wires would be the same."""
    safe = re.sub(r"[^A-Za-z0-9._-]+", "-", wire["name"]).strip("-")
    return f"{wire['id']:02d}-{safe}" if safe else f"{wire['id']:02d}-wire"


def clear(out_dir):
    """Removes the fabrication files of an earlier export from out_dir's four folders, so what is
    there always belongs to the design written beside it. Other files are left alone."""
    for folder in FOLDERS:
        path = os.path.join(out_dir, folder)
        if os.path.isdir(path):
            for name in os.listdir(path):
                if name.endswith(EXTENSIONS):
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


def export(design, out_dir, profile=None):
    """Writes the fabrication files of every wire that has a rest shape into out_dir/{svg, dxf,
    gcode, bends}, with the machine `profile` (None: the default; see machine_profile). Returns
    {"files": [paths], "wires": [per-wire program summary], "errors": [one sentence per wire that
    cannot be bent], "notes": [limits where the profile is stricter than the design]}."""
    w = native.require()
    clear(out_dir)
    profile, notes = machine_profile(design, profile)
    material = design["material"].get("name", "")
    files, summaries, errors, templates = [], [], [], []
    wires = [x for x in design["wires"] if "rest" in x]
    for wire in wires:
        rest = np.asarray(wire["rest"], dtype=np.float64)
        try:
            program = w.make_bend_program(rest, profile)
        except ValueError as exc:
            errors.append(f"wire {wire['name']}: {exc}")
            continue
        stem = file_stem(wire)
        template = {"name": wire["name"], "points": rest, "bend_points": list(program["bend_vertices"]),
                    "crossing_points": crossing_indices(design, wire)}
        crosses = self_crossings(rest, wire["closed"])
        if crosses:  # marked on the template: the wire must pass over itself there
            template["self_crossings"] = np.array([c[2] for c in crosses], dtype=np.float64)
        templates.append(template)
        for folder, name, write in (
            ("svg", f"{stem}.svg", lambda p: w.write_svg(p, [template], False)),
            ("gcode", f"{stem}.gcode", lambda p: w.write_gcode(p, rest, profile, wire["name"], material)),
            ("bends", f"{stem}.csv", lambda p: w.write_bend_table(p, rest, profile)),
        ):
            path = os.path.join(out_dir, folder, name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            write(path)
            files.append(path)
        summaries.append({"id": wire["id"], "name": wire["name"], "bend_count": program["bend_count"],
                          "wire_length": program["wire_length"], "machine_seconds": program["machine_seconds"],
                          "shape_error": program["shape_error"]})
    if templates:
        for folder, name, write in (("svg", "sheet.svg", lambda p: w.write_svg(p, templates, True)),
                                    ("dxf", "sculpture.dxf", lambda p: w.write_dxf(p, templates))):
            path = os.path.join(out_dir, folder, name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            write(path)
            files.append(path)
    return {"files": files, "wires": summaries, "errors": errors, "notes": notes}


def summary(result, out_dir):
    """(level, one message) of an export: counts per folder, then each wire's bends, length and
    machine time or the reason it cannot be bent, then the profile notes. level is "INFO",
    "WARNING" (some wire refused or a note) or "ERROR" (no wire written)."""
    counts = {folder: sum(1 for p in result["files"] if os.path.basename(os.path.dirname(p)) == folder)
              for folder in FOLDERS}
    done, refused = result["wires"], result["errors"]
    if not done and not refused:
        return "ERROR", "No wire has a rest shape: optimize until the rest shape stage has run"
    parts = [f"{w['name']}: {w['bend_count']} bends, {w['wire_length'] * 1000:.0f} mm, "
             f"about {w['machine_seconds']:.0f} s" for w in done]
    head = (f"Exported {len(done)} of {len(done) + len(refused)} wires to {out_dir} ("
            + ", ".join(f"{counts[f]} {f}" for f in FOLDERS) + " files)")
    text = "; ".join([head] + parts + [f"not bendable: {e}" for e in refused] + list(result.get("notes", [])))
    level = "ERROR" if not done else "WARNING" if refused or result.get("notes") else "INFO"
    return level, text
