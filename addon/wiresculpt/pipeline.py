"""The solver pipeline as one function of (mesh, planes, material, settings): each stage that
exists so far, in order, producing the design document. Free of bpy: the batch script and the
add-on's operators both call it.
"""
from .core.design import new_design
from .stages import layering, slicing, target_shape

ALL_STAGES = ["layering", "target_shape", "forces", "rest_shape"]


def run(vertices, faces, planes, material, settings, progress=None):
    """Runs the pipeline. `planes`: objects with name, origin, normal, contours (the rule).
    `progress(stage, message)` is called once per finished stage. Returns the design dict;
    `pending_stages` names the stages that did not run (never filled with placeholders)."""
    say = progress or (lambda stage, message: None)
    design = new_design(material, settings)
    design["pending_stages"] = list(ALL_STAGES)

    say("slicing", slicing.run(design, vertices, faces, planes, settings))
    if len(design["wires"]) < 2:
        design["reason"] = ("no plane cuts the mesh: move the planes through the mesh" if not design["wires"]
                            else "a sculpture needs at least two wires: add a plane or pick more contours")
        return design

    say("layering", layering.run(design, material, settings))
    design["pending_stages"].remove("layering")
    for message in design.get("close_crossings", []):
        say("layering", message)

    say("target_shape", target_shape.run(design, material, settings))
    design["pending_stages"].remove("target_shape")

    if design["stable"]:
        say("pending", "forces and rest shape are not computed by this version")
    return design
