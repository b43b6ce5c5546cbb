"""native.structure3d: the 3D equilibrium through the binding, on two rods tied at a point (the
native test "two rods tied at a point"): the tie force on A and B's free body agree."""
import math
import unittest

import numpy as np

from wiresculpt import native


def tied_pair():
    """A straight along x (clamped at x = 0); B an arc of radius 8 cm in the plane x = 0.1, its
    middle tied to A's vertex 4, pinned at both ends; loads on A's tip and B's vertex 2."""
    a = np.array([[0.025 * k, 0.0, 0.0] for k in range(9)])
    r = 0.08
    b = np.array([[0.1, r * math.sin(-math.pi / 2 + k * math.pi / 8), r * math.cos(-math.pi / 2 + k * math.pi / 8) - r]
                  for k in range(9)])
    wires = [{"name": "A", "rest": a, "start": a, "normal": [0, 0, 1]},
             {"name": "B", "rest": b, "start": b, "normal": [1, 0, 0]}]
    loads = [{"node": [0, 8], "force": [0.0, 0.1, -0.2]}, {"node": [1, 2], "force": [0.1, 0.0, -0.1]}]
    return wires, loads


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Structure3d(unittest.TestCase):
    def test_tied_pair_balances_through_the_binding(self):
        wires, loads = tied_pair()
        options = {"linear_density": 0.0}
        r = native.structure3d(wires, ties=[{"a": [0, 4], "b": [1, 4]}], loads=loads, clamps=[[0, 0]],
                               pins=[[1, 0], [1, 8]], options=options)
        self.assertTrue(r["converged"], r["message"])
        self.assertEqual(r["cause"], "none")
        self.assertIn(r["cause"], native.STRUCTURE3D_CAUSES)
        self.assertEqual(r["wires"][0]["points"].shape, (9, 3))
        tie = np.array(r["tie_forces"][0])
        # B's free body, computed here: its loads and pin reactions balance the tie's -T on it.
        on_b = np.array(loads[1]["force"]) + sum(np.array(p["force"]) for p in r["pins"])
        np.testing.assert_allclose(on_b - tie, 0.0, atol=1e-7)
        # A's: the tip load, the clamp's reaction and T.
        on_a = np.array(loads[0]["force"]) + np.array(r["clamps"][0]["force"])
        np.testing.assert_allclose(on_a + tie, 0.0, atol=1e-7)
        self.assertGreater(np.linalg.norm(tie), 0.05)

    def test_bad_input_is_a_value_error_naming_it(self):
        wires, _ = tied_pair()
        with self.assertRaisesRegex(ValueError, "tie 0: vertex 9 does not exist on wire 1 'B'"):
            native.structure3d(wires, ties=[{"a": [0, 4], "b": [1, 9]}], clamps=[[0, 0]])
        with self.assertRaisesRegex(ValueError, r"wires\[0\]\['rest'\]: expected an \(n, 3\) array"):
            native.structure3d([dict(wires[0], rest=np.zeros((4, 2)))])

    def test_pyramid_fit(self):
        cone = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]]
        self.assertTrue(native.pyramid_fit([2, 3, 0.5], cone)["inside"])
        out = native.pyramid_fit([-1, 2, 3], cone)
        self.assertFalse(out["inside"])
        self.assertAlmostEqual(out["distance"], 1.0, places=12)


if __name__ == "__main__":
    unittest.main()
