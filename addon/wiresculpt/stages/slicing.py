"""Slicing and contour picking: planes cut the mesh, each plane's rule picks the wires."""
import math
import time

from .. import native
from ..core import contours as contour_rules
from ..core.design import wire_entry


def _normalized(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def slice_planes(vertices, faces, planes, weld_tolerance=None):
    """The contours of every plane: list (per plane) of lists of {"points", "closed", "length"}."""
    specs = [(p.name, p.origin, p.normal) for p in planes]
    result = native.slice_mesh(vertices, faces, specs, -1.0 if weld_tolerance is None else weld_tolerance)
    return result["contours"], result["mesh"]


def run(design, vertices, faces, planes, settings):
    """Adds the picked contours to design["wires"] and stages.slicing; returns a progress line."""
    start = time.perf_counter()
    per_plane, mesh_info = slice_planes(vertices, faces, planes, settings.get("weld_tolerance"))
    for plane, found in zip(planes, per_plane):
        for k in contour_rules.pick(found, plane.contours, plane.name):
            c = found[k]
            design["wires"].append(wire_entry(len(design["wires"]), f"{plane.name}/{k}", plane.origin,
                                              _normalized(plane.normal), c["closed"], c["points"]))
    seconds = time.perf_counter() - start
    contours = sum(len(found) for found in per_plane)
    design["stages"]["slicing"] = {"seconds": seconds, "planes": len(planes), "contours": contours,
                                   "mesh": mesh_info}
    return f"{len(planes)} planes, {contours} contours, {len(design['wires'])} wires ({seconds:.3f} s)"
