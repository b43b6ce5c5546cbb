"""Optimize from the UI (modal operator, worker thread, timer) in a Blender with a window, run
under Xvfb when xvfb-run is installed: completes, and Cancel leaves the scene as it was, also
when it lands inside a native stage; cancelling never waits for a worker stuck in native code."""
import os
import shutil
import unittest

from helpers import ROOT, run_under_xvfb

SCRIPT = os.path.join(ROOT, "blender_tests", "ui_optimize_modal.py")


@unittest.skipUnless(shutil.which("xvfb-run"), "xvfb-run is not installed")
class ModalOptimize(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.result, cls.seen = run_under_xvfb(SCRIPT, "MODAL ", timeout=300)

    def setUp(self):
        self.assertIsNotNone(self.seen, self.result.stdout[-3000:] + self.result.stderr[-3000:])
        self.assertNotIn("error", self.seen, self.result.stdout[-3000:] + self.result.stderr[-3000:])

    def test_runs_modal_and_writes_the_result(self):
        self.assertEqual(self.seen["invoke"], ["RUNNING_MODAL"])
        self.assertTrue(self.seen["running"])
        self.assertIn("Esc to cancel", self.seen["status_while_running"])
        self.assertTrue(self.seen["stable"])
        self.assertEqual(self.seen["wires"], 3)
        self.assertTrue(self.seen["shader"])
        self.assertTrue(self.seen["inputs_recorded"])
        self.assertEqual(self.seen["report_changes"], [])  # the Stability box: current, not "From an earlier…"

    def test_one_undo_removes_the_result(self):
        self.assertTrue(self.seen["undo_restores"])

    def test_cancel_leaves_the_scene_as_it_was(self):
        self.assertEqual(self.seen["cancel_invoke"], ["RUNNING_MODAL"])
        self.assertTrue(self.seen["cancel_running"])
        self.assertEqual(self.seen["cancel_op"], ["FINISHED"])
        self.assertTrue(self.seen["cancel_unchanged"])


    def test_cancel_inside_native_layering_and_forces(self):
        for stage in ("layering", "forces"):
            with self.subTest(stage):
                self.assertEqual(self.seen[stage + "_invoke"], ["RUNNING_MODAL"])
                self.assertEqual(self.seen[stage + "_cancel_op"], ["FINISHED"])
                self.assertEqual(self.seen[stage + "_cancelled_in"], stage)  # the native poll saw it
                self.assertTrue(self.seen[stage + "_unchanged"])
                self.assertLess(self.seen[stage + "_cancel_seconds"], 1.0)

    def test_removing_the_modal_never_waits_for_a_stuck_worker(self):
        self.assertEqual(self.seen["stuck_invoke"], ["RUNNING_MODAL"])
        # the worker sleeps 4 s (STUCK_SECONDS of ui_optimize_modal.py); the load waits 0.2 s
        self.assertLess(self.seen["stuck_load_seconds"], 1.5)
        self.assertTrue(self.seen["stuck_running_after_load"])  # the job is still cancelling
        self.assertEqual(self.seen["stuck_status"], "wiresculpt: cancelling…")
        self.assertGreaterEqual(self.seen["stuck_ticks"], 1)  # timers kept firing meanwhile
        self.assertEqual(self.seen["stuck_cancelled_in"], "forces")
        self.assertEqual(self.seen["stuck_results_in_new_scene"], 0)
