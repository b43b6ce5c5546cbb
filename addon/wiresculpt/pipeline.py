"""The solver pipeline: slice and pick (from a mesh and planes), then solve (from wires) every
stage that exists so far, producing the design document. Free of bpy: the batch script and the
add-on's operators both call it, the add-on from a worker thread (the native stages release the
GIL) with `cancel` wired to its Esc key.
"""
import copy
import time

from . import native
from .core.design import new_design
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
    """Runs every stage after slicing on `design` (its wires' contours set), re-layering while the
    target shape cannot realise a hook (relayer). `progress(stage, message)` is called once per
    finished stage; `cancel()` returning True stops at the next safe point with Cancelled.
    `pending_stages` names the stages that did not run."""
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
    try:
        return relayer(design, material, settings, say, native_progress, checkpoint)
    except native.Cancelled:
        raise Cancelled() from None


def _copy_sharing_contours(design):
    """A deep copy of `design` whose wires share their contour lists with it."""
    return copy.deepcopy(design, {id(w["contour"]): w["contour"] for w in design["wires"]})


def _pairs(pairs):
    return [[c, h] for c, h in sorted(pairs)]


def relayer(design, material, settings, say, native_progress, checkpoint):
    """Layering, then target shape, forces and rest shape (shape_and_rest); while the result is not
    stable because the target shape could not realise some crossing's hook, forbid those (crossing,
    hook) pairs (target_shape.unrealisable: the failed hook, or both hooks of a crossing too close to
    a neighbour) and layer again from the same contours, with a fresh target-shape memo. Stops when
    the design is stable, when nothing new can be forbidden, when the layering finds no stable
    assembly under the forbidden hooks or stops at max_nodes (search incomplete), or after
    `relayer_rounds` re-layerings. Records every round in stages.relayering. Returns the design of
    the last round, or, when the last layering found no stable assembly under the forbidden hooks,
    of the last round that reached the target shape (its shapes and reason show why), saying so."""
    extra_rounds = int(layering.knob(settings, "relayer_rounds"))
    # Layering replaces (never edits) each wire's contour, so the copies share the contours.
    pristine = _copy_sharing_contours(design) if extra_rounds else None
    forbidden, rounds, start, shaped = set(), [], time.perf_counter(), None
    for round_ in range(extra_rounds + 1):
        began = time.perf_counter()
        checkpoint()
        attempt = design if round_ == 0 else _copy_sharing_contours(pristine)
        say("layering", layering.run(attempt, material, settings, native_progress, forbidden=forbidden))
        attempt["pending_stages"].remove("layering")
        for message in attempt.get("close_crossings", []):
            say("layering", message)
        if attempt["stable"]:
            attempt = shape_and_rest(attempt, material, settings, say, native_progress, checkpoint)
            shaped = attempt
        learnt = target_shape.unrealisable(attempt) - forbidden
        rounds.append({"forbidden": _pairs(forbidden), "stable": attempt["stable"],
                       "verdict": "stable" if attempt["stable"] else attempt["reason"],
                       "unrealised": _pairs(learnt), "seconds": time.perf_counter() - began})
        if attempt["stable"] or not learnt or attempt.get("search_incomplete") or round_ == extra_rounds:
            break
        forbidden |= learnt
        say("relayering", f"round {round_ + 1}: the target shape cannot realise "
                          f"{', '.join(f'hook {h:+d} at crossing {c}' for c, h in sorted(learnt))}; "
                          f"layering again without {'them' if len(learnt) > 1 else 'it'} "
                          f"({len(forbidden)} hooks forbidden)")
    if "target_shape" in attempt["pending_stages"] and shaped is not None and not attempt.get("search_incomplete"):
        shaped["reason"] += (f"; layering again without the {len(forbidden)} hooks the target shape cannot realise "
                             f"finds no stable assembly (stages.relayering)")
        attempt = shaped
    attempt["stages"]["relayering"] = {"rounds": rounds, "forbidden": _pairs(forbidden),
                                       "max_rounds": extra_rounds, "seconds": time.perf_counter() - start}
    if not attempt["stable"] and learnt and round_ == extra_rounds and extra_rounds:
        attempt["reason"] += (f" (re-layering stopped after relayer_rounds = {extra_rounds}; more rounds may "
                              f"find a stable design)")
    return attempt


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
