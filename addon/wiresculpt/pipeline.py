"""The solver pipeline: slice and pick (from a mesh and planes), then solve (from wires) every
stage that exists so far, producing the design document. Free of bpy: the batch script and the
add-on's operators both call it, the add-on from a worker thread (the native stages release the
GIL) with `cancel` wired to its Esc key.
"""
import copy
import math
import time

from . import native
from .core import mesh_faults
from .core import settings as settings_table
from .core.design import (NO_WIRES_CAUSE, ONE_WIRE_CAUSE, RELAYER_INCOMPLETE, RELAYER_NO_ASSEMBLY, RELAYER_NOTHING_NEW,
                          RELAYER_ROUNDS, RELAYER_STABLE, SETUP_WORDS, TOO_CLOSE, new_design)
from .core.sizes import STOCK_LENGTH, mesh_size, size_warnings
from .core.solve_context import Cancelled, OutOfTime, SolveContext, quiet  # noqa: F401 (the pipeline's names)
from .fab import buildability, pieces
from .stages import forces, layering, slicing, stands3d, target_shape

ALL_STAGES = ["layering", "target_shape", "forces", "rest_shape"]
COUPLING_ROUNDS = 4  # target shape <-> rest shape iterations (Sec. 4.3)
COUPLING_MARGIN_DEG = 0.5
ANGLE_SLACK = 1e-12  # rad: the bend program's kAngleSlack (native/src/fab/bend_program.cpp)
# Hooks by their forces (hooks_by_forces, docs/method-forces.md §12): a crossing's two hooks cost
# the same in Eq. 2 when within HOOK_TIE; load capacities (at the plastic limit) within CAPACITY_TIE
# of the best are equal, and the paper's out-of-plane measure decides among them; the search
# solves at most HOOK_PATTERNS patterns and starts no new one after HOOK_SECONDS.
HOOK_TIE = 1e-6
CAPACITY_TIE = 0.02
HOOK_PATTERNS = 64
HOOK_SECONDS = 60.0


def slice_and_pick(vertices, faces, planes, material, settings, progress=None):
    """A new design whose wires are the contours the planes' rules pick. `planes`: objects with
    name, origin, normal, contours (the rule)."""
    design = new_design(material, settings)
    design["model_size"] = mesh_size(vertices)  # the model's size, one figure for every message (core/sizes)
    design["mesh_faults"] = mesh_faults.check(vertices, faces)  # said in the verdict when it fails (explain)
    thin = mesh_faults.thin(vertices, faces, settings["min_segment"])  # parts no closed wire goes round
    design["mesh_faults"] += thin
    design.setdefault("warnings", []).extend(mesh_faults.sentence(f) for f in thin)
    closing = mesh_faults.closing_of(vertices, faces)  # a mesh closed for slicing (blend/mesh.py): what was done
    if closing is not None:
        design["mesh_closing"] = closing
    (progress or quiet)("slicing", slicing.run(design, vertices, faces, planes, settings))
    return design


