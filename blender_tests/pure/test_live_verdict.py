"""The words of Live's verdict line (core/live_verdict): setup problems and errors are said with
their own kinds, never "not stable"."""
import unittest

from wiresculpt.core import live_verdict as lv


class Kinds(unittest.TestCase):
    def test_each_kind_its_prefix(self):
        self.assertEqual(lv.verdict(lv.STABLE), "stable")
        self.assertEqual(lv.verdict(lv.NOT_STABLE, "crossing 3 pulls wires A/0 and B/0 apart"),
                         "not stable — crossing 3 pulls wires A/0 and B/0 apart")
        problem = "No contour is ticked: Slice, then tick the contours that become wires"
        self.assertEqual(lv.verdict(lv.CANNOT_SOLVE, problem), "cannot solve — " + problem)
        self.assertEqual(lv.verdict(lv.ERROR, "KeyError: 'x'"), "error — KeyError: 'x'")
        self.assertEqual(lv.verdict(lv.NOT_STABLE, ""), "not stable")

    def test_kind_of_reads_them_back(self):
        for kind in (lv.NOT_STABLE, lv.CANNOT_SOLVE, lv.ERROR):
            self.assertEqual(lv.kind_of(lv.verdict(kind, "crossing 3 pulls wires apart")), kind)
        self.assertEqual(lv.kind_of("stable"), lv.STABLE)
        self.assertEqual(lv.kind_of("solving…"), lv.SOLVING)
        self.assertEqual(lv.kind_of("not stable"), lv.NOT_STABLE)
        self.assertEqual(lv.kind_of(""), "")
        self.assertEqual(lv.kind_of(lv.verdict(lv.CANNOT_SOLVE, "the solver is not loaded")), lv.CANNOT_SOLVE)
        self.assertNotIn("not stable", lv.verdict(lv.CANNOT_SOLVE, "the solver is not loaded"))


if __name__ == "__main__":
    unittest.main()
