"""The auto search: planes from the mesh alone, in families along its principal axes or the
world's (the package's docstring)."""
import copy
import itertools
import math
import time

import numpy as np

from ..core import plane_faults
from ..core.plane_faults import close_gaps
from .placements import Placement
from .searcher import Searcher, _figures, stands_first

# auto's work for `count` planes: at most AUTO_SCREENS_PER_PLANE * count proposals screened and
# AUTO_SOLVES_PER_PLANE * count full solves of proposals (the final comparison of hook patterns not
# counted): on this project's 2-core machine about the 6 s per plane its wall-clock budget used to
# be. AUTO_SECONDS_PER_PLANE is only the guard that stops a search that takes too long (stopped_by
# "time"); it never decides what a search that ends returns.
AUTO_SCREENS_PER_PLANE = 400
AUTO_SOLVES_PER_PLANE = 2
AUTO_SECONDS_PER_PLANE = 30.0
EARLY_SOLVES = 3  # auto verifies as soon as this many screened proposals have no close gap


def _family_names(axes):
    names = []
    for k, a in enumerate(axes):
        j = int(np.argmax(np.abs(a)))
        names.append("XYZ"[j] if abs(a[j]) > 0.99 else "ABC"[k])
    if len(set(names)) < 3:
        names = ["A", "B", "C"]
    return names


# a family's first and last plane, as fractions of the mesh's extent along its axis: wide first;
# narrower spreads keep the planes off thin extremities (limbs, where crossings come close together)
SPREADS = ((0.2, 0.8), (0.3, 0.7), (0.12, 0.88), (0.38, 0.62), (0.25, 0.75), (0.16, 0.84))


def _surface(searcher):
    """(triangle centroids, areas) of the searcher's mesh, computed once."""
    if searcher.surface is None:
        V = np.asarray(searcher.V, dtype=float)
        F = np.asarray(searcher.F, dtype=np.int64)
        a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
        w = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
        searcher.surface = ((a + b + c) / 3.0, w if w.sum() > 0 else np.ones(len(F)))
    return searcher.surface


def family_planes(searcher, counts, contours="largest", spread=SPREADS[0], axes=None, by="extent"):
    """Placements for `counts[k]` planes along axis k of `axes` (default: the principal axes),
    spread evenly from `spread[0]` to `spread[1]` of the mesh's extent along it (a family of one
    goes through the centre); by="area": at those quantiles of the mesh's surface area along the
    axis instead (a family of one at the median), so that planes gather where the mesh has
    surface, away from thin extremities (a figure's limbs), where crossings come close together."""
    V = np.asarray(searcher.V, dtype=float)
    axes = searcher.axes if axes is None else axes
    names = _family_names(axes)
    out = []
    for k, count in enumerate(counts):
        if not count:
            continue
        axis = axes[k]
        t = (V - searcher.centre) @ axis
        lo, hi = float(t.min()), float(t.max())
        if by == "area":
            centroids, areas = _surface(searcher)
            u = (centroids - searcher.centre) @ axis
            order = np.argsort(u)
            share = np.cumsum(areas[order]) / areas.sum()
        for i in range(count):
            f = 0.5 if count == 1 else spread[0] + (spread[1] - spread[0]) * i / (count - 1)
            if by == "area":
                at = float(u[order][min(int(np.searchsorted(share, f)), len(order) - 1)])
            else:
                at = lo + f * (hi - lo)
            origin = searcher.centre + at * axis
            out.append(Placement(f"{names[k]}{i}", origin, axis, contours))
    return out


def _axis_word(axis, k):
    j = int(np.argmax(np.abs(axis)))
    return "xyz"[j] if abs(axis[j]) > 0.99 else f"principal axis {k + 1}"


def auto_budget(count):
    """auto's wall-clock guard in seconds for `count` planes (the final hook comparison comes on
    top: at most FINAL_SECONDS)."""
    return AUTO_SECONDS_PER_PLANE * max(int(count), 1)


def auto_limits(count):
    """auto's counts of work for `count` planes: {"candidates": screens, "full_solves": solves}."""
    n = max(int(count), 1)
    return {"candidates": AUTO_SCREENS_PER_PLANE * n, "full_solves": AUTO_SOLVES_PER_PLANE * n}


