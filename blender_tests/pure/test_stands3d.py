"""The 3D check of a solved design (stages/stands3d.py, core/standing.py): the rigid roll onto the
table worked out by hand, the sentences from their figures, and on a real design (three great
circles of a sphere) the physics the record must obey, re-checked here apart from the solver:
rods that do not stretch, forces tested against their pyramids by scipy's NNLS, and the
planar forces inside the pyramids they were chosen in. bpy-free."""
import math
import unittest

import numpy as np

from wiresculpt import native
from wiresculpt.core import standing
from wiresculpt.stages import stands3d

from helpers import sphere_design


def turned_by(R):
    """The angle of the rotation R, degrees."""
    return math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(R) - 1.0) / 2.0))))


class Settle(unittest.TestCase):
    def test_a_body_standing_on_its_base_does_not_move(self):
        square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 2.0]], dtype=float)
        np.testing.assert_allclose(stands3d.settle(square, np.ones(5), 1e-12), np.eye(3))

    def test_a_heavy_point_beyond_an_edge_tips_the_body_over_it(self):
        # A unit square base and a point (2, 0.5, 1) carrying nearly all the weight: its foot lies
        # beyond the edge x = 1, so the body turns about that edge (the y axis through x = 1) until
        # the point touches: it lies 45 deg above the edge (rise 1 over run 1), so 45 deg.
        body = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0.5, 1.0]], dtype=float)
        weights = np.array([1, 1, 1, 1, 100.0])
        R = stands3d.settle(body, weights, 1e-12)
        self.assertAlmostEqual(turned_by(R), 45.0, places=9)
        moved = (body - [1, 0, 0]) @ R.T + [1, 0, 0]
        self.assertAlmostEqual(moved[4, 2] - moved[:, 2].min(), 0.0, places=12)  # the point touches
        np.testing.assert_allclose(moved[1], body[1], atol=1e-12)  # the edge it turned about stays
        np.testing.assert_allclose(moved[2], body[2], atol=1e-12)

    def test_two_feet_in_a_line_fall_onto_a_third_point(self):
        # Two feet at (+-1, 0, 0) only; the weight leans to +y (the heavy point at y = 0.5: the
        # centre of mass at y = (1 - 2 + 10 x 0.5) / 14 > 0), so the body rolls about the feet's
        # line towards +y until the first point on that side touches: (0, 1, 1), 45 deg above the
        # line, before the heavy point (0, 0.5, 1) at 63.4 deg; (0, -2, 3) is on the other side.
        # Then the centre of mass's foot (y = 0.86) lies inside the triangle of feet (y up to 1.41).
        body = np.array([[-1, 0, 0], [1, 0, 0], [0, 1, 1.0], [0, -2, 3.0], [0, 0.5, 1.0]], dtype=float)
        weights = np.array([1, 1, 1, 1, 10.0])
        R = stands3d.settle(body, weights, 1e-12)
        self.assertAlmostEqual(turned_by(R), 45.0, places=9)
        moved = body @ R.T
        self.assertAlmostEqual(moved[2, 2], moved[0, 2], places=12)


class Words(unittest.TestCase):
    def test_each_cause_says_its_figures(self):
        base = {"sag_limit": 0.0025, "max_sag": 0.0012, "max_sag_wire": "A/0", "slipping": [3, 5], "tilt_deg": 26.0,
                "solver_message": "the structure turns freely"}
        self.assertEqual(standing.words(dict(base, cause=standing.STANDS)),
                         "stands in 3D: every crossing holds, the wires within 1.2 mm of their targets (limit 2.5 mm); "
                         "on a table it rests tilted by 26.0°")
        self.assertIn("crossings 3, 5 would have to pull or slip", standing.words(dict(base, cause=standing.SLIPS)))
        self.assertIn("wire A/0 sags 1.2 mm from its target (limit 2.5 mm)",
                      standing.words(dict(base, cause=standing.SAGS)))
        self.assertIn("the structure turns freely", standing.words(dict(base, cause=standing.NO_EQUILIBRIUM)))

    def test_the_sag_limit(self):
        small = {"wires": [{"target": [[0, 0, 0], [0.1, 0, 0]]}]}
        large = {"wires": [{"target": [[0, 0, 0], [0.5, 0, 0]]}]}
        self.assertAlmostEqual(standing.sag_limit(small), 0.002)  # 1 % of 0.1 m is under the floor
        self.assertAlmostEqual(standing.sag_limit(large), 0.005)


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class RealDesign(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.design = sphere_design()

    def test_the_record_is_written(self):
        d = self.design
        self.assertTrue(d["stable"], d["reason"])
        record = d["stands_3d"]
        self.assertIn(record["cause"], standing.CAUSES)
        self.assertEqual(record["stands"], record["cause"] == standing.STANDS)
        self.assertIn(record["solver_cause"], native.STRUCTURE3D_CAUSES)

    def test_the_rods_keep_their_lengths(self):
        # Steel wire's E A is about 7e5 N: newtons of force stretch a rod by parts per million.
        for w in self.design["wires"]:
            built = np.asarray(w["as_built"])
            rest = np.asarray(w["rest"])
            np.testing.assert_allclose(np.linalg.norm(np.diff(built, axis=0), axis=1),
                                       np.linalg.norm(np.diff(rest, axis=0), axis=1), rtol=1e-4)

    def test_the_sag_is_the_largest_distance_from_the_target(self):
        for w in self.design["wires"]:
            target = np.asarray(w["target"])
            built = np.asarray(w["as_built"])
            order = stands3d.walk(len(target), w["closed"], w.get("cut", -1))
            self.assertAlmostEqual(w["sag"], float(np.max(np.linalg.norm(built - target[order], axis=1))), places=12)

    def test_admissible_agrees_with_an_independent_cone_test(self):
        from scipy.optimize import nnls

        hooked = [c for c in self.design["crossings"] if c["hook"] != 0]
        self.assertTrue(hooked)
        for c in hooked:
            P = np.asarray(c["pyramid"]).T  # columns: the four unit forces
            for key, wanted in (("force", True), ("force_3d", c["admissible"])):
                f = np.asarray(c[key])
                _coef, gap = nnls(P, f)
                with self.subTest(crossing=c["id"], force=key):
                    # the planar force was chosen in its pyramid; the 3D one is, exactly when admissible
                    self.assertEqual(gap <= 1e-5 * max(np.linalg.norm(f), 1e-9), wanted, (gap, np.linalg.norm(f)))
        slipping = {c["id"] for c in hooked if not c["admissible"]}
        self.assertEqual(set(self.design["stands_3d"]["slipping"]), slipping)


if __name__ == "__main__":
    unittest.main()
