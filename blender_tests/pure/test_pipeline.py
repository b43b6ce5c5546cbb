"""The pipeline in-process: the Sec. 4.3 coupling between target and rest shape, and cancelling."""
import math
import re
import unittest
from unittest import mock

import numpy as np

from wiresculpt import native, pipeline
from wiresculpt.core import solve_context
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.scene import PlaneSpec
from wiresculpt.core.settings import defaults
from wiresculpt.stages import target_shape

from helpers import PLANES, sphere

def largest_rest_turn_deg(design):
    """The largest turning angle of any rest polyline, from its points alone."""
    worst = 0.0
    for w in design["wires"]:
        p = np.asarray(w["rest"])
        e = np.diff(p, axis=0)
        e = e[np.linalg.norm(e, axis=1) > 0]
        cross = e[:-1, 0] * e[1:, 1] - e[:-1, 1] * e[1:, 0]
        dot = np.sum(e[:-1] * e[1:], axis=1)
        worst = max(worst, float(np.max(np.degrees(np.abs(np.arctan2(cross, dot))))))
    return worst


# The soft sphere below was built so that its rest bends go about a degree past 50 deg
# without the coupling, with SLSQP's target shapes. The SQP reaches the same distances to
# the contour with the points arranged a little differently along the wires, and there the largest
# rest bend is 50.0 deg, within the limit: the case would not need the coupling. These tests are about
# the coupling, so they keep SLSQP's shapes.
SLSQP_SHAPES = mock.patch.object(target_shape, "ALGORITHM", "slsqp")


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Coupling(unittest.TestCase):
    def setUp(self):
        SLSQP_SHAPES.start()
        self.addCleanup(SLSQP_SHAPES.stop)

    def solve(self, rounds):
        settings = defaults()
        # the plastic limit and the force LP without pre-stress (torque fraction 1): rest bends that need the coupling
        settings.update(contact_angle_deg=140.0, max_bend_deg=50.0, torque_fraction=1.0, least_out_of_plane=False)
        V, F = sphere()
        saved, module = pipeline.COUPLING_ROUNDS, native.require()
        pipeline.COUPLING_ROUNDS = rounds
        saved_patterns, pipeline.HOOK_PATTERNS = pipeline.HOOK_PATTERNS, 1  # one hook pattern: count its solves
        self.calls = self.starts = 0

        class Counting:  # counts the native target-shape solves of every round
            def __getattr__(_self, name):
                if name != "optimize_target_shapes":
                    return getattr(module, name)

                def solve(problems, *args):
                    problems = list(problems)  # the stage hands a generator over
                    self.calls += len(problems)
                    self.starts += sum("start" in p["options"] for p in problems)
                    return module.optimize_target_shapes(problems, *args)
                return solve
        saved_require = native.require
        native.require = Counting
        try:
            # A soft, strong wire (k_b 0.1 N m², plastic torque 3 N m): its rest bends go past
            # 50 deg by about a degree uncoupled, which the coupling can take back.
            material = dict(PRESETS["steel"], bending_stiffness=0.1, max_torque=3.0)
            return pipeline.run(V, F, PLANES, material, settings)
        finally:
            pipeline.COUPLING_ROUNDS = saved
            pipeline.HOOK_PATTERNS = saved_patterns
            native.require = saved_require

    def test_rest_bends_respect_the_machine_after_coupling(self):
        once = self.solve(1)
        self.assertGreater(largest_rest_turn_deg(once), 50.0)  # the case needs the coupling
        # Without it the layering's verdict stood, but a bend over the limit cannot be made.
        self.assertFalse(once["stable"])
        # the limit written as the bend is, with its two decimals (native/src/figures.hpp)
        self.assertRegex(once["reason"], r"turns -?5\d\.\d\d deg, more than the machine's maximum reliable bend of "
                                         r"50\.00 deg")
        self.assertTrue(all(p["kind"] == "over_bend" for p in once["buildability"]["problems"]))
        coupled = self.solve(4)
        self.assertTrue(coupled["stable"], coupled["reason"])
        # Strictly inside: the bend program makes every wire, and the rest bends stay below 50 deg.
        self.assertLess(largest_rest_turn_deg(coupled), 50.0)
        self.assertEqual(coupled["buildability"]["problems"], [])
        stage = coupled["stages"]["target_shape"]
        self.assertGreater(stage["coupling_rounds"], 1)
        self.assertEqual(stage["rest_excess_deg"], 0.0)
        # The stage's counts add every coupling round, as its time does.
        self.assertEqual(stage["wire_solves"], self.calls)
        # Only the global limit went down (no vertex limit, below): every wire starts cold, as the
        # warm start is only for lowered vertex limits (target_shape.Memo.starts).
        self.assertEqual(self.starts, 0)
        self.assertGreater(stage["wire_solves"], len(coupled["wires"]))
        # The one bend over the limit (about 1 deg) is a hooked kink already at its least bend, so
        # no vertex limit can take it back (vertex_limits 0; before the bend program's slack was
        # applied, a bend one ulp over 50 deg got one); the other bends are lowered by its excess
        # and the margin instead, which changes the forces.
        self.assertEqual(stage["vertex_limits"], 0)
        self.assertLess(stage["max_bend_deg"], 50.0 - 0.5)
        self.assertEqual(coupled["pending_stages"], [])


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Cuts(unittest.TestCase):
    def test_a_users_cut_starts_the_rest_shape(self):
        settings = defaults()
        settings["cuts"] = {"A/0": 7}
        V, F = sphere()
        design = pipeline.run(V, F, PLANES, PRESETS["steel"], settings)
        wire = next(w for w in design["wires"] if w["name"] == "A/0")
        self.assertEqual(wire["cut"], 7)
        # docs/formats.md: rest has the target's edge lengths walked from the cut, one point more.
        target, rest = np.asarray(wire["target"]), np.asarray(wire["rest"])
        m = len(target)
        self.assertEqual(len(rest), m + 1)
        walked = [np.linalg.norm(target[(7 + j + 1) % m] - target[(7 + j) % m]) for j in range(m)]
        np.testing.assert_allclose(np.linalg.norm(np.diff(rest, axis=0), axis=1), walked, atol=1e-12)


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Cancelling(unittest.TestCase):
    def test_cancel_at_once_and_after_layering(self):
        V, F = sphere()
        for after in (0, 1):
            calls = []

            def cancel():
                calls.append(1)
                return len(calls) > after

            design = pipeline.slice_and_pick(V, F, PLANES, PRESETS["steel"], defaults())
            with self.assertRaises(pipeline.Cancelled):
                pipeline.solve(design, PRESETS["steel"], defaults(), cancel=cancel)


