"""Find Stable Planes from the UI (modal operator, worker thread, timer) in a Blender with a
window, under Xvfb: cancel mid-search leaves the scene as it was, a finished search changes
nothing either, Preview draws a candidate with no undo step, and Apply is one undo step that ends
the preview."""
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
        self.assertTrue(self.seen["apply_clears_preview"])

    def test_preview_is_drawn_and_no_undo_step(self):
        self.assertEqual(self.seen["preview"], ["FINISHED"])
        self.assertEqual(self.seen["preview_index"], 0)
        self.assertEqual(self.seen["preview_wires"], self.seen["design_wires"])
        self.assertTrue(self.seen["preview_changes_nothing"])
        self.assertTrue(self.seen["preview_no_data"])
        self.assertGreater(self.seen["drawn_after"], self.seen["drawn_before"])  # the overlay drew it
        self.assertTrue(self.seen["undo_took_the_marker"])  # the click pushed no undo step
        self.assertTrue(self.seen["preview_kept_by_undo"])


if __name__ == "__main__":
    unittest.main()
