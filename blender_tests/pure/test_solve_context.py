"""core/solve_context.SolveContext: what a solve's stages are handed instead of closures. Each
answer is the rule of the module's docstring, worked out by hand on a clock the test sets."""
import math
import unittest

from wiresculpt.core import solve_context
from wiresculpt.core.solve_context import Cancelled, OutOfTime, SolveContext


class Clock:
    """A stand-in for the time module: monotonic() is what the test sets."""

    def __init__(self):
        self.now = 100.0

    def monotonic(self):
        return self.now


class Context(unittest.TestCase):
    def setUp(self):
        self.clock, saved = Clock(), solve_context.time
        solve_context.time = self.clock
        self.addCleanup(setattr, solve_context, "time", saved)
        self.said = []
        self.cancelled = False
        self.context = SolveContext(lambda stage, message: self.said.append((stage, message)),
                                    lambda: self.cancelled, budget=10.0)

    def test_say_reports_and_names_the_stage_under_way(self):
        self.assertEqual(self.context.stage, "layering")  # before anything is said
        self.context.say("target_shape", "5 wires")
        self.assertEqual(self.said, [("target_shape", "5 wires")])
        self.assertEqual(self.context.stage, "target_shape")

    def test_the_quiet_view_says_nothing_and_shares_the_rest(self):
        quiet = self.context.quiet()
        quiet.say("forces", "not heard")
        self.assertEqual(self.said, [])
        self.assertEqual(self.context.stage, "layering")  # a quiet say moves no stage
        self.assertIs(quiet.same_solves, self.context.same_solves)
        self.assertIs(quiet.contour_cache, self.context.contour_cache)
        quiet.native_progress("forces", 0.5)  # the native's stage is the solve's, quiet or not
        self.assertEqual(self.context.stage, "forces")
        self.context.say("rest_shape", "heard")
        self.assertEqual(self.said, [("rest_shape", "heard")])

    def test_the_native_callback_stops_when_cancelled_or_out_of_time(self):
        self.assertTrue(self.context.native_progress("network", 0.0))
        self.assertEqual(self.context.stage, "layering")  # the solver's parts of the layering
        self.assertTrue(self.context.native_progress("check_assembly", 0.0))
        self.assertEqual(self.context.stage, "layering")
        self.clock.now = 110.0  # exactly at the deadline: still in time
        self.assertTrue(self.context.native_progress("", 0.3))
        self.clock.now = 110.001
        self.assertFalse(self.context.native_progress("forces", 0.3))
        self.assertEqual(self.context.stage, "forces")
        self.clock.now = 100.0
        self.cancelled = True
        self.assertFalse(self.context.native_progress("forces", 0.4))

    def test_checkpoint_and_stopped_tell_a_cancel_from_the_budget(self):
        self.context.checkpoint()  # in time, not cancelled: nothing
        self.context.say("forces", "")
        self.clock.now = 111.0
        with self.assertRaises(OutOfTime) as raised:
            self.context.checkpoint()
        self.assertEqual((raised.exception.budget, raised.exception.stage), (10.0, "forces"))
        self.assertIsInstance(self.context.stopped(), OutOfTime)
        self.cancelled = True  # a cancel is a cancel, even out of time
        with self.assertRaises(Cancelled):
            self.context.checkpoint()
        self.assertIs(type(self.context.stopped()), Cancelled)

    def test_without_callbacks_or_budget_it_never_stops(self):
        context = SolveContext()
        context.say("layering", "nobody listens")
        self.clock.now = 1e300
        context.checkpoint()
        self.assertTrue(context.native_progress("layering", 1.0))
        self.assertEqual(context.deadline, math.inf)


if __name__ == "__main__":
    unittest.main()