def solve(design, material, settings, progress=None, cancel=None, stock=None, hook_patterns=None, hook_seconds=None):
    """Runs every stage after slicing on `design` (its wires' contours set), re-layering while the
    target shape cannot realise a hook (relayer). `progress(stage, message)` is called once per
    finished stage; `cancel()` returning True stops at the next safe point with Cancelled.
    `pending_stages` names the stages that did not run. `stock`: (length in m, profile name) of
    the machine profile in use, for the stock-length warnings said before the long work and the
    pieces of the wires longer than it (fab/pieces.py; None: the default profile's). `hook_patterns`: at most this many hook patterns per round in
    hooks_by_forces (None: HOOK_PATTERNS; 1: the layering's own, as Live does); `hook_seconds`: no
    new pattern after this many seconds (None: HOOK_SECONDS; the plane search's final solve). Past settings.max_solve_seconds (wall
    clock) the solve stops the same way and raises OutOfTime, naming the key and the stage.
    `progress` may instead be the SolveContext of a longer run this solve is part of (the plane
    search's): the solve then says what it says (nothing, from a quiet view), is cancelled when that
    run is or by `cancel`, and keeps the run's deadline (one budget for the whole run) instead of
    starting its own."""
    if isinstance(progress, SolveContext):
        context = progress.for_solve(cancel)
    else:
        budget = float(settings.get("max_solve_seconds") or settings_table.SETTINGS["max_solve_seconds"][0])
        context = SolveContext(progress, cancel, budget)
    design["pending_stages"] = list(ALL_STAGES)
    if len(design["wires"]) < 2:
        design["stable"] = False
        cause = NO_WIRES_CAUSE if not design["wires"] else ONE_WIRE_CAUSE  # setup problems (core/design.py)
        design["reason"], design["reason_causes"], design["verdict_cause"] = SETUP_WORDS[cause], [cause], cause
        return design
    apply_cuts(design, settings.get("cuts"))
    for warning in size_warnings(design, *(stock or ())):  # before the long work: the contour's figure, at once
        context.say("size", warning)
    try:
        solved = relayer(design, material, settings, context, hook_patterns, hook_seconds)
        if solved["stable"]:  # the planar verdict holds: does the assembled sculpture stand in 3D?
            context.checkpoint()
            context.say("stands_3d", stands3d.run(solved, material, context.native_progress))
        if any("rest" in w for w in solved["wires"]):  # wires longer than the stock: in pieces, or why not
            pieces.apply(solved, (stock or (STOCK_LENGTH,))[0])
        # the warnings the design keeps: the solved wires' lengths, the figures its files give
        solved.setdefault("warnings", []).extend(size_warnings(solved, *(stock or ())))
        mesh_faults.explain(solved)  # a mesh of several parts or with holes: its faults lead the reason
        return solved
    except native.Cancelled:
        raise context.stopped() from None


def _copy_sharing_contours(design):
    """A deep copy of `design` whose wires share their contour lists with it."""
    return copy.deepcopy(design, {id(w["contour"]): w["contour"] for w in design["wires"]})


def _pairs(pairs):
    return [[c, h] for c, h in sorted(pairs)]


def _at_crossings(pairs):
    """"crossing 3" or "crossings 1, 2 and 5": the crossings of (crossing id, hook) `pairs`, named as
    the layering's own verdict names them."""
    ids = {c for c, _h in pairs}
    return f"crossing{'s' if len(ids) > 1 else ''} {target_shape.id_list(ids)}"


