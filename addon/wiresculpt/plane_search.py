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
  contour rule: 25 per plane), tried in order of cost, then pairs of one-plane changes of two
  different planes (25 x 25 per pair of planes), those whose two changes, each screened alone,
  together free every wire at fault in the given planes first (plane_faults.Tally.pair_order), each
  group by cost. When none gives a stable design, the search's reason (nearby_reason) says what it
  searched, whether the budget cut it short and how much was left, its candidates counted by fault
  in each family (plane_faults), and what to change.
- `auto(...)`: planes from the mesh alone: `count` planes in families along the mesh's principal
  axes (area-weighted) or the world's, each family spread over the mesh's extent along its axis or
  over the quantiles of its surface area (family_planes), for every split of `count` over the three
  axes (balanced first) and every spread of SPREADS; each with the largest contour of every plane,
  and, when that fails the screen, the contours of the crossing network's largest connected part
  without hinged wires (Searcher.connected). Screened proposals are verified fewest crossings
  closer than 2 * min_segment along a wire first (close_gaps), then by coverage; budget
  auto_budget(count) = AUTO_SECONDS_PER_PLANE * count. When no proposal of the first screening
  round keeps its crossings 2 * min_segment apart, sets grown from count - 1 planes (grow: a
  family proposal plus one plane at an area quantile along one of its axes) are screened and
  verified first.

Every candidate is screened cheaply first: slicing (each plane placement sliced once per search,
the planes of many candidates in one native call, Searcher.slice_ahead; the designs share each
contour's points, and the layering's copy of a design copies no points) and the layering
(stages.layering), whose first step is the hook-relaxed stability check (every
crossing a ball joint: a mechanism is rejected in about a millisecond) and whose search then
finds the hooks; both without the hooks the target shape cannot realise at crossings too close
along a wire (Searcher._layer). Only survivors run the full pipeline (pipeline.solve: target shape, forces, rest
shape, buildability) with the layering's own hooks (CANDIDATE_HOOK_PATTERNS), and a candidate is
returned only when that says stable (which means buildable, fab/buildability). The returned
design then gets the comparison of hook patterns by their forces (Searcher.finish), bounded by
FINAL_HOOK_SECONDS / FINAL_SECONDS; when that does not end stable in time, the verified design
is kept.

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
import time

import numpy as np

from . import native, pipeline
from .core import plane_faults
from .core.plane_faults import Tally, close_gaps, crossing_gaps  # noqa: F401 (the search's names for them)
from .core.scene import PlaneSpec
from .core.sizes import mesh_size
from .stages import layering, slicing, target_shape

MODES = ("off", "nearby", "auto")
OFFSETS = (0.02, 0.04, 0.07, 0.10, 0.15, 0.20)  # fractions of the model size S, both ways
TILTS_DEG = (5.0, 10.0, 15.0)
RULE_COST = 0.05
COVERAGE_RADIUS = 0.1  # fraction of S
FIDELITY_WEIGHT = 10.0
BUDGET_SECONDS = 8.0  # the 10 s for a nearby search on a five-plane scene, with room
AUTO_SECONDS_PER_PLANE = 6.0  # auto's search budget: this many seconds per plane (24 s for N = 4)
# Candidates are verified by full solves with the layering's own hooks (pipeline.solve with
# hook_patterns=1, as Live does: 0.2-4 s on the corpus); the comparison of hook patterns by their
# forces (issue 16: up to 64 patterns, seconds to a minute) runs once, on the returned design, within
# FINAL_HOOK_SECONDS (no new pattern after it) and stopped at FINAL_SECONDS; when it does not end
# stable in time, the verified design (stable and buildable with the layering's hooks) is returned.
CANDIDATE_HOOK_PATTERNS = 1
EARLY_SOLVES = 3  # auto verifies as soon as this many screened proposals have no close gap
SCREEN_SECONDS = 2.0  # a screen's layering longer than this does not pass (a search of many contours)
FINAL_HOOK_SECONDS = 10.0
FINAL_SECONDS = 20.0
PAIR_SINGLES = 25  # the two-plane changes pair each plane's this many cheapest one-plane changes (all 25)
SLICE_AHEAD = 32  # nearby slices the changed planes of this many candidates in one call (Searcher.slice_ahead)


