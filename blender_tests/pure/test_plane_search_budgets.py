"""The plane search counts work, not time (plane_search/searcher.py's budgets): the same scene gives
the same design however fast the clock runs or however busy the machine is, the wall clock only
stops a search that takes too long (saying so: `stopped_by` "time"), and settings.max_solve_seconds
is one budget for the whole run, the search and every solve in it included (OutOfTime naming the
key and the plane search). The scenes are test_plane_search's spheres, whose planes are known by
hand; the clocks are the test's (SolveContext's `clock`)."""
import json
import math
import os
import subprocess
import sys
import threading
import time
import unittest

from wiresculpt import native, plane_search
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.solve_context import OutOfTime, SolveContext
from wiresculpt.plane_search import searcher

from helpers import sphere
from test_plane_search import HINGE, R, settings


def untimed(value):
    """`value` without its measured times (every key "seconds" or "..._seconds": stages, rounds, the
    forces' LP and NLP times, the record, the final solve's), as design.json holds it."""
    if isinstance(value, dict):
        return {k: untimed(v) for k, v in value.items() if not (k == "seconds" or k.endswith("_seconds"))}
    if isinstance(value, list):
        return [untimed(v) for v in value]
    return value


def as_written(design):
    """The bytes design.json would hold, without its measured times."""
    return json.dumps(untimed(json.loads(json.dumps(design))), sort_keys=True).encode()


class FastClock:
    """A clock that runs `speed` times as fast as the real one: the process as if `speed` times slower."""

    def __init__(self, speed):
        self.speed, self.began = speed, time.monotonic()

    def __call__(self):
        return self.began + self.speed * (time.monotonic() - self.began)


class Busy:
    """A CPU-bound thread beside the search for the `with` block (it takes the GIL and a core)."""

    def __enter__(self):
        self.stop = False
        self.thread = threading.Thread(target=self.spin, daemon=True)
        self.thread.start()
        return self

    def spin(self):
        n = 0
        while not self.stop:
            n = (n * 7 + 1) % 1000003

    def __exit__(self, *exc):
        self.stop = True
        self.thread.join()


def setUpModule():
    # the final comparison's patterns are a count like the others: 2 keep these tests short (a
    # sphere's symmetric designs have many patterns of equal cost), and bound them the same way
    global _saved
    _saved = searcher.FINAL_HOOK_PATTERNS
    searcher.FINAL_HOOK_PATTERNS = 2