def relayer(design, material, settings, context, hook_patterns=None, hook_seconds=None):
    """Layering, then target shape, forces and rest shape (shape_and_rest); while the result is not
    stable because the target shape could not realise some crossing's hook, forbid those (crossing,
    hook) pairs (target_shape.unrealisable: the failed hook, or both hooks of a crossing too close to
    a neighbour) and layer again from the same contours, with a fresh target-shape memo (that shares only
    the solves of identical wire problems: same contour, crossings, hooks and limits). Stops when
    the design is stable, when nothing new can be forbidden, when the layering finds no stable
    assembly under the forbidden hooks or stops at max_nodes (search incomplete), or after
    `relayer_rounds` re-layerings. With the loop on (relayer_rounds > 0) every round's layering also
    forbids up front the hooks that crossings too close along a wire rule out (layering.run's
    too_close, the target shape's own tolerance), which the loop would otherwise learn one round at a
    time; when the first layering finds no stable assembly without them, it layers again with every
    hook and goes on as without them (the every-hook path), so the target shape shows which hooks fail and
    why. Records every layering run in stages.relayering, and how the loop ended (its `end`,
    core/design.py RELAYER_ENDS). Returns the design of the last round, or, when the last layering found no stable assembly under the forbidden hooks,
    of the last round that reached the target shape (its shapes and reason show why), saying so.
    `context`: the solve's SolveContext (core/solve_context.py: progress, cancel, deadline, and the
    memos every round shares). `hook_patterns`: hooks_by_forces' `patterns` bound (None:
    HOOK_PATTERNS); `hook_seconds`: its time bound over every round (None: HOOK_SECONDS)."""
    extra_rounds = int(layering.knob(settings, "relayer_rounds"))
    # Layering replaces (never edits) each wire's contour, so the copies share the contours.
    pristine = _copy_sharing_contours(design) if extra_rounds else None
    up_front = target_shape.REALISED_ANGLE if extra_rounds else None  # None: every hook (the every-hook path)
    forbidden, too_close, rounds, start, shaped = set(), set(), [], time.perf_counter(), None
    hook_deadline = time.monotonic() + (HOOK_SECONDS if hook_seconds is None else hook_seconds)  # one bound for the hook searches of every round
    round_ = 0
    while True:
        began = time.perf_counter()
        context.checkpoint()
        attempt = design if not rounds else _copy_sharing_contours(pristine)
        context.say("layering", layering.run(attempt, material, settings, context.native_progress, forbidden=forbidden,
                                             too_close=up_front, contour_cache=context.contour_cache))
        attempt["pending_stages"].remove("layering")
        # The crossings' spacing is the same every round, and a learnt pair is never a too-close
        # one, so the native lists them all each round.
        too_close = {tuple(p) for p in attempt.pop("too_close_forbidden", ())}  # never in a design.json
        if (up_front is not None and too_close and not attempt["stable"] and round_ == 0
                and not attempt.get("search_incomplete")):
            # Nothing holds without them: layer again with every hook (the every-hook path, for every round),
            # so that the user sees the target shape's curves and its reason, as without the loop. (A
            # search that max_nodes stopped proved nothing; a larger one with every hook would rarely
            # finish either, so the loop stops on its verdict, as in any later round.)
            rounds.append({"forbidden": [], "too_close": _pairs(too_close), "stable": False,
                           "verdict": attempt["reason"], "unrealised": [], "seconds": time.perf_counter() - began})
            context.say("relayering", f"the layering finds no stable assembly without the {len(too_close)} hooks "
                                      f"at {_at_crossings(too_close)}, too close to a neighbour along a wire for a "
                                      f"free bending point; layering again with every hook, for the target shape to "
                                      f"show what it cannot realise")
            up_front, too_close = None, set()
            continue
        excluded = forbidden | too_close
        for message in attempt.get("close_crossings", []):
            context.say("layering", message)
        if attempt["stable"]:
            # shape_and_rest on the layering's hooks and on the other stable patterns of equal Eq. 2
            # cost that use no forbidden hook; the best forces win among the stable (buildable) ones,
            # and when none is, the layering's own pattern is kept, so the round learns from it.
            attempt = hooks_by_forces(attempt, material, settings, context, patterns=hook_patterns,
                                      seconds=hook_seconds, forbidden=excluded, deadline=hook_deadline)
            shaped = attempt
        learnt = target_shape.unrealisable(attempt) - excluded
        rounds.append({"forbidden": _pairs(forbidden), "too_close": _pairs(too_close), "stable": attempt["stable"],
                       "verdict": "stable" if attempt["stable"] else attempt["reason"],
                       "unrealised": _pairs(learnt), "seconds": time.perf_counter() - began})
        end = (RELAYER_STABLE if attempt["stable"] else RELAYER_INCOMPLETE if attempt.get("search_incomplete")
               else RELAYER_NOTHING_NEW if not learnt else RELAYER_ROUNDS if round_ == extra_rounds else None)
        if end is not None:
            break
        forbidden |= learnt
        round_ += 1
        context.say("relayering", f"round {round_}: the target shape cannot realise "
                                  f"{', '.join(f'hook {h:+d} at crossing {c}' for c, h in sorted(learnt))}; "
                                  f"layering again without {'them' if len(learnt) > 1 else 'it'} "
                                  f"({len(forbidden | too_close)} hooks forbidden)")
    if "target_shape" in attempt["pending_stages"] and shaped is not None and not attempt.get("search_incomplete"):
        # The too-close hooks were forbidden before any target shape failed them: say where they are.
        close = (f" ({len(too_close)} of them at {_at_crossings(too_close)}, too close to a neighbour along a wire "
                 f"for a free bending point)") if too_close else ""
        shaped["reason"] += (f"; layering again without the {len(forbidden | too_close)} hooks the target shape cannot "
                             f"realise{close} finds no stable assembly (stages.relayering)")
        if too_close and TOO_CLOSE not in shaped.setdefault("reason_causes", []):
            shaped["reason_causes"].append(TOO_CLOSE)
        attempt, end = shaped, RELAYER_NO_ASSEMBLY
    attempt["stages"]["relayering"] = {"rounds": rounds, "forbidden": _pairs(forbidden), "end": end,
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


def _over(angle, limit_deg):
    """Radians by which a rest bend is beyond the machine's limit, counting one within the bend
    program's own slack (ANGLE_SLACK) as at the limit: a bend that rounding puts 1e-16 rad over
    120 deg is made, and chasing it cost the Airplane two coupling rounds."""
    over = abs(angle) - math.radians(limit_deg)
    return over if over > ANGLE_SLACK else 0.0


def _largest_over_bend(design, limit_deg):
    """The largest rest bend beyond the machine's limit (degrees over it), 0 when none. Taken from
    the rest angles with the bend program's slack only: it refuses anything further over."""
    return max((math.degrees(_over(a, limit_deg)) for w in design["wires"] for a in w.get("rest_angles", [])),
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
            if not _over(rest, machine_limit_deg):
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


def shape_and_rest(design, material, settings, context, solves=None):
    """Target shape, then forces and rest shape, with the coupling of Sec. 4.3: the machine's
    maximum bend limits the rest shape, which is only known after the forces. A rest bend beyond
    it comes from the torque its vertex carries (Eq. 12), so the target shape is solved again with
    that vertex's own bend limit lowered until its rest bend is COUPLING_MARGIN_DEG inside the
    machine's (_tighten); where that cannot act (a hooked kink at its least bend), the limit of
    every other bend is lowered by the excess, which changes the forces; from the same layering,
    at most COUPLING_ROUNDS times. Each round starts
    from what the previous one learnt (target_shape.Memo): its nulled crossings, its vertex limits,
    and the wires whose optimum the new limits leave optimal. Then the buildability verdict
    (fab/buildability.py): a bend still over the limit makes the design not stable, by name.
    `context`: the solve's SolveContext (core/solve_context.py): its say, native_progress and
    checkpoint, and its memos (`same_solves`, the solves of identical problems across re-layering
    rounds, target_shape.Memo; `contour_cache`, the contours' arrays). `solves`: a
    target_shape.Memo's per-wire solves to share with other calls (hooks_by_forces: a wire whose
    crossings keep their hooks is not solved again; the vertex limits are part of a solve's key)."""
    import copy

    def fresh(d):
        """A copy to solve on; the wires' contours are only read after layering, so they are shared
        (copying their points took most of the glue of a coupling round)."""
        return copy.deepcopy(d, {id(w["contour"]): w["contour"] for w in d["wires"]})

    machine_limit = settings["max_bend_deg"]
    target_limit = machine_limit
    kink = 180.0 - settings["contact_angle_deg"]  # a hooked crossing bends at least this much
    before = fresh(design)
    memo = target_shape.Memo(context.same_solves, context.contour_cache)
    if solves is not None:
        memo.solves = solves
    totals = dict.fromkeys(("seconds", "iterations", "wire_solves", "reused_wires"), 0)
    for round_ in range(COUPLING_ROUNDS):
        if round_:
            design = fresh(before)
        context.checkpoint()
        context.say("target_shape", target_shape.run(design, material, {**settings, "max_bend_deg": target_limit},
                                                     context.native_progress, memo))
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
        context.checkpoint()
        # The load capacity (twelve LPs, most of the stage's time) is only kept from the last round:
        # a round that may be followed by another skips it when a rest bend is over the limit, the
        # case in which another round follows (computed below if the rounds stop there anyway).
        warnings_before = len(design.get("warnings", []))
        # with the bend program's slack, as _largest_over_bend: a round that ends the coupling within
        # it keeps its load capacity instead of solving the forces a second time below
        within = math.radians(machine_limit) + ANGLE_SLACK if round_ + 1 < COUPLING_ROUNDS else None
        if "density" in material:  # an earlier solve's must not stand for a skipped one
            design.pop("load_capacity", None)
        context.say("forces", forces.run(design, material, settings, context.native_progress,
                                         load_capacity_within=within))
        design["pending_stages"].remove("forces")
        context.say("rest_shape", forces.rest_summary(design))
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
        context.say("target_shape", f"a rest bend exceeds the machine's {machine_limit:g} deg by {excess:.4f} "
                                    f"deg; solving again with {changed} vertex bend "
                                    f"limit{'s' if changed != 1 else ''} lowered so that the rest bends stay "
                                    f"{COUPLING_MARGIN_DEG:g} deg inside, other bends up to {target_limit:.2f} deg "
                                    f"(Sec. 4.3)")
    if "density" in material and "load_capacity" not in design:  # the last round skipped it
        del design.get("warnings", [])[warnings_before:]
        context.checkpoint()
        context.say("forces", forces.run(design, material, settings, context.native_progress))
    # "Stable" means buildable: the bend program of every wire, with the machine profile in use.
    buildability.apply(design)
    return design


def equal_cost_patterns(design, limit, forbidden=()):
    """Hook patterns of the layering's Eq. 2 cost: the layering's hooks with any set of the
    crossings whose two hooks cost the same (`hook_metrics` within HOOK_TIE) flipped, fewest flips
    first, the layering's own first; at most `limit` (the count of all is returned too). Flipping
    such a crossing keeps every key of the layering's objective (max and sum of e_c, null
    crossings). A crossing whose other hook is in `forbidden` ((crossing id, hook) pairs, the
    re-layering loop's) is not flipped."""
    import itertools

    hooks = [c["hook"] for c in design["crossings"]]
    free = [c["id"] for c in design["crossings"] if c["hook"] != 0 and "hook_metrics" in c
            and abs(c["hook_metrics"][0] - c["hook_metrics"][1]) <= HOOK_TIE
            and (c["id"], -c["hook"]) not in forbidden]
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


def _with_hooks(design, hooks):
    """A copy of `design` (sharing contours) whose crossings take `hooks` (with their metrics)."""
    trial = _copy_sharing_contours(design)
    for c, h in zip(trial["crossings"], hooks):
        if c["hook"] != h:
            c["hook"] = h
            c["metric"] = c["hook_metrics"][(h + 1) // 2]
    return trial


def _without_user_cuts(design):
    """A copy of `design` whose wires take automatic cuts (no cut_override or cut_point)."""
    plain = _copy_sharing_contours(design)
    for w in plain["wires"]:
        w.pop("cut_override", None)
        w.pop("cut_point", None)
    return plain


def force_score(design):
    """(carried, load capacity, out-of-plane measure) of a solved design for hooks_by_forces:
    whether the forces the assembled 3D structure carries lie in their pyramids (the forces
    stage's `stages.forces.carried_3d`, docs/method-forces.md §17), the weakest direction's
    multiple of the weight at the plastic limit (the load factor's `at_plastic_limit`; with a given
    torque fraction the weakest `load_capacity` multiple; +inf when unbounded, 0 without a load
    capacity) and the paper's out-of-plane measure (`out_of_plane.mean_to_max_force`). None when
    the forces did not run (the pattern is not stable or its target shape failed)."""
    if "forces" in design.get("pending_stages", ["forces"]) or not design.get("stable"):
        return None
    if "load_factor" in design:
        capacity = design["load_factor"]["at_plastic_limit"]
    elif "load_capacity" in design:
        held = [design["load_capacity"][a] for a in forces.AXES]
        capacity = min((m for m in held if m is not None), default=None)
    else:
        capacity = 0.0
    return (bool(design["stages"].get("forces", {}).get("carried_3d")),
            (float("inf") if capacity is None else capacity), design["out_of_plane"]["mean_to_max_force"])


def choose(scores):
    """The position in `scores` (force_score values in pattern order, None for a pattern without
    one) of the best: the patterns whose carried forces lie in their pyramids if there are any
    (they stand in 3D as the planar model says), among them those whose load capacity is within
    CAPACITY_TIE of their highest, of those the least out-of-plane measure, ties to the earliest.
    Compared with the highest, not pairwise, so a chain of near-ties cannot drift below it. None
    when no pattern has a score."""
    known = [(k, s) for k, s in enumerate(scores) if s is not None]
    if not known:
        return None
    carried = any(s[0] for _k, s in known)
    known = [(k, s) for k, s in known if s[0] == carried]
    top = max(s[1] for _k, s in known)
    near = [(round(s[2], 12), k) for k, s in known if s[1] >= top * (1 - CAPACITY_TIE)]
    return min(near)[1]


def hooks_by_forces(design, material, settings, context, patterns=None, seconds=None, forbidden=(), deadline=None):
    """shape_and_rest on the layering's hooks and on the other hook patterns of the same Eq. 2
    cost (equal_cost_patterns) whose assembly order stays stable (Eq. 1, layering.recheck), and
    keeps the design whose forces are best (force_score, choose): first the weakest-direction load
    capacity, then the paper's out-of-plane measure. Bounded: at most `patterns` patterns, none
    started after `seconds`; `stages.hook_search` records patterns (equal cost, in all), checked,
    stable, solved, failed (patterns after the first that the solver could not finish: skipped),
    the chosen pattern's index (0: the layering's), its score, seconds and
    `complete` (false, with a warning, when a bound cut the choice). The result is written into
    `design` itself (and returned), as the stages do. `patterns` and `seconds`
    default to HOOK_PATTERNS and HOOK_SECONDS (read at the call). `forbidden`: (crossing id, hook)
    pairs no pattern may use (relayer's). `deadline` (time.monotonic()): no new pattern after it,
    instead of `seconds` from the call (relayer's, shared by its rounds). `context`: the solve's
    SolveContext (its memos go to shape_and_rest; patterns after the first say nothing). When no
    pattern ends stable, the layering's own pattern
    is the result (relayer learns from its unrealisable hooks)."""
    patterns = HOOK_PATTERNS if patterns is None else patterns
    seconds = HOOK_SECONDS if seconds is None else seconds
    start = time.monotonic()
    stop_at = start + seconds if deadline is None else deadline
    candidates, total = equal_cost_patterns(design, patterns if design["stable"] else 1, forbidden)
    shared = {}  # the target shape's per-wire solves, shared by the patterns
    base = design  # only copied from (each pattern solves a copy); replaced by the result at the end
    # The user's cuts (cut handles, settings.cuts) change the forces a little, so patterns within
    # CAPACITY_TIE could trade places when a handle moves and move every other wire's automatic
    # cut with them. The patterns are compared with automatic cuts; the chosen one is then solved
    # with the user's.
    user_cuts = len(candidates) > 1 and any("cut_override" in w or "cut_point" in w for w in base["wires"])
    scored = _without_user_cuts(base) if user_cuts else base
    solutions, scores = [], []  # the solved patterns in order, (index, design), and their force_score
    checked = stable = failed = 0
    cut = design["stable"] and len(candidates) < total
    for index, hooks in enumerate(candidates):
        if index and time.monotonic() > stop_at:
            cut = True
            break
        context.checkpoint()
        trial = _with_hooks(scored, hooks)
        checked += 1
        try:
            if index and not layering.recheck(trial, material, settings, context.native_progress)["stable"]:
                continue
            stable += 1
            trial = shape_and_rest(trial, material, settings, context if index == 0 else context.quiet(), shared)
        except (native.Cancelled, OutOfTime):
            raise
        except (ValueError, RuntimeError):  # another pattern the solver cannot finish: not a better one
            if index == 0:
                raise
            failed += 1
            continue
        solutions.append((index, trial))
        scores.append(force_score(trial))
    pick = choose(scores)
    chosen, best = solutions[0 if pick is None else pick]
    best_score = None if pick is None else scores[pick]
    if user_cuts:  # the chosen pattern again, with the user's cuts; the layering's when that breaks it
        for index in dict.fromkeys((chosen, 0)):
            context.checkpoint()
            best = shape_and_rest(_with_hooks(base, candidates[index]), material, settings, context.quiet(), shared)
            chosen, best_score = index, force_score(best)
            if best_score is not None:
                break
    search = {"patterns": len(candidates), "equal_cost": total, "checked": checked, "stable": stable,
              "solved": len(solutions), "failed": failed, "chosen": chosen, "seconds": time.monotonic() - start,
              "complete": not cut}
    if best_score is not None:
        search["carried_3d"], search["load_capacity"], search["out_of_plane"] = best_score
        if search["load_capacity"] == float("inf"):
            search["load_capacity"] = None
    best["stages"]["hook_search"] = search
    if cut:
        best.setdefault("warnings", []).append(
            f"hooks by forces: {checked} of {total} hook patterns of equal Eq. 2 cost were tried (bounded to "
            f"{patterns} patterns{f' and {seconds:g} s' if math.isfinite(seconds) else ''}"
            f"{' over every re-layering round' if deadline is not None else ''}); "
            "a better one may exist")
    if chosen and best_score is not None:
        context.say("forces", f"hooks by forces: pattern {chosen} of {checked} tried (weakest load "
                              f"{best_score[1]:.2f}x the weight at the plastic limit, out of plane "
                              f"{100 * best_score[2]:.1f}% of the largest force"
                              f"{'; its 3D forces in their pyramids' if best_score[0] else ''})")
    design.clear()  # callers keep the dict they passed (operators/optimize.py)
    design.update(best)
    return design


def run(vertices, faces, planes, material, settings, progress=None, cancel=None, stock=None):
    """slice_and_pick then solve: the whole pipeline from a mesh and planes (`progress`: as solve's,
    a callback or the SolveContext of the run)."""
    design = slice_and_pick(vertices, faces, planes, material, settings,
                            progress.say if isinstance(progress, SolveContext) else progress)
    return solve(design, material, settings, progress, cancel, stock)