class Clock:
    """A stand-in for the time module in pipeline and its solve context (core/solve_context.py):
    monotonic() advances `step` seconds per call."""

    def __init__(self, step):
        import time

        self.now, self.step, self.perf_counter = 0.0, step, time.perf_counter

    def monotonic(self):
        self.now += self.step
        return self.now


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class TimeBudget(unittest.TestCase):
    """settings.max_solve_seconds: past it the solve stops with OutOfTime naming the key and the
    stage, whether the budget runs out between stages or inside the native solver's polls."""

    def solve(self, budget, step, cancel=None):
        V, F = sphere()
        settings = dict(defaults(), max_solve_seconds=budget)
        design = pipeline.slice_and_pick(V, F, PLANES, PRESETS["steel"], settings)
        saved, pipeline.time = pipeline.time, Clock(step)
        solve_context.time = pipeline.time  # one clock for both, read in the same order
        try:
            return pipeline.solve(design, PRESETS["steel"], settings, cancel=cancel)
        finally:
            pipeline.time = solve_context.time = saved

    def test_the_budget_stops_the_solve_and_names_the_key(self):
        stages = ("layering", "target shape", "forces", "rest shape", "load capacity", "relayering", "size")
        for budget in (1.5, 40.0):  # the first checkpoint, and somewhere inside the work
            with self.subTest(budget=budget), self.assertRaises(pipeline.OutOfTime) as ctx:
                self.solve(budget, 1.0)
            text = str(ctx.exception)
            self.assertTrue(text.startswith(f"the solve stopped at its time budget, settings.max_solve_seconds = "
                                            f"{budget:g} s, during the "), text)
            self.assertTrue(any(f"during the {s}:" in text for s in stages), text)
            self.assertIsInstance(ctx.exception, RuntimeError)  # the batch's one-line error, exit 1

    def test_the_same_clock_with_room_to_spare_finishes(self):
        design = self.solve(1e12, 1.0)
        self.assertTrue(design["stable"], design.get("reason"))
        self.assertEqual(design["pending_stages"], [])

    def test_a_cancel_is_a_cancel_even_out_of_time(self):
        with self.assertRaises(pipeline.Cancelled) as ctx:
            self.solve(1.5, 1.0, cancel=lambda: True)
        self.assertNotIsInstance(ctx.exception, pipeline.OutOfTime)


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class StockBeforeSolving(unittest.TestCase):
    def test_wires_longer_than_the_profiles_stock_are_said_before_the_layering(self):
        V, F = sphere()
        design = pipeline.slice_and_pick(V, F, PLANES, PRESETS["steel"], defaults())
        # the contours' lengths from their points, apart from core/sizes.py
        lengths = {w["name"]: sum(math.dist(a, b) for a, b in zip(w["contour"], w["contour"][1:] + w["contour"][:1]))
                   for w in design["wires"]}
        stock = 0.5 * (min(lengths.values()) + max(lengths.values()))
        said = []
        pipeline.solve(design, PRESETS["steel"], defaults(), progress=lambda s, m: said.append((s, m)),
                       stock=(stock, "shop bender"))
        longer = sorted(n for n, l in lengths.items() if l > stock)
        self.assertTrue(0 < len(longer) < len(lengths))
        warned = [m for s, m in said if s == "size"]
        self.assertEqual(sorted(m.split()[1] for m in warned), longer)
        for m in warned:
            # the three circles' lengths differ only by rounding, and so does the stock between them: the
            # length and the stock are written alike, with the digits it takes to read one longer
            found = re.search(r"is (\d+\.?(\d*)) mm long \(its sliced contour[^)]*\), longer than the "
                              r"(\d+\.?(\d*)) mm stock of shop bender", m)
            self.assertIsNotNone(found, m)
            self.assertGreater(float(found[1]), float(found[3]))
            self.assertEqual(len(found[2]), len(found[4]))
            self.assertAlmostEqual(float(found[3]), stock * 1000, places=6)
        stages = [s for s, _m in said]
        self.assertLess(max(i for i, s in enumerate(stages) if s == "size"), stages.index("layering"))
        # the design keeps the solved wires' figures: each stock warning's mm is the wire's own length
        # (docs/formats.md "length", what its DXF and G-code are cut to), not the contour's said above
        solved = pipeline.solve(pipeline.slice_and_pick(V, F, PLANES, PRESETS["steel"], defaults()), PRESETS["steel"],
                                defaults(), stock=(stock, "shop bender"))
        kept = {}
        for m in solved["warnings"]:
            found = re.search(r"wire (\S+) is (\d+\.?\d*) mm long, longer than the", m)
            if found:
                kept[found[1]] = found[2]
        by_name = {w["name"]: w for w in solved["wires"]}
        solved_lengths = {n: sum(math.dist(a, b) for a, b in zip(w["target"], w["target"][1:] + w["target"][:1]))
                          for n, w in by_name.items()}
        self.assertEqual(sorted(kept), sorted(n for n, l in solved_lengths.items() if l > stock))
        for name, mm in kept.items():
            decimals = len(mm.partition(".")[2])
            self.assertAlmostEqual(float(mm), solved_lengths[name] * 1000, delta=0.5 * 10 ** -decimals + 1e-9)
            self.assertAlmostEqual(by_name[name]["length"], solved_lengths[name], places=9)


