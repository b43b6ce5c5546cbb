"""The Searcher: for one mesh, material and settings, the slicing cache, the cheap screen (slicing
and the layering, without the hooks the target shape cannot realise at crossings too close along a
wire) and the full solves (pipeline.solve) of the candidates that pass it."""
import copy
import math
import time

import numpy as np

from .. import native, pipeline
from ..core import fidelity, plane_faults
from ..core.solve_context import OutOfTime, SolveContext
from ..stages import layering, slicing, target_shape
from .placements import Placement, _unit, mesh_frame

COVERAGE_RADIUS = 0.1  # fraction of S
# Candidates are verified by full solves with the layering's own hooks (pipeline.solve with
# hook_patterns=1, as Live does: 0.2-4 s on the corpus); the comparison of hook patterns by their
# forces (up to FINAL_HOOK_PATTERNS patterns, seconds to a minute) runs once, on the returned
# design; when it does not end stable, the verified design (stable and buildable with the
# layering's hooks) is returned.
#
# What the search chooses is bounded by counts of work, never by the clock, so that a scene gives
# the same design on any machine and under any load: candidates screened and full solves (each
# search's own limits, nearby.py and auto.py), a screen's layering search nodes (SCREEN_NODES: a
# screen that needs more does not pass, "incomplete") and the final comparison's hook patterns
# (FINAL_HOOK_PATTERNS). The wall clock only stops a search that takes too long: its guard
# (`budget_seconds`; FINAL_SECONDS for the final comparison), after which the search returns what
# it has with `stopped_by` "time", and the run's one budget (settings.max_solve_seconds, the
# context's deadline), after which the run ends with OutOfTime naming the plane search.
CANDIDATE_HOOK_PATTERNS = 1
SCREEN_NODES = 5000  # a screen's layering search stops after this many nodes (a search of many contours)
FINAL_HOOK_PATTERNS = 16  # the final comparison of hook patterns: at most this many (about the 10 s it had)
FINAL_SECONDS = 120.0  # the final comparison's wall-clock guard (stopped_by "time" when it fires)
SCREEN_SECONDS = None  # gone: a screen is bounded by SCREEN_NODES (kept for the package's names)
FINAL_HOOK_SECONDS = None  # gone: the final comparison is bounded by FINAL_HOOK_PATTERNS


