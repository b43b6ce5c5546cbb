"""Find Stable Planes from the UI (modal operator, worker thread, timer) in a Blender with a
window, under Xvfb: cancel mid-search leaves the scene as it was, a finished search changes
nothing either, and Apply is one undo step."""
import os
import shutil
import unittest

from helpers import ROOT, run_under_xvfb

SCRIPT = os.path.join(ROOT, "blender_tests", "ui_plane_search_modal.py")


@unittest.skipUnless(shutil.which("xvfb-run"), "xvfb-run is not installed")
class ModalFindPlanes(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.result, cls.seen = run_under_xvfb(SCRIPT, "MODAL ", timeout=200)

    def setUp(self):
        self.assertIsNotNone(self.seen, self.result.stdout[-3000:] + self.result.stderr[-3000:])
        self.assertNotIn("error", self.seen, self.result.stdout[-3000:] + self.result.stderr[-3000:])

    def test_cancel_mid_search_leaves_the_scene(self):
        self.assertEqual(self.seen["cancel_invoke"], ["RUNNING_MODAL"])
        self.assertTrue(self.seen["cancel_running"])
        self.assertIn("Esc to cancel", self.seen["status_while_running"])
        self.assertTrue(self.seen["cancel_still_running"])
        self.assertEqual(self.seen["cancel_op"], ["FINISHED"])
        self.assertTrue(self.seen["cancel_unchanged"])
        self.assertTrue(self.seen["cancel_no_candidates"])

    def test_search_then_apply_is_one_undo_step(self):
        self.assertEqual(self.seen["invoke"], ["RUNNING_MODAL"])
        self.assertGreaterEqual(self.seen["candidates"], 1)
        self.assertTrue(self.seen["search_unchanged"])
        self.assertEqual(self.seen["apply"], ["FINISHED"])
        self.assertTrue(self.seen["apply_changed"])
        self.assertTrue(self.seen["undo_restores"])


if __name__ == "__main__":
    unittest.main()