def splits_of(count):
    """The ways to split `count` planes over three axes using at least two, balanced first."""
    splits = [c for c in itertools.product(range(count + 1), repeat=3) if sum(c) == count
              and sum(1 for x in c if x) >= 2]
    return sorted(splits, key=lambda c: (max(c), 0 in c))


GROW_BASES = 3  # grow: the (count - 1)-plane proposals extended, fewest close crossings first
GROW_QUANTILES = tuple(round(0.05 * k, 2) for k in range(1, 20))  # where grow adds a plane: 5 %, 10 %, ... 95 %


def area_quantile_plane(searcher, axis, q, name):
    """The plane normal to `axis` through the point at which a share `q` of the mesh's surface area
    lies below it along `axis`."""
    centroids, areas = _surface(searcher)
    u = (centroids - searcher.centre) @ axis
    order = np.argsort(u)
    share = np.cumsum(areas[order]) / areas.sum()
    at = float(u[order][min(int(np.searchsorted(share, q)), len(order) - 1)])
    return Placement(name, searcher.centre + at * np.asarray(axis, dtype=float), axis, "largest")


def grow(s, count, frames, min_segment, until):
    """Proposals of `count` planes grown from proposals of count - 1 (a designer adds a plane to a
    set that holds): the (count - 1)-plane family proposals (largest contours) screened for up to a
    quarter of the screens left before `until` (a count of screens), the GROW_BASES that pass with
    the fewest crossings closer than 2 * min_segment along a wire (then the largest closest gap)
    each extended by one plane along each of its three axes at every area quantile of
    GROW_QUANTILES (area_quantile_plane) and screened, up to half the screens left. Returns the
    extended sets that pass the screen as auto's
    pool entries, fewest close gaps first, then the largest closest gap. The families' evenly spread
    planes often put crossings closer than 2 * min_segment along some wire (man, N = 6: every
    proposal), and planes at uneven places, which no spread gives, keep them apart."""
    began = s.screened
    limit = began + (until - began) // 4
    bases = []
    for spread, by, counts, axes in itertools.product(SPREADS, ("area", "extent"), splits_of(count - 1), frames):
        if s.screened >= limit or s.should_stop():
            break
        placements = family_planes(s, counts, "largest", spread, axes, by)
        ok, _design, probe = s.screen_layered(placements)
        if ok:
            gap = plane_faults.closest_gap(probe)
            bases.append((close_gaps(probe, min_segment), -(gap[0] if gap else math.inf), counts, axes, placements))
    bases.sort(key=lambda b: b[:2])
    limit = began + (until - began) // 2
    out = []
    for _close, _gap, counts, axes, placements in bases[:GROW_BASES]:
        names = _family_names(axes)
        for k in range(3):
            for q in GROW_QUANTILES:
                if s.screened >= limit or s.should_stop():
                    return sorted(out, key=lambda t: t[:2])
                added = area_quantile_plane(s, axes[k], q, f"{names[k]}{counts[k]}")
                ok, design, probe = s.screen_layered(placements + [added])
                if ok:
                    gap = plane_faults.closest_gap(probe)
                    out.append((close_gaps(probe, min_segment), -(gap[0] if gap else math.inf),
                                tuple(c + (j == k) for j, c in enumerate(counts)), axes, placements + [added],
                                design, f" (grown: the last along {_axis_word(axes[k], k)} at {q:.0%} of the "
                                        "surface area)"))
    return sorted(out, key=lambda t: t[:2])


