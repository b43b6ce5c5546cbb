"""Live's settle time is counted from the depsgraph update that evaluated a moved plane, not from
the tick that first sees it (operators/live.py): on a viewport whose redraws take longer than
SETTLE_SECONDS (software OpenGL) the timer only runs after the redraw that evaluated the move, so
counting from that tick cost one more redraw before the solve started. The clock here is
live.time, replaced by a counter the test sets, and the ticks are called by hand (no timer runs in
the background), so no time is measured.

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- live_settle
"""
import time
import unittest
from unittest import mock

import bpy

from wiresculpt import native
from wiresculpt.operators import live

from helpers import BlenderCase as Case, globe


class Clock:
    """A stand-in for the time module inside operators/live.py: monotonic() is `now`."""

    def __init__(self, now):
        self.now = now

    def monotonic(self):
        return self.now

    def perf_counter(self):
        return time.perf_counter()


@unittest.skipUnless(native.available(), "the native module is not built")
class Settle(Case):
    def setUp(self):
        super().setUp()
        globe()
        self.clock = Clock(1000.0)
        patch = mock.patch.object(live, "time", self.clock)
        patch.start()
        self.addCleanup(patch.stop)
        self.addCleanup(live.stop)
        bpy.context.scene.wiresculpt.live = True  # starts the timer; the ticks below are called here
        self.finish_job()
        self.assertEqual(live.STATE.verdict, "stable")

    def finish_job(self):
        """Ticks until a started job has been shown (its thread joined: nothing waits on the clock)."""
        for _ in range(5):
            self.clock.now += 0.02
            live.tick()
            if live.STATE.job is not None:
                live.STATE.job.thread.join(60.0)
                self.clock.now += 0.02
                live.tick()
                return
        self.fail(f"no live job started: {live.STATE.verdict!r}")

    def move(self, dz):
        self.clock.now += 0.005  # after the previous tick
        plane = next(o for o in bpy.context.scene.objects if o.name.startswith("Slice"))
        plane.location.z += dz
        bpy.context.view_layer.update()  # the depsgraph update that evaluates it (its handler runs)

    def test_a_move_evaluated_a_redraw_ago_is_solved_at_the_first_tick(self):
        self.move(0.01)  # evaluated at `now`, then a redraw of 0.2 s before the timer runs again
        self.clock.now += 0.2
        live.tick()
        self.assertIsNotNone(live.STATE.job, "the first tick after the redraw should start the solve")
        self.finish_job()

    def test_a_move_evaluated_just_now_still_waits_to_settle(self):
        self.move(0.01)
        self.clock.now += 0.01  # within SETTLE_SECONDS of its evaluation: the plane may still move
        live.tick()
        self.assertIsNone(live.STATE.job)
        self.assertEqual(live.STATE.verdict, "solving…")
        self.clock.now += live.SETTLE_SECONDS + 0.001
        live.tick()
        self.assertIsNotNone(live.STATE.job)
        self.finish_job()

    def test_a_change_without_a_depsgraph_update_settles_from_the_tick_that_sees_it(self):
        # An update long before the previous tick says nothing about when this change came.
        self.clock.now += 0.005
        bpy.context.scene.wiresculpt.contours[0].use = False  # a contour unticked
        live._EVALUATED[0] = self.clock.now - 10.0  # whatever update its change caused came before the tick
        self.clock.now += 0.2
        live.tick()
        self.assertIsNone(live.STATE.job)
        self.clock.now += live.SETTLE_SECONDS + 0.001
        live.tick()
        self.assertTrue(live.STATE.job is not None or live.STATE.verdict.startswith("not stable"),
                        (live.STATE.verdict, live.STATE.running, bpy.context.scene.wiresculpt.live))


if __name__ == "__main__":
    unittest.main()
