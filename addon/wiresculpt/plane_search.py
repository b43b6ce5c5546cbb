"""The plane assistant (issue 15): placements of the slicing planes that give a stable, buildable
design. bpy-free, on top of the pipeline (pipeline.slice_and_pick, stages.layering, pipeline.solve);
the batch (settings.plane_search) and the add-on's operators both call it.

Two searches:

- `nearby(...)`: the user's planes, changed as little as possible. A *change* moves a plane along
  its normal by d, tilts it by an angle a about an axis in the plane (about the plane's point
  nearest the mesh's centre) or changes which contours it takes ("largest" <-> "all"). Its cost,
  the measure the search minimises, is

      cost = sum over changed planes of ( |d| / S  +  a / 1 rad  +  0.05 per contour-rule change )

  with S the model size (largest side of the mesh's bounding box): 5 % of the model's size costs
  as much as a tilt of 0.05 rad (2.9 deg). Candidates are one-plane changes (offsets
  +-{2, 4, 7, 10, 15, 20} % of S, tilts of 5, 10, 15 deg about two axes each way, the other
  contour rule), then pairs of one-plane changes of two different planes, tried in order of cost.
- `auto(...)`: planes from the mesh alone: `count` planes in families along the mesh's principal
  axes (area-weighted), each family spread evenly over the mesh's extent along its axis (one plane
  of a family goes through the centre: the mesh's symmetry plane when it has one). Candidates are
  the ways to split `count` over the three axes (at least two families), each with four spreads
  (SPREADS), in the principal frame and the world's, solved in order of coverage.

Every candidate is screened cheaply first: slicing (each plane placement sliced once, cached) and
the layering (stages.layering), whose first step is the hook-relaxed stability check (every
crossing a ball joint: a mechanism is rejected in about a millisecond) and whose search then
finds the hooks. Only survivors run the full pipeline (pipeline.solve: target shape, forces, rest
shape, buildability), and a candidate is returned only when that says stable (which means
buildable, fab/buildability).

Score of a returned candidate (documented in docs/formats.md, higher is better):

    score = coverage - 10 * max_deviation / S          (auto; a design with two-hand assembly
                                                        steps ranks after every one without)
    score = -cost                                      (nearby)

coverage: the share of the mesh's vertices within 0.1 S of some wire's contour; max_deviation:
the largest distance of a target shape from its contour (target_max_distance).
"""
import copy
import itertools
import math
import threading
import time

import numpy as np

from . import pipeline
from .core import ordered
from .core.ordered import InOrder
from .core.scene import PlaneSpec
from .stages import layering, slicing

MODES = ("off", "nearby", "auto")
OFFSETS = (0.02, 0.04, 0.07, 0.10, 0.15, 0.20)  # fractions of the model size S, both ways
TILTS_DEG = (5.0, 10.0, 15.0)
RULE_COST = 0.05
COVERAGE_RADIUS = 0.1  # fraction of S
FIDELITY_WEIGHT = 10.0
BUDGET_SECONDS = 8.0  # the 10 s for a nearby search on a five-plane scene, with room


class Placement:
    """One plane as the search places it (a PlaneSpec plus what changed and what that costs)."""

    def __init__(self, name, origin, normal, contours, changes=(), cost=0.0):
        self.name, self.origin, self.contours = name, tuple(float(c) for c in origin), contours
        self.normal = tuple(float(c) for c in _unit(normal))
        self.changes, self.cost = list(changes), cost

    def spec(self):
        return PlaneSpec(self.name, self.origin, self.normal, self.contours)

    def key(self):
        return (tuple(round(c, 12) for c in self.origin), tuple(round(c, 12) for c in self.normal))

    def as_dict(self):
        return {"name": self.name, "origin": [float(c) for c in self.origin],
                "normal": [float(c) for c in self.normal], "contours": self.contours}


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def mesh_frame(vertices, faces):
    """(centre, axes 3x3 rows: principal axes by decreasing spread, size S) of the mesh surface
    (area-weighted triangle centroids)."""
    V = np.asarray(vertices, dtype=float)
    F = np.asarray(faces, dtype=np.int64)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    w = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    cent = (a + b + c) / 3.0
    if w.sum() <= 0:
        w = np.ones(len(F))
    centre = (w[:, None] * cent).sum(axis=0) / w.sum()
    x = cent - centre
    cov = (w[:, None] * x).T @ x / w.sum()
    values, vectors = np.linalg.eigh(cov)
    axes = vectors[:, ::-1].T.copy()
    for k in range(3):  # each axis pointing to its largest positive world component
        if axes[k][int(np.argmax(np.abs(axes[k])))] < 0:
            axes[k] = -axes[k]
    if np.ptp(values) < 1e-2 * max(values.max(), 1e-30):  # a sphere-like spread: the world axes
        axes = np.eye(3)
    size = float(np.max(V.max(axis=0) - V.min(axis=0)))
    return centre, axes, size


