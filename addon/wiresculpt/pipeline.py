"""The solver pipeline: slice and pick (from a mesh and planes), then solve (from wires) every
stage that exists so far, producing the design document. Free of bpy: the batch script and the
add-on's operators both call it, the add-on from a worker thread (the native stages release the
GIL) with `cancel` wired to its Esc key.
"""
import copy
import math
import time

from . import native
from .core.design import new_design
from .core.sizes import size_warnings
from .fab import buildability
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
    for warning in size_warnings(design):  # before the long work: the figure, at once
        design.setdefault("warnings", []).append(warning)
        say("size", warning)
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
    a neighbour) and layer again from the same contours, with a fresh target-shape memo (that shares only
    the solves of identical wire problems: same contour, crossings, hooks and limits). Stops when
    the design is stable, when nothing new can be forbidden, when the layering finds no stable
    assembly under the forbidden hooks or stops at max_nodes (search incomplete), or after
    `relayer_rounds` re-layerings. Records every round in stages.relayering. Returns the design of
    the last round, or, when the last layering found no stable assembly under the forbidden hooks,
    of the last round that reached the target shape (its shapes and reason show why), saying so."""
    extra_rounds = int(layering.knob(settings, "relayer_rounds"))
    # Layering replaces (never edits) each wire's contour, so the copies share the contours.
    pristine = _copy_sharing_contours(design) if extra_rounds else None
    forbidden, rounds, start, shaped = set(), [], time.perf_counter(), None
    same_solves = {}  # target-shape solves by exact input, for every round (target_shape.Memo `same`)
    for round_ in range(extra_rounds + 1):
        began = time.perf_counter()
        checkpoint()
        attempt = design if round_ == 0 else _copy_sharing_contours(pristine)
        say("layering", layering.run(attempt, material, settings, native_progress, forbidden=forbidden))
        attempt["pending_stages"].remove("layering")
        for message in attempt.get("close_crossings", []):
            say("layering", message)
        if attempt["stable"]:
            attempt = shape_and_rest(attempt, material, settings, say, native_progress, checkpoint, same_solves)
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
    """The largest rest bend beyond the machine's limit (degrees over it), 0 when none. Taken from
    the rest angles with no tolerance: the bend program refuses anything over the limit."""
    return max((math.degrees(abs(a)) - limit_deg for w in design["wires"] for a in w.get("rest_angles", [])),
               default=0.0)


def rest_angle(target, k):
    """Eq. 12 for one vertex with the torque it carries as k = t / (4 k_b / l): the rest angle
    2 atan(tan(a/2) + k / (1 + tan^2(a/2))) of a target angle a (radians, signed)."""
    tan = math.tan(0.5 * target)
    return 2.0 * math.atan(tan + k / (1.0 + tan * tan))


def target_limit_for(target, rest, wanted):
    """The largest target bend |a'| <= |target| whose rest angle, under the torque this vertex
    carries now (read back from its target and rest angles through Eq. 12), has |rest| <= wanted
    (radians). None when no such bend of the same sign exists (the torque alone bends it further)."""
    sign = 1.0 if rest >= 0.0 else -1.0
    a, r = sign * target, sign * rest  # mirrored so that the rest angle is positive
    tan = math.tan(0.5 * a)
    k = (math.tan(0.5 * r) - tan) * (1.0 + tan * tan)
    if a <= 0.0 or rest_angle(0.0, k) > wanted:
        return None
    lo, hi = 0.0, a  # rest_angle increases with the target angle for the torques of a wire (k << 1)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if rest_angle(mid, k) <= wanted else (lo, mid)
    return lo


def _tighten(design, memo, machine_limit_deg, floor_deg):
    """The coupling's step (Sec. 4.3): at every rest vertex bent beyond the machine, the target
    bend that brings it to COUPLING_MARGIN_DEG inside the machine's limit under the torque it
    carries becomes that vertex's own limit for the next target shape (memo.vertex_limits, per
    wire name and target index; only ever lowered, never below `floor_deg`, the bend of a hooked
    kink). Returns (how many vertices got a new limit, the largest excess in degrees of those that
    could not: a hooked kink already at its least bend, whose torque only the forces change)."""
    wanted = math.radians(machine_limit_deg - COUPLING_MARGIN_DEG)
    floor = math.radians(floor_deg)
    changed, stuck = 0, 0.0
    for w in design["wires"]:
        m = len(w["target"])
        for position, (rest, target) in enumerate(zip(w["rest_angles"], w["target_angles"])):
            if abs(rest) <= math.radians(machine_limit_deg):
                continue
            vertex = (w["cut"] + position) % m if w["closed"] else position
            limit = target_limit_for(target, rest, wanted)
            limits = memo.vertex_limits.setdefault(w["name"], {})
            new = max(floor, min(limit if limit is not None else 0.0, limits.get(vertex, math.pi)))
            if new < min(limits.get(vertex, math.pi), abs(target)):
                limits[vertex] = new
                changed += 1
            else:
                stuck = max(stuck, math.degrees(abs(rest)) - machine_limit_deg)
    return changed, stuck


def shape_and_rest(design, material, settings, say, native_progress, checkpoint, same_solves=None):
    """Target shape, then forces and rest shape, with the coupling of Sec. 4.3: the machine's
    maximum bend limits the rest shape, which is only known after the forces. A rest bend beyond
    it comes from the torque its vertex carries (Eq. 12), so the target shape is solved again with
    that vertex's own bend limit lowered until its rest bend is COUPLING_MARGIN_DEG inside the
    machine's (_tighten); where that cannot act (a hooked kink at its least bend), the limit of
    every other bend is lowered by the excess, which changes the forces; from the same layering,
    at most COUPLING_ROUNDS times. Each round starts
    from what the previous one learnt (target_shape.Memo): its nulled crossings, its vertex limits,
    and the wires whose optimum the new limits leave optimal; `same_solves` (a dict, see
    target_shape.Memo) carries the solves of identical problems across re-layering rounds. Then the buildability verdict
    (fab/buildability.py): a bend still over the limit makes the design not stable, by name."""
    import copy

    def fresh(d):
        """A copy to solve on; the wires' contours are only read after layering, so they are shared
        (copying their points took most of the glue of a coupling round)."""
        return copy.deepcopy(d, {id(w["contour"]): w["contour"] for w in d["wires"]})

    machine_limit = settings["max_bend_deg"]
    target_limit = machine_limit
    kink = 180.0 - settings["contact_angle_deg"]  # a hooked crossing bends at least this much
    before = fresh(design)
    memo = target_shape.Memo(same_solves)
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
        stage["max_bend_deg"] = target_limit
        stage["vertex_limits"] = sum(len(v) for v in memo.vertex_limits.values())
        stage["coupling_rounds"] = round_ + 1
        if not design["stable"]:  # forces need the hooks of a complete stable assembly
            return design
        checkpoint()
        say("forces", forces.run(design, material, settings, native_progress))
        design["pending_stages"].remove("forces")
        say("rest_shape", forces.rest_summary(design))
        design["pending_stages"].remove("rest_shape")
        excess = _largest_over_bend(design, machine_limit)
        stage["rest_excess_deg"] = max(excess, 0.0)
        if excess <= 0.0 or round_ + 1 == COUPLING_ROUNDS:
            break
        changed, stuck = _tighten(design, memo, machine_limit, kink + 0.01)
        if stuck > 0.0:  # a kink's torque: only other bends, through the forces they lead to, can change it
            target_limit = max(1.0, kink + 0.01, target_limit - stuck - COUPLING_MARGIN_DEG)
        if not changed and stuck <= 0.0:
            break
        say("target_shape", f"a rest bend exceeds the machine's {machine_limit:g} deg by {excess:.4f} deg; "
                            f"solving again with {changed} vertex bend limit{'s' if changed != 1 else ''} lowered so "
                            f"that the rest bends stay {COUPLING_MARGIN_DEG:g} deg inside, other bends up to "
                            f"{target_limit:.2f} deg (Sec. 4.3)")
    # "Stable" means buildable: the bend program of every wire, with the machine profile in use.
    buildability.apply(design)
    return design


def run(vertices, faces, planes, material, settings, progress=None, cancel=None):
    """slice_and_pick then solve: the whole pipeline from a mesh and planes."""
    design = slice_and_pick(vertices, faces, planes, material, settings, progress)
    return solve(design, material, settings, progress, cancel)