if __name__ == "__main__":
    unittest.main()


def eq12(target, torque, l_bar, k_b):
    """The paper's Eq. 12 (signs for counter-clockwise angles, rest_shape.hpp), written apart from
    pipeline.rest_angle: the rest angle of a target angle under a torque."""
    t = math.tan(target / 2)
    return 2 * math.atan(t + torque / ((4 * k_b / l_bar) * (1 + t * t)))


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class LoadCapacityOfTheLastRound(unittest.TestCase):
    """The coupling rounds skip the load capacity (native load_capacity_within) in a round whose
    rest bends are over the limit, the rounds that are solved again: the design is the same as
    with it computed in every round, from one load capacity instead of one per round. On the soft
    sphere of Coupling, which needs more than one round (with SLSQP's shapes, SLSQP_SHAPES)."""

    def setUp(self):
        SLSQP_SHAPES.start()
        self.addCleanup(SLSQP_SHAPES.stop)

    def solve(self, deferred, tighten=None):
        settings = defaults()
        settings.update(contact_angle_deg=140.0, max_bend_deg=50.0, torque_fraction=1.0, least_out_of_plane=False)
        V, F = sphere()
        material = dict(PRESETS["steel"], bending_stiffness=0.1, max_torque=3.0)
        self.assertIn("density", material)  # the load capacity is computed at all
        module, run, saved_tighten = native.require(), pipeline.forces.run, pipeline._tighten
        computed = []

        class Counting:  # which forces_and_rest calls computed a load capacity
            def __getattr__(_self, name):
                if name != "forces_and_rest":
                    return getattr(module, name)

                def call(*args):
                    r = module.forces_and_rest(*args)
                    computed.append(r["load_capacity"] is not None)
                    return r
                return call

        def every_round(design, material, settings, native_progress=None, load_capacity_within=None):
            return run(design, material, settings, native_progress)

        saved_require, saved_patterns = native.require, pipeline.HOOK_PATTERNS
        native.require, pipeline.HOOK_PATTERNS = Counting, 1
        if not deferred:
            pipeline.forces.run = every_round
        if tighten:
            pipeline._tighten = tighten
        try:
            return pipeline.run(V, F, PLANES, material, settings), computed
        finally:
            native.require, pipeline.HOOK_PATTERNS = saved_require, saved_patterns
            pipeline.forces.run, pipeline._tighten = run, saved_tighten

    def assertSameDesign(self, a, b):
        self.assertEqual(a["load_capacity"], b["load_capacity"])
        self.assertEqual(a.get("load_factor"), b.get("load_factor"))
        self.assertEqual(a["warnings"], b["warnings"])
        self.assertEqual((a["stable"], a.get("reason")), (b["stable"], b.get("reason")))
        self.assertEqual([c.get("normal_force") for c in a["crossings"]], [c.get("normal_force") for c in b["crossings"]])
        self.assertEqual([w["rest_angles"] for w in a["wires"]], [w["rest_angles"] for w in b["wires"]])

    def test_one_load_capacity_for_the_same_design(self):
        deferred, calls = self.solve(True)
        every, calls_every = self.solve(False)
        self.assertGreater(deferred["stages"]["target_shape"]["coupling_rounds"], 1)  # the case it is about
        self.assertEqual(len(calls), len(calls_every))
        self.assertTrue(all(calls_every))
        self.assertEqual(calls, [False] * (len(calls) - 1) + [True])
        self.assertSameDesign(deferred, every)

    def test_rounds_that_stop_over_the_limit_still_get_it(self):
        # _tighten changing nothing stops the rounds after the first, its rest bends still over the
        # limit: the load capacity it skipped is computed then, and its warnings are not repeated.
        def nothing(design, memo, limit, kink):
            return 0, 0.0

        deferred, calls = self.solve(True, nothing)
        every, _ = self.solve(False, nothing)
        self.assertGreater(deferred["stages"]["target_shape"]["rest_excess_deg"], 0.0)
        self.assertEqual(calls, [False, True])
        self.assertSameDesign(deferred, every)


