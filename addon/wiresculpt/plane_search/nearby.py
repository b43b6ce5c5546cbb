"""The nearby search: the user's planes, changed as little as possible (the package's docstring)."""
import copy
import itertools
import math
import time

from ..core import plane_faults
from ..core.plane_faults import Tally
from .placements import Placement, _unit, single_changes
from .searcher import Searcher, _figures, stands_first

# A nearby search's work: at most NEARBY_SCREENS candidates screened and NEARBY_SOLVES full solves
# of candidates (the final comparison of hook patterns not counted), which on this project's 2-core
# machine takes about the 8 s its wall-clock budget used to be (man's 5 planes: every one of its
# 6376 candidates screened and 16 solved in 5-7 s). BUDGET_SECONDS is only the guard that stops a
# search that takes too long (stopped_by "time"); it never decides what a search that ends returns.
NEARBY_SCREENS = 8000
NEARBY_SOLVES = 24
BUDGET_SECONDS = 60.0
PAIR_SINGLES = 25  # the two-plane changes pair each plane's this many cheapest one-plane changes (all 25)
SLICE_AHEAD = 32  # nearby slices the changed planes of this many candidates in one call (Searcher.slice_ahead)


def nearby(mesh, planes, material, settings, want=1, budget=BUDGET_SECONDS, context=None, stock=None):
    """Up to `want` stable, buildable candidates near `planes`, cheapest change first:
    [{"planes": [Placement], "changes": [sentence], "cost", "score", "design", "figures"}], the
    Searcher (its counts) and the start time. The given planes themselves are candidate 0 (cost 0).
    Order: one-plane changes by cost, then pairs (plane_faults.Tally.pair_order: those that the
    single changes' faults point at first, then by cost); within each, except that a screened candidate
    whose layering reports crossings closer along a wire than the machine's minimum segment
    (`close_crossings`; before the screen left out the hooks such crossings cannot get, the full
    pipeline failed on most of them, at a second each; now they are rarer, and kept last) is solved only
    after the others, and only while it is cheaper than the `want`-th found, so that the answer is
    still the cheapest one-plane change the budget allows (a pair: the cheapest of its group, the
    search stopping at the first pair that costs more than the `want`-th found). When none is found,
    the Searcher's tally (plane_faults.Tally) holds the account nearby_reason words. `budget`: the
    wall-clock guard in seconds (the counts NEARBY_SCREENS and NEARBY_SOLVES bound the work)."""
    s = Searcher(mesh, material, settings, context, stock)
    start = time.perf_counter()
    s.guard, s.budget = s.clock() + budget, budget
    s.limits = {"candidates": NEARBY_SCREENS, "full_solves": NEARBY_SOLVES}
    base = [Placement(p.name, p.origin, _unit(p.normal), p.contours) for p in planes]
    singles = {i: single_changes(p, s.centre, s.size) for i, p in enumerate(planes)}
    pairs = [(a.cost + b.cost, ((i, a), (j, b))) for i, j in itertools.combinations(sorted(singles), 2)
             for a in singles[i][:PAIR_SINGLES] for b in singles[j][:PAIR_SINGLES]]
    tally = s.tally = Tally(base, singles, len(pairs))
    found = []

    def out_of_time():
        """The search's end with work left: its guard, or a count of its limits reached."""
        return s.should_stop() or s.out_of_work()

    def bar():
        """The cost a candidate must beat to matter: the want-th cheapest found, else infinity."""
        costs = sorted(c["cost"] for c in found)
        return costs[want - 1] if len(costs) >= want else math.inf

    def solve(cost, changes, placements, design, probe):
        family, stopped = tally.family_of(changes), s.timed_out
        tally.solved(family)
        solved = s.solve(copy.deepcopy(design))
        if solved is None or not solved["stable"]:
            fault = ((("stopped" if s.timed_out > stopped else "failed"), (), ()) if solved is None
                     else plane_faults.verdict_fault(probe, solved))
            tally.fault(family, fault, changes)
            return
        tally.fault(family, ("stable", (), ()), changes)
        found.append({"planes": placements, "changes": [t for _, c in changes for t in c.changes], "cost": cost,
                      "score": -cost, "design": solved, "figures": _figures(solved), "sliced": design})
        s.say("plane_search", f"candidate {len(found)}: {'; '.join(found[-1]['changes']) or 'the planes as given'} "
                              f"(cost {cost:.3f}, {s.screened} screened, {s.full_solves} solved)")

    def phase(options):
        deferred = []
        for n, (cost, changes) in enumerate(options):
            if cost >= bar() or out_of_time():
                break
            if any(c.key() not in s.cache for _i, c in changes):  # this and the next candidates' planes at once
                s.slice_ahead([c for _cost, ahead in options[n:n + SLICE_AHEAD] for _i, c in ahead])
            placements = list(base)
            for i, c in changes:
                placements[i] = c
            ok, design, probe = s.screen_layered(placements)
            tally.screened(tally.family_of(changes))
            if not ok:
                tally.fault(tally.family_of(changes), s.fault, changes)
                continue
            if probe.get("close_crossings"):
                deferred.append((cost, changes, placements, design, probe))
            else:
                solve(cost, changes, placements, design, probe)
        for k, (cost, changes, placements, design, probe) in enumerate(deferred):
            if cost >= bar() or s.should_stop() or s.out_of_work(("full_solves",)):
                for _cost, later, _placements, _design, left in deferred[k:]:
                    gap = plane_faults.closest_gap(left)
                    tally.fault(tally.family_of(later), ("near", (gap[1],), gap[2]) if gap else ("unsolved", (), ()),
                                later)
                break
            solve(cost, changes, placements, design, probe)

    phase([(0.0, ())] + sorted(((c.cost, ((i, c),)) for i, cs in singles.items() for c in cs), key=lambda t: t[0]))
    if len(found) < want and not out_of_time():  # pairs of one-plane changes of two planes
        phase(tally.pair_order(pairs))
    tally.seconds = time.perf_counter() - start
    tally.out_of_time = s.time_stopped or s.count_stopped
    found.sort(key=lambda c: (stands_first(c), c["cost"]))  # what stands in 3D first, then the least change
    if found:
        s.finish(found[0])
    for candidate in found[:want]:  # fidelity and coverage, shown with each candidate (after the budget)
        s.looks(candidate)
    return found[:want], s, start