def auto(mesh, count, material, settings, want=2, budget=None, context=None, stock=None):
    """Up to `want` stable, buildable plane sets of `count` planes proposed from the mesh alone,
    best score first (see the module's docstring), and the Searcher. `budget`: the wall-clock guard
    in seconds (None: auto_budget(count)); the work is bounded by counts (auto_limits(count)), and
    every share below is a share of them. Proposals: every split of `count` over three axes using at least two
    (balanced first), every spread of SPREADS, in the principal axes' frame and (when it differs)
    the world's; each with the largest contour of every plane and, when that does not pass the
    screen, with the contours of the network's largest connected part (Searcher.connected).
    Screening (up to half the screens) keeps the proposals the layering finds stable; they are
    verified by full solves with the layering's hooks in order of how many crossings come closer
    than 2 * min_segment along a wire (fewest first), then the fidelity of their contours (highest
    first); the stable ones are ranked by the fidelity of their solved wires (the score) and the
    best gets the comparison of hook patterns (Searcher.finish)."""
    s = Searcher(mesh, material, settings, context, stock)
    start = time.perf_counter()
    budget = auto_budget(count) if budget is None else budget
    s.guard, s.budget = s.clock() + budget, budget
    s.limits = auto_limits(count)
    screens = s.limits["candidates"]
    frames = [s.axes] + ([np.eye(3)] if np.abs(np.abs(s.axes) - np.eye(3)).max() > 1e-6 else [])
    min_segment = float(settings.get("min_segment") or 0.0)
    proposals = itertools.product(SPREADS, ("area", "extent"), splits_of(count), frames)
    seen, found, passed = set(), [], 0

    def screen_some(limit, soft=math.inf):
        """Screens proposals until `limit` screens in all or EARLY_SOLVES of them pass with no close
        gap, or until `soft` screens when none has passed without one by then (or the guard);
        returns the passing ones, and whether proposals remain."""
        nonlocal passed
        batch, clean = [], 0
        for spread, by, counts, axes in proposals:
            placements = family_planes(s, counts, "largest", spread, axes, by)
            ok, design, probe = s.screen_layered(placements)
            if not ok:
                joined = s.connected(placements)
                if joined is None or all(p.contours == [0] for p in joined):
                    joined = None
                else:
                    key = tuple((p.key(), tuple(p.contours)) for p in joined)
                    joined = None if key in seen else joined
                    seen.add(key)
                if joined is not None:
                    placements = joined
                    ok, design, probe = s.screen_layered(placements)
            if ok:
                # --- fidelity: verified highest fidelity of the contours first (core/fidelity.py) ---
                batch.append((close_gaps(probe, min_segment), -(s.fidelity(design)["share"] or 0.0), counts, axes,
                              placements, design, ""))
                clean += batch[-1][0] == 0
            if (clean >= EARLY_SOLVES or s.screened >= limit or (not clean and s.screened >= soft)
                    or s.should_stop()):
                passed += len(batch)
                return batch, True
        passed += len(batch)
        return batch, False

    more, pool, first, grown = True, [], True, None
    while more and len(found) < want and not (s.should_stop() or s.out_of_work()):
        # screening up to half the screens at first (a quarter when no proposal passes without close
        # crossings by then: grow follows), later up to half of what is left; verifying the pool
        # (fewest close gaps first) after each round
        batch, more = (screen_some(screens // 2, screens // 4) if first else
                       screen_some(s.screened + (screens - s.screened) // 2))
        first = False
        pool = sorted(pool + batch, key=lambda t: t[:2])
        s.say("plane_search", f"{passed} of {s.screened} proposals pass the screen; "
                              f"{sum(1 for t in pool if t[0] == 0)} to verify without crossings closer than "
                              f"2 x min_segment along a wire")
        if grown is None and count >= 3 and not any(t[0] == 0 for t in pool):
            # no proposal keeps its crossings apart: sets grown from count - 1 planes, verified first
            grown = grow(s, count, frames, min_segment, screens)
            s.say("plane_search", f"{len(grown)} sets grown from {count - 1} planes pass the screen")
        while (grown or pool) and len(found) < want and not (s.should_stop() or s.out_of_work(("full_solves",))):
            close, _looks, counts, axes, placements, design, extra = (grown or pool).pop(0)
            solved = s.solve(copy.deepcopy(design))
            if solved is None or not solved["stable"]:
                continue
            rule = "" if all(p.contours == "largest" for p in placements) else ", the connected contours"
            found.append({"planes": placements, "changes": [f"{len(placements)} planes: " + ", ".join(
                f"{n} along {_axis_word(axes[k], k)}" for k, n in enumerate(counts) if n) + rule + extra],
                "cost": 0.0, "design": solved, "figures": _figures(solved), "sliced": design})
            found[-1]["score"] = score = s.looks(found[-1])  # score = fidelity (of the solved wires)
            # --- end of fidelity ---
            s.say("plane_search", f"candidate {len(found)}: {found[-1]['changes'][0]} (score {score:.3f})")
    # a design whose assembly needs two wires placed at once (two_hand_steps) comes after every
    # design that can be built one wire at a time, then one that does not stand in 3D after every one
    # that does, whatever its score
    found.sort(key=lambda c: (bool(c["design"].get("two_hand_steps")), stands_first(c), -c["score"]))
    if found:
        s.finish(found[0])
    return found, s, start