class CouplingStep(unittest.TestCase):
    """pipeline._tighten on the vertex measured on the corpus (bear, zzxxy5, 0.75 m; wire X1/0,
    target vertex 40): target bend 120.000 deg at the limit, rest 120.089 deg from its torque."""

    def design(self, target_deg, rest_deg):
        angles = [0.0, math.radians(target_deg), 0.0]
        rests = [0.0, math.radians(rest_deg), 0.0]
        return {"wires": [{"name": "X1/0", "closed": True, "cut": 39, "target": [[0, 0, 0]] * 60,
                           "target_angles": angles, "rest_angles": rests}]}

    def test_the_vertex_gets_the_limit_that_puts_its_rest_bend_inside(self):
        memo = pipeline.target_shape.Memo()
        changed, stuck = pipeline._tighten(self.design(120.0, 120.089), memo, 120.0, 20.01)
        self.assertEqual((changed, stuck), (1, 0.0))
        limit = memo.vertex_limits["X1/0"][40]  # position 1 from the cut at 39
        # The torque read back from the two angles (any l_bar, k_b: only t l_bar / k_b matters).
        k_b, l_bar = 0.73, 0.03
        t = math.tan(math.radians(60.0))
        torque = (math.tan(math.radians(120.089) / 2) - t) * (1 + t * t) * 4 * k_b / l_bar
        self.assertAlmostEqual(math.degrees(eq12(math.radians(120.0), torque, l_bar, k_b)), 120.089, places=9)
        self.assertAlmostEqual(math.degrees(eq12(limit, torque, l_bar, k_b)), 120.0 - pipeline.COUPLING_MARGIN_DEG,
                               places=6)
        self.assertLess(math.degrees(limit), 120.0)

    def test_a_kink_at_its_least_bend_is_left_to_the_global_limit(self):
        memo = pipeline.target_shape.Memo()
        changed, stuck = pipeline._tighten(self.design(40.0, 51.046), memo, 50.0, 40.01)
        self.assertEqual(changed, 0)
        self.assertAlmostEqual(stuck, 1.046, places=9)
        self.assertEqual(memo.vertex_limits.get("X1/0", {}), {})


