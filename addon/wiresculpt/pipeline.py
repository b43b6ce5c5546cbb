"""The solver pipeline: slice and pick (from a mesh and planes), then solve (from wires) every
stage that exists so far, producing the design document. Free of bpy: the batch script and the
add-on's operators both call it, the add-on from a worker thread (the native stages release the
GIL) with `cancel` wired to its Esc key.
"""
from . import native
from .core.design import new_design
from .core.sizes import size_warnings
from .stages import forces, layering, slicing, target_shape

ALL_STAGES = ["layering", "target_shape", "forces", "rest_shape"]
COUPLING_ROUNDS = 4  # target shape <-> rest shape iterations (Sec. 4.3)
COUPLING_MARGIN_DEG = 0.5


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
    apply_cuts(design, settings.get("cuts"))
    for warning in size_warnings(design):  # before the long work: the figure, at once
        design.setdefault("warnings", []).append(warning)
        say("size", warning)
    try:
        checkpoint()
        say("layering", layering.run(design, material, settings, native_progress))
        design["pending_stages"].remove("layering")
        for message in design.get("close_crossings", []):
            say("layering", message)
        design = shape_and_rest(design, material, settings, say, native_progress, checkpoint)
    except native.Cancelled:
        raise Cancelled() from None
    return design


def apply_cuts(design, cuts):
    """The user's cuts ({wire name: target index}) onto the design's wires; ValueError names a
    wire that does not exist. The index itself is checked by the forces stage."""
    names = {w["name"]: w for w in design["wires"]}
    for name, index in (cuts or {}).items():
        if name not in names:
            raise ValueError(f'settings.cuts names wire "{name}", but the wires are {", ".join(sorted(names))}')
        names[name]["cut_override"] = index


def _largest_over_bend(design, limit_deg):
    """The largest rest bend beyond the machine's limit (degrees over it), 0 when none."""
    over = [o["angle_deg"] for w in design["wires"] for o in w.get("rest_over_bend", [])]
    return max((abs(a) - limit_deg for a in over), default=0.0)


def shape_and_rest(design, material, settings, say, native_progress, checkpoint):
    """Target shape, then forces and rest shape, with the coupling of Sec. 4.3: the machine's
    maximum bend limits the rest shape, which is only known after the forces; when a rest bend
    exceeds it, the target's limit is lowered by the excess (plus COUPLING_MARGIN_DEG) and the
    shape is solved again from the same layering, at most COUPLING_ROUNDS times. Each round starts
    from what the previous one learnt (target_shape.Memo): its nulled crossings, and the wires whose
    optimum the lower limit leaves optimal."""
    import copy

    def fresh(d):
        """A copy to solve on; the wires' contours are only read after layering, so they are shared
        (copying their points took most of the glue of a coupling round)."""
        return copy.deepcopy(d, {id(w["contour"]): w["contour"] for w in d["wires"]})

    machine_limit = settings["max_bend_deg"]
    target_limit = machine_limit
    before = fresh(design)
    memo = target_shape.Memo()
    totals = dict.fromkeys(("seconds", "iterations", "wire_solves", "reused_wires"), 0)
    for round_ in range(COUPLING_ROUNDS):
        if round_:
            design = fresh(before)
        checkpoint()
        say("target_shape", target_shape.run(design, material, {**settings, "max_bend_deg": target_limit},
                                             native_progress, memo))
        design["pending_stages"].remove("target_shape")
        stage = design["stages"]["target_shape"]
        for key in totals:  # the stage's cost over every coupling round; its shapes are the last round's
            totals[key] += stage[key]
            stage[key] = totals[key]
        design["stages"]["target_shape"]["max_bend_deg"] = target_limit
        design["stages"]["target_shape"]["coupling_rounds"] = round_ + 1
        if not design["stable"]:  # forces need the hooks of a complete stable assembly
            return design
        checkpoint()
        say("forces", forces.run(design, material, settings, native_progress))
        design["pending_stages"].remove("forces")
        say("rest_shape", forces.rest_summary(design))
        design["pending_stages"].remove("rest_shape")
        excess = _largest_over_bend(design, machine_limit)
        if excess <= 0.0:
            return design
        if round_ + 1 < COUPLING_ROUNDS:
            target_limit = max(1.0, target_limit - excess - COUPLING_MARGIN_DEG)
            say("target_shape", f"a rest bend exceeds the machine's {machine_limit:g} deg by {excess:.4f} deg; "
                                f"solving again with target bends up to {target_limit:.2f} deg (Sec. 4.3)")
    return design


def run(vertices, faces, planes, material, settings, progress=None, cancel=None):
    """slice_and_pick then solve: the whole pipeline from a mesh and planes."""
    design = slice_and_pick(vertices, faces, planes, material, settings, progress)
    return solve(design, material, settings, progress, cancel)
