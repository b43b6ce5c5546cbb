"""The solver pipeline: slice and pick (from a mesh and planes), then solve (from wires) every
stage that exists so far, producing the design document. Free of bpy: the batch script and the
add-on's operators both call it, the add-on from a worker thread (the native stages release the
GIL) with `cancel` wired to its Esc key.
"""
from . import native
from .core.design import new_design
from .stages import forces, layering, slicing, target_shape

ALL_STAGES = ["layering", "target_shape", "forces", "rest_shape"]


class Cancelled(Exception):
    """The user cancelled; the caller keeps its previous state."""


def _quiet(stage, message):
    pass


def slice_and_pick(vertices, faces, planes, material, settings, progress=None):
    """A new design whose wires are the contours the planes' rules pick. `planes`: objects with
    name, origin, normal, contours (the rule)."""
    design = new_design(material, settings)
    (progress or _quiet)("slicing", slicing.run(design, vertices, faces, planes, settings))
    return design


def solve(design, material, settings, progress=None, cancel=None):
    """Runs every stage after slicing on `design` (its wires' contours set). `progress(stage,
    message)` is called once per finished stage; `cancel()` returning True stops at the next safe
    point with Cancelled. `pending_stages` names the stages that did not run."""
    say = progress or _quiet
    cancelled = cancel or (lambda: False)

    def native_progress(_stage, _fraction):
        return not cancelled()

    def checkpoint():
        if cancelled():
            raise Cancelled()

    design["pending_stages"] = list(ALL_STAGES)
    if len(design["wires"]) < 2:
        design["stable"] = False
        design["reason"] = ("no plane cuts the mesh: move the planes through the mesh" if not design["wires"]
                            else "a sculpture needs at least two wires: add a plane or pick more contours")
        return design
    try:
        checkpoint()
        say("layering", layering.run(design, material, settings, native_progress))
        design["pending_stages"].remove("layering")
        for message in design.get("close_crossings", []):
            say("layering", message)
        checkpoint()
        say("target_shape", target_shape.run(design, material, settings, native_progress))
        design["pending_stages"].remove("target_shape")
        if design["stable"]:  # forces need the hooks of a complete stable assembly
            checkpoint()
            say("forces", forces.run(design, material, settings, native_progress))
            design["pending_stages"].remove("forces")
            say("rest_shape", forces.rest_summary(design))
            design["pending_stages"].remove("rest_shape")
    except native.module.Cancelled:
        raise Cancelled() from None
    return design


def run(vertices, faces, planes, material, settings, progress=None, cancel=None):
    """slice_and_pick then solve: the whole pipeline from a mesh and planes."""
    design = slice_and_pick(vertices, faces, planes, material, settings, progress)
    return solve(design, material, settings, progress, cancel)