def tearDownModule():
    searcher.FINAL_HOOK_PATTERNS = _saved


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class SameDesignAnyClock(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.V, cls.F = sphere(R)

    def searches(self, context=None, budget=None):
        """(nearby on HINGE, auto of 4 planes): their designs and records, with `context` and the guard
        `budget` (None: each search's own)."""
        mesh = (self.V, self.F)
        near = {} if budget is None else {"budget": budget}
        found, s, _ = plane_search.nearby(mesh, HINGE, PRESETS["steel"], settings(), 1, context=context, **near)
        found_auto, a, _ = plane_search.auto(mesh, 4, PRESETS["steel"], settings(), context=context, budget=budget)
        self.assertTrue(found and found_auto)
        return [(found[0]["design"], s.stopped_by(), s.screened, s.full_solves),
                (found_auto[0]["design"], a.stopped_by(), a.screened, a.full_solves)]

    def test_a_clock_a_million_times_fast_changes_nothing_but_the_times(self):
        # every guard lifted (the searches' budgets, the final comparison's): a choice that read the
        # clock anywhere would see 10^6 times the seconds and choose otherwise
        saved = searcher.FINAL_SECONDS
        searcher.FINAL_SECONDS = math.inf
        try:
            quick = self.searches(SolveContext(), budget=math.inf)
            slow = self.searches(SolveContext(clock=FastClock(1e6)), budget=math.inf)
        finally:
            searcher.FINAL_SECONDS = saved
        for (d0, by0, n0, k0), (d1, by1, n1, k1) in zip(quick, slow):
            self.assertEqual((by0, by1), ("done", "done"))
            self.assertEqual((n0, k0), (n1, k1))
            self.assertEqual(as_written(d0), as_written(d1))
            self.assertTrue(d0["stable"])

    def test_the_batch_entry_slowed_gives_the_same_bytes(self):
        # through plane_search.run with the default guards and budget: once quietly, once with a clock
        # five times fast and a CPU-bound thread beside it (the target shape's two threads scheduled
        # otherwise); the designs, the records' counts and what stopped them are the same
        def both(clock=None):
            out = []
            for mode, planes, extra in (("nearby", HINGE, {}), ("auto", [], {"plane_count": 4})):
                design, used = plane_search.run(self.V, self.F, planes, PRESETS["steel"],
                                                settings(plane_search=mode, **extra), SolveContext(clock=clock))
                self.assertTrue(design["stable"], design["reason"])
                self.assertEqual(design["plane_search"]["stopped_by"], "done")
                out.append((as_written(design), [p.name for p in used]))
            return out
        quiet = both()
        with Busy():
            busy = both(FastClock(5.0))
        self.assertEqual(quiet, busy)

    def test_the_guard_stops_a_search_and_says_so(self):
        # a clock 10^9 times fast: the nearby search's 60 s guard passes within its first screens
        context = SolveContext(clock=FastClock(1e9))
        found, s, _ = plane_search.nearby((self.V, self.F), HINGE, PRESETS["steel"], settings(), 1, context=context)
        self.assertEqual(s.stopped_by(), "time")
        self.assertTrue(s.tally.out_of_time)
        self.assertLess(s.screened, plane_search.NEARBY_SCREENS)


# One process's nearby search on HINGE, printing the SHA-256 of its design's bytes without the times.
ONE_PROCESS = """
import hashlib, sys
sys.path[:0] = sys.argv[1:]
from wiresculpt import plane_search
from wiresculpt.core.materials import PRESETS
from helpers import sphere
import test_plane_search_budgets as t
V, F = sphere(t.R)
t.setUpModule()
design, _ = plane_search.run(V, F, t.HINGE, PRESETS["steel"], t.settings(plane_search="nearby"))
print(hashlib.sha256(t.as_written(design)).hexdigest())
"""


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class SameDesignAnyProcess(unittest.TestCase):
    def test_string_hashing_does_not_reach_the_design(self):
        # two processes whose string hashes differ (PYTHONHASHSEED): sets and dicts of wire and plane
        # names iterate otherwise, and the design's bytes must not show it
        here = os.path.dirname(os.path.abspath(__file__))
        path = [os.path.join(os.path.dirname(os.path.dirname(here)), "addon"), os.path.dirname(here), here]
        digests = set()
        for seed in ("1", "2"):
            r = subprocess.run([sys.executable, "-c", ONE_PROCESS, *path], capture_output=True, text=True,
                               env=dict(os.environ, PYTHONHASHSEED=seed), timeout=600)
            self.assertEqual(r.returncode, 0, r.stderr)
            digests.add(r.stdout.strip().splitlines()[-1])
        self.assertEqual(len(digests), 1)


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class CountsBoundTheWork(unittest.TestCase):
    def test_a_count_ends_a_search_with_work_left_and_says_so(self):
        # HINGE's nearby search finds a change among its one-plane changes (test_plane_search); with at
        # most 3 candidates screened it is cut after the given planes and two one-plane changes
        V, F = sphere(R)
        saved = plane_search.nearby.__globals__["NEARBY_SCREENS"]
        plane_search.nearby.__globals__["NEARBY_SCREENS"] = 3
        try:
            found, s, _ = plane_search.nearby((V, F), HINGE, PRESETS["steel"], settings(), 1)
        finally:
            plane_search.nearby.__globals__["NEARBY_SCREENS"] = saved
        self.assertEqual(s.screened, 3)
        self.assertEqual(s.stopped_by(), "count")
        self.assertEqual(found, [])  # the given planes and Z1's two cheapest changes keep W's hinge
        # 1 + 5 x 25 one-plane + 10 x 25 x 25 two-plane candidates: 6376, of which 6373 are left
        self.assertIn("The limit of 3 candidates screened ended the search after 3 of 6376 candidates: 6373 left",
                      plane_search.nearby_reason(s))


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class OneBudgetForTheRun(unittest.TestCase):
    def test_the_search_keeps_the_runs_budget(self):
        # max_solve_seconds = 5 on a clock 10^9 times fast: out of time at the search's first step,
        # whatever the search's own guard; the stage named is the plane search
        V, F = sphere(R)
        for mode, planes in (("auto", []), ("nearby", HINGE)):
            with self.subTest(mode=mode), self.assertRaises(OutOfTime) as raised:
                plane_search.run(V, F, planes, PRESETS["steel"],
                                 settings(plane_search=mode, plane_count=4, max_solve_seconds=5.0),
                                 SolveContext(clock=FastClock(1e9)))
            self.assertEqual((raised.exception.budget, raised.exception.stage), (5.0, "plane_search"))
            self.assertTrue(str(raised.exception).startswith(
                "the solve stopped at its time budget, settings.max_solve_seconds = 5 s, during the plane search"))

    def test_a_solve_inside_the_search_starts_no_budget_of_its_own(self):
        # the run's deadline passes while a full solve of the search runs: the solve ends with the
        # run's OutOfTime (not a fresh max_solve_seconds, not a failed candidate the search skips)
        V, F = sphere(R)
        clock = FastClock(1.0)
        real = searcher.pipeline.solve

        def late_solve(*args, **kwargs):
            clock.speed = 1e12  # from the first full solve on, the run's 600 s are long past
            return real(*args, **kwargs)
        searcher.pipeline.solve = late_solve
        try:
            with self.assertRaises(OutOfTime) as raised:
                plane_search.run(V, F, HINGE, PRESETS["steel"], settings(plane_search="nearby"),
                                 SolveContext(clock=clock))
        finally:
            searcher.pipeline.solve = real
        self.assertEqual(raised.exception.budget, 600.0)
        self.assertNotEqual(raised.exception.stage, "plane_search")  # a stage of the solve under way


if __name__ == "__main__":
    unittest.main()
