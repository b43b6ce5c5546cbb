"""Fabrication files for a finished design (Sec. 5.1): per wire a bend program, a 1:1 SVG
template, G-code and a CSV bend table, plus one SVG sheet and one DXF with a layer per wire.
Free of bpy: the batch run and the add-on's Export operator both call it. Every file is written
atomically by the native writers.
"""
import os
import re

import numpy as np

from . import native

FOLDERS = ("svg", "dxf", "gcode", "bends")


def machine_profile(design):
    """The default machine profile with the design's machine limits."""
    profile = native.require().default_machine_profile()
    profile.update({k: design["machine"][k] for k in ("min_segment", "max_bend_deg", "min_bend_deg")})
    return profile


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


def export(design, out_dir):
    """Writes the fabrication files of every wire that has a rest shape into out_dir/{svg, dxf,
    gcode, bends}. Returns {"files": [paths], "wires": [per-wire program summary], "errors":
    [one sentence per wire that cannot be bent]}."""
    w = native.require()
    clear(out_dir)
    profile = machine_profile(design)
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
    return {"files": files, "wires": summaries, "errors": errors}
