"""Optimize from the UI (modal operator, worker thread, timer) in a Blender with a window, run
under Xvfb when xvfb-run is installed: completes, and Cancel leaves the scene as it was."""
import os
import shutil
import unittest

from helpers import ROOT, run_under_xvfb

SCRIPT = os.path.join(ROOT, "blender_tests", "ui_optimize_modal.py")


@unittest.skipUnless(shutil.which("xvfb-run"), "xvfb-run is not installed")
class ModalOptimize(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.result, cls.seen = run_under_xvfb(SCRIPT, "MODAL ")

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

    def test_one_undo_removes_the_result(self):
        self.assertTrue(self.seen["undo_restores"])

    def test_cancel_leaves_the_scene_as_it_was(self):
        self.assertEqual(self.seen["cancel_invoke"], ["RUNNING_MODAL"])
        self.assertTrue(self.seen["cancel_running"])
        self.assertEqual(self.seen["cancel_op"], ["FINISHED"])
        self.assertTrue(self.seen["cancel_unchanged"])