class Searcher:
    """Slicing cache, screening and full solves for one mesh, material and settings. `mesh`:
    (vertices, faces); `context`: a core.solve_context.SolveContext, whose say reports the search's
    progress and whose cancel stops it, whose deadline is the run's one budget (OutOfTime past it)
    and whose clock every wall-clock bound reads (None: silent, never cancelled, no deadline);
    `stock`: (length, profile name) for pipeline.solve's stock-length warnings. The search's own
    guard (`guard`, a clock time; `budget`, its seconds) is set by the search that holds it."""

    def __init__(self, mesh, material, settings, context=None, stock=None):
        self.V, self.F = mesh
        self.stock = stock
        self.material, self.settings = material, settings
        self.context = SolveContext() if context is None else context
        self.say = self.context.say
        self.cancel = self.context.cancelled
        self.clock = self.context.clock
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
        self.outlines = None  # the mesh's three views (core/fidelity.Silhouettes), made by fidelity() when first needed
        self.guard = math.inf  # clock() time after which the search stops (its wall-clock guard)
        self.budget = None  # the guard's seconds (`budget_seconds`)
        self.limits = {}  # the search's counts of work ({"candidates": n, "full_solves": m}), set by it
        self.verified = 0  # full solves of candidates (the final comparison not counted)
        self.screens_cut = 0  # screens whose layering SCREEN_NODES stopped
        self.time_stopped = self.count_stopped = False  # what ended the search before it was done
        self.centre, self.axes, self.size = mesh_frame(self.V, self.F)
        self.sample = np.asarray(self.V, dtype=float)
        if len(self.sample) > 4000:
            self.sample = self.sample[np.linspace(0, len(self.sample) - 1, 4000).astype(int)]

    def over_time(self):
        """Whether the search's wall-clock guard has passed (it then stops, `stopped_by` "time")."""
        if self.clock() > self.guard:
            self.time_stopped = True
        return self.time_stopped

    def should_stop(self):
        """At a step of the search: OutOfTime past the run's one budget (it comes before the search's
        own guard), else whether the guard has passed (over_time)."""
        self._run_out()
        return self.over_time()

    def out_of_work(self, which=("candidates", "full_solves")):
        """Whether a count of the search's limits (`limits`: those named by `which`) is reached:
        the search then stops, `stopped_by` "count" (the caller asks only when there is more to do)."""
        done = {"candidates": self.screened, "full_solves": self.verified}
        if any(done[k] >= self.limits.get(k, math.inf) for k in which):
            self.count_stopped = True
            return True
        return False

    def stopped_by(self):
        """What ended the search: "time" (its guard), "count" (a limit of `limits`) or "done"."""
        return "time" if self.time_stopped else "count" if self.count_stopped else "done"

    def _run_out(self):
        """Raises OutOfTime, naming the plane search, past the run's one budget (the context's)."""
        if self.context.out_of_time():
            raise OutOfTime(self.context.budget, "plane_search")

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
        from ..core import contours as rules
        from ..core.design import new_design, wire_entry

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
        self._run_out()
        self.screened += 1
        self.fault = None
        try:
            design, arrays = self._sliced(placements)
            if design is None or len(design["wires"]) < 2:
                self.fault = ("misses", (), (self.empty,)) if design is None else ("few", (), ())
                return False, design, None
            probe = self._probe(design, arrays)
            self._layer(probe, design)
            self.screens_cut += bool(probe.get("search_incomplete"))
            if not probe["stable"]:
                self.fault = plane_faults.screen_fault(probe, lambda: self._decided_by_too_close(design, arrays))
            return bool(probe["stable"]), design, probe
        except (ValueError, RuntimeError, native.Cancelled) as exc:
            if self.cancel():
                raise pipeline.Cancelled() from None
            self._run_out()
            self.fault = (("slow", (), ()) if isinstance(exc, native.Cancelled) else
                          ("refused", (), (str(exc).split(";", 1)[0][:120],)))
            return False, None, None  # refused, or its layering ran past the guard

    def _decided_by_too_close(self, design, arrays):
        """Whether the hooks a screen forbade as too close decided its verdict: with every hook the
        layering's hook-relaxed check passes and its search, stopped after one node, is not over
        (or found a stable structure). About a millisecond; asked only of screens that failed with
        such hooks forbidden and no structural fault."""
        every = self._probe(design, arrays)
        self._layer(every, design, too_close=False, max_nodes=1)
        return bool(every["stable"] or every.get("search_incomplete"))

    def _layer(self, probe, design, too_close=True, **settings):
        """layering.run on `probe`, stopped (native.Cancelled) by a cancel, past the guard or the
        run's deadline, and its search after SCREEN_NODES nodes (or the settings' max_nodes, when
        fewer; the probe is then "search_incomplete"): a layering search can take many seconds on a
        network of many small contours (elephant, N = 6: one took the whole screening time), and a
        screen is to be cheap; a count of nodes, not seconds, so that the verdict is the same on any
        machine.
        The hooks that the target shape cannot realise for want of a free bending point between
        two crossings (too_close, the native too_close_hooks) are forbidden: a placement that needs
        them could only fail its full solve (measured on man's nearby search: of the 288
        placements that passed the screen with every hook, 252 then failed it in about 1 ms
        instead of a 20 ms hook search, and the full solves fell from 304 to the few that can
        still be stable). The probe's contours come back as arrays (`arrays`): as lists, a list per
        point, the garbage collector's walks over them took 2 of the 5.6 s of man's 6376 screens.
        `too_close=False` allows every hook; `settings` override the search's (max_nodes)."""
        nodes = min(int(layering.knob(self.settings, "max_nodes")), SCREEN_NODES)
        settings = dict({"max_nodes": nodes}, **settings)
        layering.run(probe, self.material, dict(self.settings_for(design), **settings),
                     lambda _stage, _fraction: not (self.cancel() or self.over_time() or self.context.out_of_time()),
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
            self._run_out()
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
        None when it fails or runs past the search's guard (a solve is stopped there, like a
        cancel, so the guard holds however long one solve would take). The solve keeps the run's
        one budget (the context's deadline: OutOfTime past it, raised). `hook_patterns`: as
        pipeline.solve's (default: the layering's own hooks, see CANDIDATE_HOOK_PATTERNS);
        `deadline`: a clock time at which it is stopped too (the final comparison's guard)."""
        self.full_solves += 1
        self.verified += deadline is None
        self._run_out()
        stop = math.inf if deadline is None else deadline
        try:
            return pipeline.solve(design, self.material, self.settings_for(design), self.context.quiet(),
                                  # past the run's budget the solve's own OutOfTime (naming its stage)
                                  # comes before the guard's stop
                                  cancel=lambda: self.cancel() or ((self.over_time() or self.clock() > stop)
                                                                   and not self.context.out_of_time()),
                                  stock=self.stock, hook_patterns=hook_patterns, hook_seconds=hook_seconds)
        except OutOfTime:  # the run's budget: the run ends
            raise
        except (ValueError, RuntimeError):  # a candidate the solver cannot finish (an infeasible LP): no answer
            self.failed += 1
            return None
        except pipeline.Cancelled:
            if self.cancel():
                raise
            self.timed_out += 1
            return None

    def finish(self, candidate):
        """The comparison of hook patterns by their forces (pipeline.solve's default) on a
        candidate verified with the layering's hooks (its "sliced" design, unsolved): at most
        FINAL_HOOK_PATTERNS patterns, no time bound on them; its design is replaced when that
        solve ends stable, else kept. Stopped by the search's guard or FINAL_SECONDS, whichever
        comes first (the search is then "stopped_by" "time"). Records self.final: {"hook_search":
        "by forces" or "the layering's hooks", "seconds", "why"}."""
        began, stopped = self.clock(), self.timed_out
        solved = self.solve(copy.deepcopy(candidate["sliced"]), hook_patterns=FINAL_HOOK_PATTERNS,
                            hook_seconds=math.inf, deadline=began + FINAL_SECONDS)
        if solved is not None and solved["stable"]:
            candidate["design"], candidate["figures"] = solved, _figures(solved)
            self.looks(candidate)
            self.final = {"hook_search": "by forces", "seconds": self.clock() - began}
        else:
            if self.timed_out > stopped:
                self.time_stopped = True
            why = (f"stopped at {min(FINAL_SECONDS, self.budget or math.inf):g} s" if self.timed_out > stopped else
                   "the solver could not finish it" if solved is None else f"not stable: {solved['reason']}")
            self.final = {"hook_search": "the layering's hooks", "seconds": self.clock() - began, "why": why}
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

    # --- how the design looks like the model (core/fidelity.py) ---
    def fidelity(self, design):
        """The design's `fidelity` record (core/fidelity.py) against the mesh's three views, rendered
        on the first call (0.2-1 s on the corpus' meshes)."""
        if self.outlines is None:
            self.outlines = fidelity.Silhouettes(self.V, self.F, self.size)
        return self.outlines.of_design(design)

    def looks(self, candidate):
        """Writes the candidate design's `fidelity` record, and its coverage and fidelity (the record's
        share, 0 when no view has an outline) into the candidate and its figures; returns the share."""
        design = candidate["design"]
        record = design["fidelity"] = self.fidelity(design)
        candidate["coverage"] = cover = candidate["coverage"] if "coverage" in candidate else self.coverage(design)
        candidate["fidelity"] = share = record["share"] or 0.0
        candidate["figures"].update(coverage=cover, fidelity=share, views=dict(record["views"]))
        return share
    # --- end of fidelity ---

    def max_deviation(self, design):
        return max((w.get("target_max_distance", 0.0) for w in design["wires"]), default=0.0)


def _figures(design):
    """The stability figures a candidate shows: load capacity (least multiple of its weight over
    the six directions), max deviation and largest closure gap, and the 3D check's verdict:
    `stands_3d` (true when the assembled sculpture stands, stages/stands3d.py; None when the check
    did not run), its `cause` and `sag` (m, the largest distance of a wire from its target)."""
    cap = design.get("load_capacity") or {}
    multiples = [v for k, v in cap.items() if k in ("+x", "-x", "+y", "-y", "+z", "-z") and isinstance(v, (int, float))]
    record = design.get("stands_3d") or {}
    return {"load_capacity": min(multiples) if multiples else None,
            "max_deviation": max((w.get("target_max_distance", 0.0) for w in design["wires"]), default=0.0),
            "closure_gap": max((w.get("closure_gap", 0.0) for w in design["wires"]), default=0.0),
            "stands_3d": record.get("stands"), "cause_3d": record.get("cause"), "sag": record.get("max_sag")}


def stands_first(candidate):
    """0 for a candidate whose assembled sculpture stands in the 3D check, 1 otherwise: the key
    both searches rank by before their own score (a design that stands as the planar model says
    before one that slips or sags)."""
    return 0 if candidate["figures"].get("stands_3d") else 1
