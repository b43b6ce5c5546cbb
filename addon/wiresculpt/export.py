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


def file_stem(name):
    """A wire name as a file name: "Equator/0" -> "Equator-0"."""
    return re.sub(r"[^A-Za-z0-9._-]+", "-", name).strip("-") or "wire"


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
        stem = file_stem(wire["name"])
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
