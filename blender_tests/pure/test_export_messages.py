"""Export's message matches the design's state: an unstable result points at Stability, an
unfinished one at Optimize."""
import unittest

from wiresculpt.fab import export


def empty_result(design):
    return {"files": [], "wires": [], "errors": [], "notes": [], "empty_reason": export.no_rest_reason(design)}


class ExportMessageTest(unittest.TestCase):
    def test_unstable_design_points_at_stability(self):
        design = {"stable": False, "reason": "crossing 3 pulls wires A/0 and B/0 apart",
                  "pending_stages": ["rest_shape"], "wires": [{"name": "A/0"}]}
        level, text = export.summary(empty_result(design), "/tmp/out")
        self.assertEqual(level, "ERROR")
        self.assertIn("the design is not stable: see Stability", text)
        self.assertIn("crossing 3", text)
        self.assertNotIn("optimize until", text)

    def test_a_setup_problem_is_not_called_unstable(self):
        # fewer than two wires: the pipeline's sentence, a scene to set up (as Live's "cannot solve")
        design = {"stable": False, "reason": "a sculpture needs at least two wires: add a plane or pick more contours",
                  "pending_stages": ["layering", "target_shape", "forces", "rest_shape"], "wires": [{"name": "A/0"}]}
        level, text = export.summary(empty_result(design), "/tmp/out")
        self.assertEqual(level, "ERROR")
        self.assertIn("the design cannot be solved as set up: see Stability (a sculpture needs at least two wires: "
                      "add a plane or pick more contours)", text)
        self.assertNotIn("not stable", text)

    def test_unfinished_design_points_at_optimize(self):
        design = {"stable": True, "reason": "", "pending_stages": ["rest_shape"], "wires": [{"name": "A/0"}]}
        level, text = export.summary(empty_result(design), "/tmp/out")
        self.assertEqual(level, "ERROR")
        self.assertIn("optimize until the rest shape stage has run", text)
        self.assertNotIn("not stable", text)


if __name__ == "__main__":
    unittest.main()
