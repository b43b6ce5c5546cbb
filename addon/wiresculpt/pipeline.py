"""The solver pipeline as one function of (mesh, planes, material, settings): slice, pick, and each
stage that exists so far, producing the design document. Free of bpy: the batch script and the
add-on's operators both call it.
"""
import math
import time

from . import native
from .core import contours as contour_rules
from .core.design import new_design, wire_entry


def _normalized(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def slice_planes(vertices, faces, planes, weld_tolerance=None):
    """The contours of every plane: list (per plane) of lists of {"points", "closed", "length"}."""
    specs = [(p.name, p.origin, p.normal) for p in planes]
    result = native.slice_mesh(vertices, faces, specs, -1.0 if weld_tolerance is None else weld_tolerance)
    return result["contours"], result["mesh"]


def run(vertices, faces, planes, material, settings, progress=None):
    """Runs the pipeline. `planes`: objects with name, origin, normal, contours (the rule).
    `progress(stage, message)` is called once per finished stage. Returns the design dict."""
    say = progress or (lambda stage, message: None)
    design = new_design(material, settings)

    start = time.perf_counter()
    per_plane, mesh_info = slice_planes(vertices, faces, planes, settings.get("weld_tolerance"))
    for plane, found in zip(planes, per_plane):
        for k in contour_rules.pick(found, plane.contours, plane.name):
            c = found[k]
            design["wires"].append(wire_entry(len(design["wires"]), f"{plane.name}/{k}", plane.origin,
                                              _normalized(plane.normal), c["closed"], c["points"]))
    seconds = time.perf_counter() - start
    design["stages"]["slicing"] = {
        "seconds": seconds,
        "planes": len(planes),
        "contours": sum(len(found) for found in per_plane),
        "mesh": mesh_info,
    }
    say("slicing", f"{len(planes)} planes, {design['stages']['slicing']['contours']} contours, "
                   f"{len(design['wires'])} wires ({seconds:.3f} s)")
    if not design["wires"]:
        design["reason"] = "no plane cuts the mesh: move the planes through the mesh"
        return design

    design["reason"] = ("not computed yet: this version slices and picks contours only; layering, "
                        "target shape, forces and rest shape do not exist yet")
    return design
