"""Closure gaps as figures users read (core/closure.py): mm, % of the wire's length, and how to
join the ends, on hand-made wires."""
import unittest

from wiresculpt.core import closure


class ClosureTest(unittest.TestCase):
    def test_figures(self):
        # a 785 mm ring whose ends stand 116 mm apart: 14.78% of its length
        ring = {"closed": True, "closure_gap": 0.116, "length": 0.785}
        gap, share = closure.closure(ring)
        self.assertEqual(gap, 0.116)
        self.assertAlmostEqual(share, 116 / 785, places=12)
        self.assertEqual(closure.closure_text(ring), "116.0 mm (14.8% of its length)")
        # an open wire, or one before the forces stage, has no closure
        self.assertIsNone(closure.closure({"closed": False, "closure_gap": 0.0, "length": 0.5}))
        self.assertIsNone(closure.closure_text({"closed": True, "length": 0.5}))

    def test_advice(self):
        d = 0.003
        small = {"closed": True, "closure_gap": 0.01, "length": 1.0}     # 1%: a sleeve
        large = {"closed": True, "closure_gap": 0.116, "length": 0.785}  # 14.8%: an overlap
        edge = {"closed": True, "closure_gap": 0.05, "length": 1.0}      # at the rule's limit
        method, text = closure.closure_advice(small, d)
        self.assertEqual(method, "sleeve")
        self.assertIn("10.0 mm", text)
        self.assertIn("3 mm wire", text)
        method, text = closure.closure_advice(large, d)
        self.assertEqual(method, "overlap")
        self.assertIn("116.0 mm", text)
        self.assertIn(f"{closure.OVERLAP_DIAMETERS * 3} mm of extra wire", text)
        self.assertEqual(closure.closure_advice(edge, d)[0], "sleeve")
        self.assertIsNone(closure.closure_advice({"closed": False}, d))

    def test_advice_with_the_profiles_overlap_allowance(self):
        d = 0.003
        small = {"closed": True, "closure_gap": 0.01, "length": 1.0}
        large = {"closed": True, "closure_gap": 0.116, "length": 0.785}
        method, text = closure.closure_advice(large, d, overlap=0.025)
        self.assertEqual(method, "overlap")
        self.assertIn("the bend program feeds 25 mm of extra wire past the cut", text)
        self.assertNotIn("leave", text)
        method, text = closure.closure_advice(small, d, overlap=0.025)
        self.assertEqual(method, "sleeve")
        self.assertIn("trim the 25 mm the bend program fed past the cut", text)
        self.assertNotIn("trim", closure.closure_advice(small, d)[1])


if __name__ == "__main__":
    unittest.main()