def _perpendiculars(n):
    n = _unit(n)
    u = np.cross(n, [0.0, 0.0, 1.0] if abs(n[2]) < 0.9 else [1.0, 0.0, 0.0])
    u = _unit(u)
    return u, np.cross(n, u)


def _direction_word(n, sign):
    """'up'/'down' for a z-like normal, else '+x'-style words for the move along sign*n."""
    d = sign * _unit(n)
    k = int(np.argmax(np.abs(d)))
    if abs(d[k]) > 0.9:
        if k == 2:
            return "up" if d[k] > 0 else "down"
        return f"{'+' if d[k] > 0 else '-'}{'xyz'[k]}"
    return "along its normal" if sign > 0 else "against its normal"


def single_changes(plane, centre, size):
    """Every one-plane change of `plane` (a PlaneSpec) as Placements, cheapest first."""
    n = _unit(plane.normal)
    o = np.asarray(plane.origin, dtype=float)
    pivot = centre - float((centre - o) @ n) * n  # the plane's point nearest the mesh's centre
    out = []
    for f in OFFSETS:
        for sign in (1.0, -1.0):
            d = sign * f * size
            out.append(Placement(plane.name, pivot + d * n, n, plane.contours,
                                 [f"move plane {plane.name} {_direction_word(n, sign)} {abs(d) * 1000:.0f} mm"],
                                 abs(d) / size))
    u, v = _perpendiculars(n)
    for deg in TILTS_DEG:
        a = math.radians(deg)
        for axis, label in ((u, "u"), (-u, "u"), (v, "v"), (-v, "v")):
            turned = n * math.cos(a) + np.cross(axis, n) * math.sin(a)  # n turned about `axis` by a
            out.append(Placement(plane.name, pivot, _unit(turned), plane.contours,
                                 [f"tilt plane {plane.name} by {deg:g}\N{DEGREE SIGN} "
                                  f"(normal to {np.round(_unit(turned), 3).tolist()})"], a))
    other = "all" if plane.contours != "all" else "largest"
    out.append(Placement(plane.name, plane.origin, n, other,
                         [f"plane {plane.name}: use {'every contour' if other == 'all' else 'the largest contour'}"],
                         RULE_COST))
    out.sort(key=lambda p: p.cost)
    return out