class Placement:
    """One plane as the search places it (a PlaneSpec plus what changed and what that costs)."""

    def __init__(self, name, origin, normal, contours, changes=(), cost=0.0):
        self.name, self.origin, self.contours = name, tuple(float(c) for c in origin), contours
        self.normal = tuple(float(c) for c in _unit(normal))
        self.changes, self.cost = list(changes), cost
        self._key = None

    def spec(self):
        return PlaneSpec(self.name, self.origin, self.normal, self.contours)

    def key(self):
        """(origin, normal) rounded to 1e-12: the slicing cache's key (made once; a search asks
        for it several times per candidate)."""
        if self._key is None:
            self._key = (tuple(round(c, 12) for c in self.origin), tuple(round(c, 12) for c in self.normal))
        return self._key

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
    return centre, axes, mesh_size(V)


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
        self.cache = {}  # placement key -> the slicer's contours of the plane
        # repr(placement key) -> the slicer's message refusing the plane (_contours raises it); by
        # repr, as a refused key may hold a NaN, which is not equal to itself
        self.refused = {}
        self.points = {}  # (placement key, contour index) -> (list, array) of its points (_points)
        self.mesh_info = None  # the slicer's report on the mesh (stages.slicing.mesh), from its first call
        self.screened = self.full_solves = self.timed_out = self.failed = 0
        self.final = None  # what finish() did with the returned design
        self.fault = None  # why the last screen did not pass (plane_faults), None when it passed
        self.empty = None  # the plane of the last _sliced() that found no contour
        self.tally = None  # the nearby search's account of its candidates (plane_faults.Tally)
        self.surface = None  # (triangle centroids, areas) of the mesh, made by _surface when first needed
        self.deadline = math.inf  # perf_counter() time at which a full solve is stopped (the budget)
        self.budget = None  # seconds
        self.centre, self.axes, self.size = mesh_frame(vertices, faces)
        self.sample = np.asarray(vertices, dtype=float)
        if len(self.sample) > 4000:
            self.sample = self.sample[np.linspace(0, len(self.sample) - 1, 4000).astype(int)]

    def _contours(self, placement):
        """The slicer's contours of `placement`; ValueError with the slicer's message when it
        refused the plane (raised here, inside the screen of the candidate that holds it)."""
        key = placement.key()
        if key not in self.cache and repr(key) not in self.refused:
            self.slice_ahead([placement])
        if repr(key) in self.refused:
            raise ValueError(self.refused[repr(key)])
        return self.cache[key]

    def slice_ahead(self, placements):
        """Slices every placement of `placements` not yet in the cache, in one native call: the
        slicer prepares (welds, cleans) the mesh once per call, which on the corpus' meshes costs
        ten times a plane's cut (armadillo, 52,000 triangles: 7.8 ms a call of one plane, 0.7 ms a
        plane in a call of 30). A plane's contours do not depend on the others in the call. When
        the call refuses one of several placements, each is sliced alone and the refused ones are
        remembered with the slicer's message (`refused`), so that the refusal reaches only the
        candidates that hold them, when _contours reads them. Never raises ValueError itself: a
        look-ahead must not end the search."""
        todo = {}
        for p in placements:
            todo.setdefault(p.key(), p)
        for key in [k for k in todo if k in self.cache or repr(k) in self.refused]:
            del todo[key]
        if not todo:
            return
        try:
            found, info = slicing.slice_planes(self.V, self.F, [p.spec() for p in todo.values()],
                                               self.settings.get("weld_tolerance"))
        except ValueError as refusal:
            if len(todo) == 1:
                self.refused[repr(next(iter(todo)))] = str(refusal)
                return
            for p in todo.values():
                self.slice_ahead([p])
            return
        self.mesh_info = self.mesh_info or info
        for key, contours in zip(todo, found):
            self.cache[key] = contours

    def _points(self, placement, k, contour):
        """Contour `k` of `placement` (the slicer's `contour`) as (the design's list of [x, y, z],
        float64 (n, 3) array), made once per search: every design sliced from the placement shares
        them, so they are never changed in place (the layering replaces a wire's contour, and
        solves get deep copies)."""
        key = (placement.key(), k)
        if key not in self.points:
            array = np.array(contour["points"], dtype=np.float64)  # a copy of its own, read-only
            array.flags.writeable = False  # shared by every design of the placement: never changed in place
            self.points[key] = (array.tolist(), array)
        return self.points[key]

    def settings_for(self, design):
        """The settings with the user's cuts kept only for wires that exist in `design`."""
        names = {w["name"] for w in design["wires"]}
        cuts = {k: v for k, v in (self.settings.get("cuts") or {}).items() if k in names}
        return {**self.settings, "cuts": cuts}

    def _sliced(self, placements):
        """(a new design from the placements' cached contours, the same wires slicing.run makes;
        the float64 arrays of its wires' contours) or (None, None) when a plane finds no contour."""
        from .core import contours as rules
        from .core.design import new_design, wire_entry

        began = time.perf_counter()
        design = new_design(self.material, self.settings)
        design["model_size"] = self.size  # the mesh's, as pipeline.slice_and_pick records it (core/sizes)
        arrays = []
        contours = 0
        self.slice_ahead(placements)
        for p in placements:
            found = self._contours(p)
            if not found:
                self.empty = p.name
                return None, None  # a change that removes a plane's wire is no answer
            contours += len(found)
            for k in rules.pick(found, p.contours, p.name):
                c = found[k]
                points, array = self._points(p, k, c)
                wire = wire_entry(len(design["wires"]), f"{p.name}/{k}", list(p.origin),
                                  [float(x) for x in _unit(p.normal)], c["closed"], ())
                wire["contour"] = points  # shared with every design of this placement (_points)
                design["wires"].append(wire)
                arrays.append(array)
        # as slicing.run records it (seconds: this design's share, each placement sliced once per search)
        design["stages"]["slicing"] = {"seconds": time.perf_counter() - began, "planes": len(placements),
                                       "contours": contours, "mesh": self.mesh_info}
        return design, arrays

    @staticmethod
    def _probe(design, arrays):
        """A copy of the sliced `design` for layering.run to fill in, without copying its points:
        its own design, wire and stages dicts (what the layering sets), each wire's contour the
        array of the same points (the layering reads it and puts the contour with the crossing
        points inserted in its place)."""
        probe = dict(design, stages=dict(design["stages"]),
                     wires=[dict(w, contour=a) for w, a in zip(design["wires"], arrays)])
        if "warnings" in design:
            probe["warnings"] = list(design["warnings"])
        return probe

    def screen(self, placements):
        """The layering's verdict on the placements (slicing + hook-relaxed check + hook search):
        (passes, the sliced design, whether the layering found crossings too close along a wire for
        the machine); an input the network refuses (planes that coincide) does not pass."""
        ok, design, probe = self.screen_layered(placements)
        return ok, design, bool(probe and probe.get("close_crossings"))

    def screen_layered(self, placements):
        """As screen, with the layered copy of the design instead of the close-crossings flag:
        (passes, the sliced design, the layered design or None)."""
        if self.cancel():
            raise pipeline.Cancelled()
        self.screened += 1
        self.fault = None
        try:
            design, arrays = self._sliced(placements)
            if design is None or len(design["wires"]) < 2:
                self.fault = ("misses", (), (self.empty,)) if design is None else ("few", (), ())
                return False, design, None
            probe = self._probe(design, arrays)
            self._layer(probe, design)
            if not probe["stable"]:
                self.fault = plane_faults.screen_fault(probe, lambda: self._decided_by_too_close(design, arrays))
            return bool(probe["stable"]), design, probe
        except (ValueError, RuntimeError, native.Cancelled) as exc:
            if self.cancel():
                raise pipeline.Cancelled() from None
            self.fault = (("slow", (), ()) if isinstance(exc, native.Cancelled) else
                          ("refused", (), (str(exc).split(";", 1)[0][:120],)))
            return False, None, None  # refused, or its layering ran past the deadline

    def _decided_by_too_close(self, design, arrays):
        """Whether the hooks a screen forbade as too close decided its verdict: with every hook the
        layering's hook-relaxed check passes and its search, stopped after one node, is not over
        (or found a stable structure). About a millisecond; asked only of screens that failed with
        such hooks forbidden and no structural fault."""
        every = self._probe(design, arrays)
        self._layer(every, design, too_close=False, max_nodes=1)
        return bool(every["stable"] or every.get("search_incomplete"))

    def _layer(self, probe, design, too_close=True, **settings):
        """layering.run on `probe`, stopped (native.Cancelled) by a cancel, past the deadline or
        after SCREEN_SECONDS: a layering search can take many seconds on a network of many small
        contours (elephant, N = 6: one took the whole screening time), and a screen is to be cheap.
        The hooks that the target shape cannot realise for want of a free bending point between
        two crossings (too_close, the native too_close_hooks) are forbidden: a placement that needs
        them could only fail its full solve (measured on man's nearby search: of the 288
        placements that passed the screen with every hook, 252 then failed it in about 1 ms
        instead of a 20 ms hook search, and the full solves fell from 304 to the few that can
        still be stable). The probe's contours come back as arrays (`arrays`): as lists, a list per
        point, the garbage collector's walks over them took 2 of the 5.6 s of man's 6376 screens.
        `too_close=False` allows every hook; `settings` override the search's (max_nodes)."""
        stop = min(self.deadline, time.perf_counter() + SCREEN_SECONDS)
        layering.run(probe, self.material, dict(self.settings_for(design), **settings),
                     lambda _stage, _fraction: not (self.cancel() or time.perf_counter() > stop),
                     too_close=target_shape.REALISED_ANGLE if too_close else None, arrays=True)

    def connected(self, placements):
        """The placements with, for each plane, the contours ("all" of them) that belong to the
        largest connected part of the crossing network (the part that crosses the most planes, then
        has the most crossings) after dropping, again and again, every wire that crosses fewer than
        two other wires: a contour that crosses no other wire or hangs apart from the rest is left
        out, and so is one that crosses a single other wire, since two planar wires cross only on
        their planes' common line, about which it would turn (a hinge). None when no part reaches
        every plane (a plane would have no wire) or the network refuses the input."""
        every = [Placement(p.name, p.origin, p.normal, "all") for p in placements]
        design, arrays = self._sliced(every)
        if design is None or len(design["wires"]) < 2:
            return None
        probe = self._probe(design, arrays)
        try:
            self._layer(probe, design)
        except (ValueError, RuntimeError, native.Cancelled):
            if self.cancel():
                raise pipeline.Cancelled() from None
            return None
        partners = {i: set() for i in range(len(probe["wires"]))}
        for c in probe["crossings"]:
            a, b = c["wires"]
            partners[a].add(b)
            partners[b].add(a)
        kept = set(partners)
        while True:
            weak = {i for i in kept if len(partners[i] & kept) < 2}
            if not weak:
                break
            kept -= weak
        crossings = [c for c in probe["crossings"] if set(c["wires"]) <= kept]
        parent = list(range(len(probe["wires"])))

        def root(i):
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i
        for c in crossings:
            a, b = (root(w) for w in c["wires"])
            parent[a] = b
        parts = {}
        for c in crossings:
            parts.setdefault(root(c["wires"][0]), []).append(c)
        best, best_key = None, None
        for r, crossings in parts.items():
            wires = {i for i in kept if root(i) == r}
            planes = {probe["wires"][i]["name"].rsplit("/", 1)[0] for i in wires}
            key = (len(planes), len(crossings))
            if best_key is None or key > best_key:
                best, best_key = wires, key
        if best is None or best_key[0] < len(placements):
            return None
        chosen = {}
        for i in sorted(best):
            plane, k = probe["wires"][i]["name"].rsplit("/", 1)
            chosen.setdefault(plane, []).append(int(k))
        return [Placement(p.name, p.origin, p.normal, sorted(chosen[p.name])) for p in placements]

    def solve(self, design, hook_patterns=CANDIDATE_HOOK_PATTERNS, hook_seconds=None, deadline=None):
        """The full pipeline on a screened design; the solved design (stable means buildable), or
        None when it fails or runs past the search's deadline (a solve is stopped there, like a
        cancel, so the budget holds however long one solve would take). `hook_patterns`: as
        pipeline.solve's (default: the layering's own hooks, see CANDIDATE_HOOK_PATTERNS);
        `deadline`: instead of the search's."""
        self.full_solves += 1
        stop = self.deadline if deadline is None else deadline
        try:
            return pipeline.solve(design, self.material, self.settings_for(design),
                                  cancel=lambda: self.cancel() or time.perf_counter() > stop, stock=self.stock,
                                  hook_patterns=hook_patterns, hook_seconds=hook_seconds)
        except (ValueError, RuntimeError):  # a candidate the solver cannot finish (an infeasible LP): no answer
            self.failed += 1
            return None
        except pipeline.Cancelled:
            if self.cancel():
                raise
            self.timed_out += 1
            return None

    def finish(self, candidate):
        """The comparison of hook patterns by their forces (pipeline.solve's default, issue 16) on a
        candidate verified with the layering's hooks (its "sliced" design, unsolved): its design
        is replaced when that solve ends stable within FINAL_SECONDS, else kept. Records
        self.final: {"hook_search": "by forces" or "the layering's hooks", "seconds", "why"}."""
        began, stopped = time.perf_counter(), self.timed_out
        solved = self.solve(copy.deepcopy(candidate["sliced"]), hook_patterns=None, hook_seconds=FINAL_HOOK_SECONDS,
                            deadline=began + FINAL_SECONDS)
        if solved is not None and solved["stable"]:
            candidate["design"], candidate["figures"] = solved, _figures(solved)
            self.final = {"hook_search": "by forces", "seconds": time.perf_counter() - began}
        else:
            why = (f"stopped at {FINAL_SECONDS:g} s" if self.timed_out > stopped else
                   "the solver could not finish it" if solved is None else f"not stable: {solved['reason']}")
            self.final = {"hook_search": "the layering's hooks", "seconds": time.perf_counter() - began, "why": why}
        return candidate

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
            "solves_failed": searcher.failed, "final_solve": searcher.final,
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
    Order: one-plane changes by cost, then pairs (plane_faults.Tally.pair_order: those that the
    single changes' faults point at first, then by cost); within each, except that a screened candidate
    whose layering reports crossings closer along a wire than the machine's minimum segment
    (`close_crossings`; before the screen left out the hooks such crossings cannot get, the full
    pipeline failed on most of them, at a second each; now they are rarer, and kept last) is solved only
    after the others, and only while it is cheaper than the `want`-th found, so that the answer is
    still the cheapest one-plane change the budget allows (a pair: the cheapest of its group, the
    search stopping at the first pair that costs more than the `want`-th found). When none is found,
    the Searcher's tally (plane_faults.Tally) holds the account nearby_reason words."""
    s = Searcher(vertices, faces, material, settings, progress, cancel, stock)
    start = time.perf_counter()
    s.deadline, s.budget = start + budget, budget
    min_segment = float(settings.get("min_segment") or 0.0)
    base = [Placement(p.name, p.origin, _unit(p.normal), p.contours) for p in planes]
    singles = {i: single_changes(p, s.centre, s.size) for i, p in enumerate(planes)}
    pairs = [(a.cost + b.cost, ((i, a), (j, b))) for i, j in itertools.combinations(sorted(singles), 2)
             for a in singles[i][:PAIR_SINGLES] for b in singles[j][:PAIR_SINGLES]]
    tally = s.tally = Tally(base, singles, len(pairs))
    found = []

    def out_of_time():
        return time.perf_counter() - start > budget

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
            if cost >= bar() or out_of_time():
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
    tally.out_of_time = out_of_time()
    found.sort(key=lambda c: c["cost"])
    if found:
        s.finish(found[0])
    return found[:want], s, start


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
    """auto's search budget in seconds for `count` planes (the final hook comparison comes on top:
    at most FINAL_SECONDS)."""
    return AUTO_SECONDS_PER_PLANE * max(int(count), 1)


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
    quarter of the time left before `until`, the GROW_BASES that pass with the fewest crossings
    closer than 2 * min_segment along a wire (then the largest closest gap) each extended by one
    plane along each of its three axes at every area quantile of GROW_QUANTILES (area_quantile_plane)
    and screened, up to half the time left. Returns the extended sets that pass the screen as auto's
    pool entries, fewest close gaps first, then the largest closest gap. The families' evenly spread
    planes often put crossings closer than 2 * min_segment along some wire (man, N = 6: every
    proposal), and planes at uneven places, which no spread gives, keep them apart."""
    began = time.perf_counter()
    s.deadline = began + (until - began) / 4
    bases = []
    for spread, by, counts, axes in itertools.product(SPREADS, ("area", "extent"), splits_of(count - 1), frames):
        if time.perf_counter() > s.deadline:
            break
        placements = family_planes(s, counts, "largest", spread, axes, by)
        ok, _design, probe = s.screen_layered(placements)
        if ok:
            gap = plane_faults.closest_gap(probe)
            bases.append((close_gaps(probe, min_segment), -(gap[0] if gap else math.inf), counts, axes, placements))
    bases.sort(key=lambda b: b[:2])
    s.deadline = began + (until - began) / 2
    out = []
    for _close, _gap, counts, axes, placements in bases[:GROW_BASES]:
        names = _family_names(axes)
        for k in range(3):
            for q in GROW_QUANTILES:
                if time.perf_counter() > s.deadline:
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


def auto(vertices, faces, count, material, settings, want=2, budget=None, progress=None, cancel=None,
         stock=None):
    """Up to `want` stable, buildable plane sets of `count` planes proposed from the mesh alone,
    best score first (see the module's docstring), and the Searcher. `budget`: seconds (None:
    auto_budget(count)). Proposals: every split of `count` over three axes using at least two
    (balanced first), every spread of SPREADS, in the principal axes' frame and (when it differs)
    the world's; each with the largest contour of every plane and, when that does not pass the
    screen, with the contours of the network's largest connected part (Searcher.connected).
    Screening (up to half the budget) keeps the proposals the layering finds stable; they are
    verified by full solves with the layering's hooks in order of how many crossings come closer
    than 2 * min_segment along a wire (fewest first), then coverage; the best found gets the
    comparison of hook patterns (Searcher.finish)."""
    s = Searcher(vertices, faces, material, settings, progress, cancel, stock)
    start = time.perf_counter()
    budget = auto_budget(count) if budget is None else budget
    s.deadline, s.budget = start + budget / 2, budget  # screening: up to half the budget
    frames = [s.axes] + ([np.eye(3)] if np.abs(np.abs(s.axes) - np.eye(3)).max() > 1e-6 else [])
    min_segment = float(settings.get("min_segment") or 0.0)
    proposals = itertools.product(SPREADS, ("area", "extent"), splits_of(count), frames)
    seen, found, passed = set(), [], 0

    def screen_some(limit, soft=math.inf):
        """Screens proposals until `limit` (perf_counter time) or EARLY_SOLVES of them pass with
        no close gap, or until `soft` when none has passed without one by then; returns the passing
        ones, and whether proposals remain."""
        nonlocal passed
        s.deadline = limit
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
                batch.append((close_gaps(probe, min_segment), -s.coverage(design), counts, axes, placements, design,
                              ""))
                clean += batch[-1][0] == 0
            if clean >= EARLY_SOLVES or time.perf_counter() > limit or (not clean and time.perf_counter() > soft):
                passed += len(batch)
                return batch, True
        passed += len(batch)
        return batch, False

    more, pool, first, grown = True, [], True, None
    while more and len(found) < want and time.perf_counter() - start < budget:
        # screening up to half the budget at first (a quarter when no proposal passes without close
        # crossings by then: grow follows), later up to half of what is left; verifying the pool
        # (fewest close gaps first) after each round
        now = time.perf_counter()
        batch, more = (screen_some(start + budget / 2, start + budget / 4) if first else
                       screen_some(now + (start + budget - now) / 2))
        first = False
        s.deadline = start + budget
        pool = sorted(pool + batch, key=lambda t: t[:2])
        s.say("plane_search", f"{passed} of {s.screened} proposals pass the screen; "
                              f"{sum(1 for t in pool if t[0] == 0)} to verify without crossings closer than "
                              f"2 x min_segment along a wire")
        if grown is None and count >= 3 and not any(t[0] == 0 for t in pool):
            # no proposal keeps its crossings apart: sets grown from count - 1 planes, verified first
            grown = grow(s, count, frames, min_segment, start + budget)
            s.deadline = start + budget
            s.say("plane_search", f"{len(grown)} sets grown from {count - 1} planes pass the screen")
        while (grown or pool) and len(found) < want and time.perf_counter() - start < budget:
            close, cover, counts, axes, placements, design, extra = (grown or pool).pop(0)
            solved = s.solve(copy.deepcopy(design))
            if solved is None or not solved["stable"]:
                continue
            cover = -cover
            score = cover - FIDELITY_WEIGHT * s.max_deviation(solved) / s.size
            rule = "" if all(p.contours == "largest" for p in placements) else ", the connected contours"
            found.append({"planes": placements, "changes": [f"{len(placements)} planes: " + ", ".join(
                f"{n} along {_axis_word(axes[k], k)}" for k, n in enumerate(counts) if n) + rule + extra],
                "cost": 0.0, "score": score, "coverage": cover, "design": solved, "figures": _figures(solved),
                "sliced": design})
            s.say("plane_search", f"candidate {len(found)}: {found[-1]['changes'][0]} (score {score:.3f})")
    # a design whose assembly needs two wires placed at once (two_hand_steps) comes after every
    # design that can be built one wire at a time, whatever its score
    found.sort(key=lambda c: (bool(c["design"].get("two_hand_steps")), -c["score"]))
    if found:
        s.finish(found[0])
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
            if not design["stable"]:
                design["reason"] = (f"{nearby_reason(s)}. The planes as given: {design['reason']}"
                                    if design["reason"] else nearby_reason(s))
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


def nearby_reason(searcher):
    """Why the nearby search `searcher` ran found no stable placement (plane_faults.Tally.report):
    what it searched, how far the budget let it, its candidates counted by fault, what to change."""
    s = searcher
    return s.tally.report(OFFSETS[-1] * s.size * 1000.0, s.size * 1000.0, TILTS_DEG[-1], s.budget,
                          float(s.settings.get("min_segment") or 0.0))


def _summary(record):
    what = "; ".join(record["changes"]) or ("the planes as given" if record["planes_after"] else "nothing stable")
    return (f"{record['mode']}: {what} ({record['candidates']} candidates screened, {record['full_solves']} "
            f"full solves, {record['seconds']:.2f} s)")
