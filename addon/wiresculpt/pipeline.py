"""The solver pipeline: slice and pick (from a mesh and planes), then solve (from wires) every
stage that exists so far, producing the design document. Free of bpy: the batch script and the
add-on's operators both call it, the add-on from a worker thread (the native stages release the
GIL) with `cancel` wired to its Esc key.
"""
from . import native
from .core.design import new_design
from .stages import forces, layering, slicing, target_shape

ALL_STAGES = ["layering", "target_shape", "forces", "rest_shape"]
COUPLING_ROUNDS = 4  # target shape <-> rest shape iterations (Sec. 4.3)
COUPLING_MARGIN_DEG = 0.5
# Hooks by their forces (hooks_by_forces, docs/method-forces.md §12): a crossing's two hooks cost
# the same in Eq. 2 when within HOOK_TIE; load capacities (at the plastic limit) within CAPACITY_TIE
# of the best are equal, and the paper's out-of-plane measure decides among them; the search
# solves at most HOOK_PATTERNS patterns and starts no new one after HOOK_SECONDS.
HOOK_TIE = 1e-6
CAPACITY_TIE = 0.02
HOOK_PATTERNS = 64
HOOK_SECONDS = 60.0


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
    try:
        checkpoint()
        say("layering", layering.run(design, material, settings, native_progress))
        design["pending_stages"].remove("layering")
        for message in design.get("close_crossings", []):
            say("layering", message)
        design = hooks_by_forces(design, material, settings, say, native_progress, checkpoint)
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


def shape_and_rest(design, material, settings, say, native_progress, checkpoint, solves=None):
    """Target shape, then forces and rest shape, with the coupling of Sec. 4.3: the machine's
    maximum bend limits the rest shape, which is only known after the forces; when a rest bend
    exceeds it, the target's limit is lowered by the excess (plus COUPLING_MARGIN_DEG) and the
    shape is solved again from the same layering, at most COUPLING_ROUNDS times. Each round starts
    from what the previous one learnt (target_shape.Memo): its nulled crossings, and the wires whose
    optimum the lower limit leaves optimal. `solves`: a target_shape.Memo's per-wire solves to share
    with other calls (hooks_by_forces: a wire whose crossings keep their hooks is not solved again)."""
    import copy

    def fresh(d):
        """A copy to solve on; the wires' contours are only read after layering, so they are shared
        (copying their points took most of the glue of a coupling round)."""
        return copy.deepcopy(d, {id(w["contour"]): w["contour"] for w in d["wires"]})

    machine_limit = settings["max_bend_deg"]
    target_limit = machine_limit
    before = fresh(design)
    memo = target_shape.Memo()
    if solves is not None:
        memo.solves = solves
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


def equal_cost_patterns(design, limit):
    """Hook patterns of the layering's Eq. 2 cost: the layering's hooks with any set of the
    crossings whose two hooks cost the same (`hook_metrics` within HOOK_TIE) flipped, fewest flips
    first, the layering's own first; at most `limit` (the count of all is returned too). Flipping
    such a crossing keeps every key of the layering's objective (max and sum of e_c, null
    crossings)."""
    import itertools

    hooks = [c["hook"] for c in design["crossings"]]
    free = [c["id"] for c in design["crossings"] if c["hook"] != 0 and "hook_metrics" in c
            and abs(c["hook_metrics"][0] - c["hook_metrics"][1]) <= HOOK_TIE]
    out = []
    for k in range(len(free) + 1):
        for flipped in itertools.combinations(free, k):
            if len(out) >= limit:
                return out, 2 ** len(free)
            pattern = list(hooks)
            for c in flipped:
                pattern[c] = -pattern[c]
            out.append(pattern)
    return out, 2 ** len(free)


def force_score(design):
    """(load capacity, out-of-plane measure) of a solved design for hooks_by_forces: the weakest
    direction's multiple of the weight at the plastic limit (the load factor's `at_plastic_limit`;
    with a given torque fraction the weakest `load_capacity` multiple; +inf when unbounded, 0 without
    a load capacity) and the paper's out-of-plane measure (`out_of_plane.mean_to_max_force`). None
    when the forces did not run (the pattern is not stable or its target shape failed)."""
    if "forces" in design.get("pending_stages", ["forces"]) or not design.get("stable"):
        return None
    if "load_factor" in design:
        capacity = design["load_factor"]["at_plastic_limit"]
    elif "load_capacity" in design:
        held = [design["load_capacity"][a] for a in forces.AXES]
        capacity = min((m for m in held if m is not None), default=None)
    else:
        capacity = 0.0
    return (float("inf") if capacity is None else capacity), design["out_of_plane"]["mean_to_max_force"]


