"""The solver pipeline as one function of (mesh, planes, material, settings): slice, pick, and each
stage that exists so far, producing the design document. Free of bpy: the batch script and the
add-on's operators both call it.
"""
import math
import time

import numpy as np

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


def layering_settings(material, settings):
    """The native layering stage's settings from the design's material and settings."""
    return {
        "min_segment": settings["min_segment"],
        "friction": material["friction"],
        "contact_angle": math.radians(settings["contact_angle_deg"]),
    }


def run_layering(design, material, settings, progress=None):
    """Crossings, hooks and assembly order (Sec. 4.1-4.2) into `design`. Returns the native result."""
    wires = [{"name": w["name"], "origin": w["plane"]["origin"], "normal": w["plane"]["normal"],
              "points": np.asarray(w["contour"], dtype=np.float64), "closed": w["closed"]}
             for w in design["wires"]]
    result = native.require().layering(wires, layering_settings(material, settings), progress)
    net = result["network"]
    for wire, solved in zip(design["wires"], net["wires"]):
        wire["contour"] = solved["points"].tolist()  # the sliced contour with its crossing points inserted
    design["crossings"] = [
        {"id": c["id"], "wires": list(c["wires"]), "contour_vertices": list(c["vertices"]),
         "point": list(c["point"]), "hook": c["hook"], "metric": result["metric"][c["id"]]}
        for c in net["crossings"]
    ]
    design["assembly_order"] = list(result["assembly_order"])
    design["assembly_steps"] = [list(s) for s in result["steps"]]
    design["two_hand_steps"] = list(result["two_hand_steps"])
    design["stable"] = bool(result["stable"])
    design["reason"] = result["reason"]
    design.setdefault("warnings", []).extend(result["warnings"])
    if net["close_crossings"]:
        design["close_crossings"] = [g["message"] for g in net["close_crossings"]]
        design["required_size"] = net["required_size"]
    stats = result["stats"]
    design["stages"]["layering"] = {
        "seconds": stats["seconds"], "lp_solves": stats["lp_solves"], "nodes": stats["nodes"],
        "complete_search": result["complete_search"], **result["objective"],
    }
    return result


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
    if len(design["wires"]) < 2:
        design["pending_stages"] = ["layering", "target_shape", "forces", "rest_shape"]
        design["reason"] = ("no plane cuts the mesh: move the planes through the mesh" if not design["wires"]
                            else "a sculpture needs at least two wires: add a plane or pick more contours")
        return design

    lay = run_layering(design, material, settings)
    stage = design["stages"]["layering"]
    say("layering", f"{len(design['crossings'])} crossings, "
                    f"{'stable' if design['stable'] else 'not stable'}, order {design['assembly_order']}, "
                    f"{stage['lp_solves']} LPs, {stage['nodes']} nodes ({stage['seconds']:.3f} s)")
    for message in design.get("close_crossings", []):
        say("layering", message)
    # Stages this version does not have yet: named, never filled in.
    design["pending_stages"] = ["target_shape", "forces", "rest_shape"]
    if lay["stable"]:
        say("pending", "target shape, forces and rest shape are not computed by this version")
    return design