class OverBendSlack(unittest.TestCase):
    """A rest bend counts as over the machine's limit only beyond the bend program's own slack
    (1e-12 rad, native/src/fab/bend_program.cpp kAngleSlack): rounding one ulp over 120 deg is at
    the limit (the Airplane stand-in spent two coupling rounds on 1.4e-14 deg), 1e-9 rad is over."""

    @staticmethod
    def design(*angles):
        return {"wires": [{"rest_angles": list(angles)}]}

    def test_rounding_is_at_the_limit(self):
        at = math.radians(120.0)
        ulp_over = math.nextafter(at, 4.0)
        self.assertGreater(ulp_over, at)
        self.assertEqual(pipeline._largest_over_bend(self.design(ulp_over, -ulp_over, 0.1), 120.0), 0.0)
        self.assertEqual(pipeline._largest_over_bend(self.design(at + 0.9e-12), 120.0), 0.0)

    def test_beyond_the_slack_is_over(self):
        at = math.radians(120.0)
        self.assertAlmostEqual(pipeline._largest_over_bend(self.design(0.2, -(at + 1e-9)), 120.0),
                               math.degrees(1e-9), delta=1e-13)
        self.assertAlmostEqual(pipeline._largest_over_bend(self.design(at + math.radians(0.5)), 120.0), 0.5, delta=1e-9)

    def test_within_is_zero(self):
        self.assertEqual(pipeline._largest_over_bend(self.design(0.3, -1.0), 120.0), 0.0)
        self.assertEqual(pipeline._largest_over_bend({"wires": [{}]}, 120.0), 0.0)