def better(score, best):
    """score beats best: a load capacity more than CAPACITY_TIE above, or within CAPACITY_TIE and
    a smaller out-of-plane measure."""
    if best is None:
        return score is not None
    if score is None:
        return False
    capacity, share = score
    top = best[0]
    if capacity > top * (1 + CAPACITY_TIE):
        return True
    return capacity >= top * (1 - CAPACITY_TIE) and share < best[1] - 1e-12


def hooks_by_forces(design, material, settings, say, native_progress, checkpoint, patterns=None, seconds=None):
    """shape_and_rest on the layering's hooks and on the other hook patterns of the same Eq. 2
    cost (equal_cost_patterns) whose assembly order stays stable (Eq. 1, layering.recheck), and
    keeps the design whose forces are best (force_score, better): first the weakest-direction load
    capacity, then the paper's out-of-plane measure. Bounded: at most `patterns` patterns, none
    started after `seconds`; `stages.hook_search` records patterns (equal cost, in all), checked,
    stable, solved, the chosen pattern's index (0: the layering's), its score, seconds and
    `complete` (false, with a warning, when a bound cut the choice). The result is written into
    `design` itself (and returned), as the stages do. `patterns` and `seconds`
    default to HOOK_PATTERNS and HOOK_SECONDS (read at the call)."""
    import copy
    import time

    patterns = HOOK_PATTERNS if patterns is None else patterns
    seconds = HOOK_SECONDS if seconds is None else seconds
    start = time.monotonic()
    candidates, total = equal_cost_patterns(design, patterns if design["stable"] else 1)
    shared = {}  # the target shape's per-wire solves, shared by the patterns
    base = copy.deepcopy(design)
    best, best_score, chosen = None, None, 0
    checked = stable = solved = 0
    cut = design["stable"] and len(candidates) < total
    for index, hooks in enumerate(candidates):
        if index and time.monotonic() - start > seconds:
            cut = True
            break
        checkpoint()
        trial = copy.deepcopy(base)
        for c, h in zip(trial["crossings"], hooks):
            if c["hook"] != h:
                c["hook"] = h
                c["metric"] = c["hook_metrics"][(h + 1) // 2]
        checked += 1
        if index and not layering.recheck(trial, material, settings, native_progress)["stable"]:
            continue
        stable += 1
        trial = shape_and_rest(trial, material, settings, say if index == 0 else _quiet, native_progress, checkpoint,
                               shared)
        solved += 1
        score = force_score(trial)
        if best is None or better(score, best_score):
            best, best_score, chosen = trial, score, index
    search = {"patterns": len(candidates), "equal_cost": total, "checked": checked, "stable": stable,
              "solved": solved, "chosen": chosen, "seconds": time.monotonic() - start, "complete": not cut}
    if best_score is not None:
        search["load_capacity"], search["out_of_plane"] = best_score
        if search["load_capacity"] == float("inf"):
            search["load_capacity"] = None
    best["stages"]["hook_search"] = search
    if cut:
        best.setdefault("warnings", []).append(
            f"hooks by forces: {checked} of {total} hook patterns of equal Eq. 2 cost were tried (bounded to "
            f"{patterns} patterns and {seconds:g} s); a better one may exist")
    if chosen:
        say("forces", f"hooks by forces: pattern {chosen} of {checked} tried (weakest load "
                      f"{best_score[0]:.2f}x the weight at the plastic limit, out of plane "
                      f"{100 * best_score[1]:.1f}% of the largest force)")
    design.clear()  # callers keep the dict they passed (operators/optimize.py)
    design.update(best)
    return design


def run(vertices, faces, planes, material, settings, progress=None, cancel=None):
    """slice_and_pick then solve: the whole pipeline from a mesh and planes."""
    design = slice_and_pick(vertices, faces, planes, material, settings, progress)
    return solve(design, material, settings, progress, cancel)