class Searcher:
    """Slicing cache, screening and full solves for one mesh, material and settings."""

    def __init__(self, vertices, faces, material, settings, progress=None, cancel=None, stock=None):
        self.V, self.F = vertices, faces
        self.stock = stock  # (length, profile name) for pipeline.solve's stock-length warnings
        self.material, self.settings = material, settings
        self.say = progress or (lambda stage, message: None)
        self.cancel = cancel or (lambda: False)
        self.cache = {}
        self.mesh_info = None  # the slicer's report on the mesh (stages.slicing.mesh), from its first call
        self.screened = self.full_solves = self.timed_out = self.failed = 0
        self.workers = ordered.workers()  # full solves at once (1: the search on one thread)
        self._counting = threading.Lock()  # solve() runs on the pool's threads
        self.deadline = math.inf  # perf_counter() time at which a full solve is stopped (the budget)
        self.budget = None  # seconds
        self.centre, self.axes, self.size = mesh_frame(vertices, faces)
        self.sample = np.asarray(vertices, dtype=float)
        if len(self.sample) > 4000:
            self.sample = self.sample[np.linspace(0, len(self.sample) - 1, 4000).astype(int)]

    def _contours(self, placement):
        key = placement.key()
        if key not in self.cache:
            found, info = slicing.slice_planes(self.V, self.F, [placement.spec()], self.settings.get("weld_tolerance"))
            self.cache[key] = found[0]
            self.mesh_info = self.mesh_info or info
        return self.cache[key]

    def settings_for(self, design):
        """The settings with the user's cuts kept only for wires that exist in `design`."""
        names = {w["name"] for w in design["wires"]}
        cuts = {k: v for k, v in (self.settings.get("cuts") or {}).items() if k in names}
        return {**self.settings, "cuts": cuts}

    def sliced(self, placements):
        """A new design from the placements' cached contours (the same wires slicing.run makes)."""
        from .core import contours as rules
        from .core.design import new_design, wire_entry

        began = time.perf_counter()
        design = new_design(self.material, self.settings)
        contours = 0
        for p in placements:
            found = self._contours(p)
            if not found:
                return None  # a change that removes a plane's wire is no answer
            contours += len(found)
            for k in rules.pick(found, p.contours, p.name):
                c = found[k]
                design["wires"].append(wire_entry(len(design["wires"]), f"{p.name}/{k}", list(p.origin),
                                                  [float(x) for x in _unit(p.normal)], c["closed"], c["points"]))
        # as slicing.run records it (seconds: this design's share, each placement sliced once per search)
        design["stages"]["slicing"] = {"seconds": time.perf_counter() - began, "planes": len(placements),
                                       "contours": contours, "mesh": self.mesh_info}
        return design

    def screen(self, placements):
        """The layering's verdict on the placements (slicing + hook-relaxed check + hook search):
        (passes, the sliced design, whether the layering found crossings too close along a wire for
        the machine); an input the network refuses (planes that coincide) does not pass."""
        if self.cancel():
            raise pipeline.Cancelled()
        self.screened += 1
        try:
            design = self.sliced(placements)
            if design is None or len(design["wires"]) < 2:
                return False, design, False
            probe = copy.deepcopy(design)
            layering.run(probe, self.material, self.settings_for(design))
            return bool(probe["stable"]), design, bool(probe.get("close_crossings"))
        except (ValueError, RuntimeError):
            return False, None, False

    def solve(self, design):
        """The full pipeline on a screened design; the solved design (stable means buildable), or
        None when it fails or runs past the search's deadline (a solve is stopped there, like a
        cancel, so the budget holds however long one solve would take)."""
        self._count("full_solves")
        try:
            return pipeline.solve(design, self.material, self.settings_for(design),
                                  cancel=lambda: self.cancel() or time.perf_counter() > self.deadline, stock=self.stock)
        except (ValueError, RuntimeError):  # a candidate the solver cannot finish (an infeasible LP): no answer
            self._count("failed")
            return None
        except pipeline.Cancelled:
            if self.cancel():
                raise
            self._count("timed_out")
            return None

    def _count(self, name):
        with self._counting:
            setattr(self, name, getattr(self, name) + 1)

    def coverage(self, design):
        """Share of the mesh's (sampled) vertices within COVERAGE_RADIUS * S of a contour point."""
        points = np.concatenate([np.asarray(w["contour"], dtype=float) for w in design["wires"]])
        radius = COVERAGE_RADIUS * self.size
        near = np.zeros(len(self.sample), dtype=bool)
        for chunk in np.array_split(points, max(1, len(points) // 256)):
            d2 = ((self.sample[:, None, :] - chunk[None, :, :]) ** 2).sum(axis=2)
            near |= (d2 <= radius * radius).any(axis=1)
        return float(near.mean())

    def max_deviation(self, design):
        return max((w.get("target_max_distance", 0.0) for w in design["wires"]), default=0.0)


def _figures(design):
    """The stability figures a candidate shows: load capacity (least multiple of its weight over
    the six directions), max deviation and largest closure gap."""
    cap = design.get("load_capacity") or {}
    multiples = [v for k, v in cap.items() if k in ("+x", "-x", "+y", "-y", "+z", "-z") and isinstance(v, (int, float))]
    return {"load_capacity": min(multiples) if multiples else None,
            "max_deviation": max((w.get("target_max_distance", 0.0) for w in design["wires"]), default=0.0),
            "closure_gap": max((w.get("closure_gap", 0.0) for w in design["wires"]), default=0.0)}


def _record(mode, before, candidate, searcher, start):
    return {"mode": mode,
            "planes_before": [Placement(p.name, p.origin, p.normal, p.contours).as_dict() for p in before],
            "planes_after": [p.as_dict() for p in candidate["planes"]] if candidate else [],
            "changes": candidate["changes"] if candidate else [],
            "candidates": searcher.screened, "full_solves": searcher.full_solves,
            "budget_seconds": searcher.budget, "solves_stopped": searcher.timed_out,
            "solves_failed": searcher.failed,
            "seconds": time.perf_counter() - start, "score": candidate["score"] if candidate else None,
            "measure": ("cost = sum of |offset| / model size + tilt in radians + 0.05 per contour-rule change; "
                        "score = -cost" if mode == "nearby" else
                        "score = coverage (share of mesh vertices within 0.1 model size of a wire) "
                        "- 10 * max target deviation / model size")}


def nearby(vertices, faces, planes, material, settings, want=1, budget=BUDGET_SECONDS, progress=None, cancel=None,
           stock=None):
    """Up to `want` stable, buildable candidates near `planes`, cheapest change first:
    [{"planes": [Placement], "changes": [sentence], "cost", "score", "design", "figures"}], the
    Searcher (its counts) and the start time. The given planes themselves are candidate 0 (cost 0).
    Order: one-plane changes, then pairs; within each, by cost, except that a screened candidate
    whose layering reports crossings closer along a wire than the machine's minimum segment
    (`close_crossings`: the full pipeline mostly fails on them, at a second each) is solved only
    after the others, and only while it is cheaper than the `want`-th found, so that the answer is
    still the cheapest the budget allows."""
    s = Searcher(vertices, faces, material, settings, progress, cancel, stock)
    start = time.perf_counter()
    s.deadline, s.budget = start + budget, budget
    base = [Placement(p.name, p.origin, _unit(p.normal), p.contours) for p in planes]
    singles = {i: single_changes(p, s.centre, s.size) for i, p in enumerate(planes)}
    found = []

    def out_of_time():
        return time.perf_counter() - start > budget

    def bar():
        """The cost a candidate must beat to matter: the want-th cheapest found, else infinity."""
        costs = sorted(c["cost"] for c in found)
        return costs[want - 1] if len(costs) >= want else math.inf

    def take(tag, solved):
        """A full solve's answer, in the order one thread would have solved them: one that one
        thread would not have solved (it no longer beats the bar) is dropped."""
        cost, changes, placements = tag
        if cost >= bar() or solved is None or not solved["stable"]:
            return
        found.append({"planes": placements, "changes": [t for _, c in changes for t in c.changes], "cost": cost,
                      "score": -cost, "design": solved, "figures": _figures(solved)})
        s.say("plane_search", f"candidate {len(found)}: {'; '.join(found[-1]['changes']) or 'the planes as given'} "
                              f"(cost {cost:.3f}, {s.screened} screened, {s.full_solves} solved)")

    def phase(options):
        # Full solves run on s.workers threads while the next candidates are screened; their
        # answers are taken in order (core/ordered.py), so what is found is what one thread finds.
        deferred = []
        with InOrder(take, s.workers) as pool:
            for cost, changes in options:
                if cost >= bar() or out_of_time():
                    break
                placements = list(base)
                for i, c in changes:
                    placements[i] = c
                ok, design, close = s.screen(placements)
                if not ok:
                    continue
                if close:
                    deferred.append((cost, changes, placements, design))
                else:
                    pool.submit((cost, changes, placements), s.solve, design)
            pool.drain()
            for cost, changes, placements, design in deferred:
                if cost >= bar() or out_of_time():
                    break
                pool.submit((cost, changes, placements), s.solve, design)

    phase([(0.0, ())] + sorted(((c.cost, ((i, c),)) for i, cs in singles.items() for c in cs), key=lambda t: t[0]))
    if len(found) < want and not out_of_time():  # pairs of one-plane changes of two planes
        pairs = []
        for i, j in itertools.combinations(sorted(singles), 2):
            for a in singles[i][:12]:
                for b in singles[j][:12]:
                    pairs.append((a.cost + b.cost, ((i, a), (j, b))))
        phase(sorted(pairs, key=lambda t: t[0]))
    found.sort(key=lambda c: c["cost"])
    return found[:want], s, start


def _family_names(axes):
    names = []
    for k, a in enumerate(axes):
        j = int(np.argmax(np.abs(a)))
        names.append("XYZ"[j] if abs(a[j]) > 0.99 else "ABC"[k])
    if len(set(names)) < 3:
        names = ["A", "B", "C"]
    return names


SPREADS = ((0.2, 0.8), (0.3, 0.7), (0.12, 0.88), (0.38, 0.62))  # a family's first and last plane


def family_planes(searcher, counts, contours="largest", spread=SPREADS[0], axes=None):
    """Placements for `counts[k]` planes along axis k of `axes` (default: the principal axes),
    spread evenly from `spread[0]` to `spread[1]` of the mesh's extent along it (a family of one
    goes through the centre)."""
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
        for i in range(count):
            f = 0.5 if count == 1 else spread[0] + (spread[1] - spread[0]) * i / (count - 1)
            origin = searcher.centre + (lo + f * (hi - lo)) * axis
            out.append(Placement(f"{names[k]}{i}", origin, axis, contours))
    return out


def _axis_word(axis, k):
    j = int(np.argmax(np.abs(axis)))
    return "xyz"[j] if abs(axis[j]) > 0.99 else f"principal axis {k + 1}"


def auto(vertices, faces, count, material, settings, want=2, budget=3 * BUDGET_SECONDS, progress=None, cancel=None,
         stock=None):
    """Up to `want` stable, buildable plane sets of `count` planes proposed from the mesh alone,
    best score first (see the module's docstring), and the Searcher. Proposals: every split of
    `count` over three axes using at least two, every spread of SPREADS, in the principal axes'
    frame and (when it differs) the world's."""
    s = Searcher(vertices, faces, material, settings, progress, cancel, stock)
    start = time.perf_counter()
    s.deadline, s.budget = start + budget, budget
    splits = [c for c in itertools.product(range(count + 1), repeat=3) if sum(c) == count
              and sum(1 for x in c if x) >= 2]
    frames = [s.axes] + ([np.eye(3)] if np.abs(np.abs(s.axes) - np.eye(3)).max() > 1e-6 else [])
    screened = []
    for rule in ("largest", "all"):
        for axes, spread, counts in itertools.product(frames, SPREADS, splits):
            if time.perf_counter() - start > budget / 2:
                break
            placements = family_planes(s, counts, rule, spread, axes)
            ok, design, _close = s.screen(placements)
            if ok:
                screened.append((s.coverage(design), counts, axes, rule, placements, design))
        if screened:
            break
    screened.sort(key=lambda t: -t[0])
    found = []

    def take(tag, solved):  # in coverage order, as one thread would: past `want` found, dropped
        cover, counts, axes, rule, placements, _design = tag
        if len(found) >= want or solved is None or not solved["stable"]:
            return
        score = cover - FIDELITY_WEIGHT * s.max_deviation(solved) / s.size
        found.append({"planes": placements, "changes": [f"{len(placements)} planes: " + ", ".join(
            f"{n} along {_axis_word(axes[k], k)}" for k, n in enumerate(counts) if n)
            + ("" if rule == "largest" else ", every contour")],
            "cost": 0.0, "score": score, "coverage": cover, "design": solved, "figures": _figures(solved)})
        s.say("plane_search", f"candidate {len(found)}: {found[-1]['changes'][0]} (score {score:.3f})")

    with InOrder(take, s.workers) as pool:
        for item in screened:
            if len(found) >= want or time.perf_counter() - start > budget:
                break
            pool.submit(item, s.solve, item[-1])
    # a design whose assembly needs two wires placed at once (two_hand_steps) comes after every
    # design that can be built one wire at a time, whatever its score
    found.sort(key=lambda c: (bool(c["design"].get("two_hand_steps")), -c["score"]))
    return found, s, start


def run(vertices, faces, planes, material, settings, progress=None, cancel=None, stock=None):
    """The headless pipeline with settings.plane_search: "off" -> pipeline.run; "nearby" -> the
    given planes first, the nearby search when they give no stable design; "auto" -> planes
    from the mesh. The design carries `plane_search` whenever a search ran; when none is found the
    design of the given planes (nearby) or of the first proposal (auto) is returned, not stable,
    with the reason saying what was tried. `stock`: as pipeline.solve's. Returns (design, planes
    actually used)."""
    say = progress or (lambda stage, message: None)
    mode = settings.get("plane_search", "off")
    if mode == "off":
        return pipeline.run(vertices, faces, planes, material, settings, progress, cancel, stock), list(planes)
    if mode == "nearby":
        if not planes:
            raise ValueError('settings.plane_search "nearby" needs planes to start from; give "planes" or use "auto"')
        found, s, start = nearby(vertices, faces, planes, material, settings, 1, progress=say, cancel=cancel,
                                 stock=stock)
        if found:
            best = found[0]
            design = best["design"]
        else:
            design = pipeline.run(vertices, faces, planes, material, settings, progress, cancel, stock)
            best = None
            design["reason"] += (f"; no nearby placement ({s.screened} tried: offsets up to "
                                 f"{OFFSETS[-1] * 100:g} % of the model size, tilts up to {TILTS_DEG[-1]:g} deg, "
                                 f"contour rules, one or two planes at a time) gives a stable design"
                                 + (f" within the search's {s.budget:g} s budget" if time.perf_counter() - start > s.budget
                                    else ""))
        design["plane_search"] = _record("nearby", planes, best, s, start)
        used = [p.spec() for p in best["planes"]] if best else list(planes)
        say("plane_search", _summary(design["plane_search"]))
        return design, used
    if mode == "auto":
        count = int(settings.get("plane_count", 5))
        found, s, start = auto(vertices, faces, count, material, settings, progress=say, cancel=cancel, stock=stock)
        if found:
            best = found[0]
            design = best["design"]
            used = [p.spec() for p in best["planes"]]
        else:
            best = None
            used = [p.spec() for p in family_planes(s, (count - count // 2, count // 2, 0))]
            design = pipeline.run(vertices, faces, used, material, settings, progress, cancel, stock)
            if not design["stable"]:
                design["reason"] += (f"; no proposed set of {count} planes ({s.screened} tried) gives a "
                                     f"stable design")
        design["plane_search"] = _record("auto", planes, best or ({"planes": [
            Placement(p.name, p.origin, p.normal, p.contours) for p in used], "changes": [], "score": None}
            if design["stable"] else None), s, start)
        say("plane_search", _summary(design["plane_search"]))
        return design, used
    raise ValueError(f'settings.plane_search must be one of {", ".join(MODES)}, got {mode!r}')


def _summary(record):
    what = "; ".join(record["changes"]) or ("the planes as given" if record["planes_after"] else "nothing stable")
    return (f"{record['mode']}: {what} ({record['candidates']} candidates screened, {record['full_solves']} "
            f"full solves, {record['seconds']:.2f} s)")
