"""The plane assistant's fidelity (core/fidelity.py) in its candidates, its score and the batch's
design: on a sphere (radius R = 0.125 m), whose silhouette from the front, the side and the top is a
circle of radius R, so that three great circles along the axes trace all of it and planes off the
centre trace none of it (their circles' radius sqrt(R^2 - d^2) is over 0.03 S = 7.5 mm inside once
d > 0.045 m).
"""
import json
import math
import unittest

import numpy as np

from wiresculpt import native, plane_search
from wiresculpt.core import fidelity
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.scene import PlaneSpec

from helpers import PLANES, settings, sphere

R = 0.125


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Candidates(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.V, cls.F = sphere(R)
        cls.outlines = fidelity.Silhouettes(cls.V, cls.F)

    def test_looks_of_great_circles_and_of_planes_off_the_centre(self):
        s = plane_search.Searcher((self.V, self.F), PRESETS["steel"], settings())
        great, _ = s._sliced([plane_search.Placement(p.name, p.origin, p.normal, "largest") for p in PLANES])
        d = 0.06  # the circles' radius 0.110 m: 15 mm inside the outline
        off, _ = s._sliced([plane_search.Placement(p.name, tuple(d * np.asarray(p.normal)), p.normal, "largest")
                            for p in PLANES])
        self.assertEqual(s.fidelity(great)["share"], 1.0)
        # Seen edge on, an off-centre circle is a line at d from the centre, ending on the outline at
        # angle t0 = asin(d / R) from the line through the centre: two such ends per line, two lines per
        # view. At an end the outline is traced over the arc within the tolerance T of the line's end
        # beyond it (T) and of the line itself before it (the arc leaves the line at cos t0 of its
        # length: T / cos t0). The outline is measured along the pixel grid, an arc of direction
        # (-sin t, cos t) counting (sin t + cos t) of its length, and the whole circle 8 R.
        t0, T = math.asin(d / R), 0.03 * 2 * R
        expected = 4 * T * (1 + 1 / math.cos(t0)) * (math.sin(t0) + math.cos(t0)) / (8 * R)
        self.assertAlmostEqual(expected, 0.0871, places=4)
        self.assertAlmostEqual(s.fidelity(off)["share"], expected, delta=0.003)
        candidate = {"design": great, "figures": {}}
        self.assertEqual(s.looks(candidate), 1.0)
        self.assertEqual(candidate["fidelity"], 1.0)
        self.assertEqual(candidate["figures"]["fidelity"], 1.0)
        self.assertEqual(candidate["figures"]["views"], {"front": 1.0, "side": 1.0, "top": 1.0})
        self.assertEqual(candidate["figures"]["coverage"], s.coverage(great))
        self.assertEqual(great["fidelity"]["share"], 1.0)

    def test_auto_scores_by_fidelity(self):
        found, s, _start = plane_search.auto((self.V, self.F), 4, PRESETS["steel"], settings(), want=2)
        self.assertTrue(found)
        for c in found:
            # the candidate's record is the one measured independently on its solved wires
            mine = self.outlines.of_design(c["design"])
            self.assertEqual(c["design"]["fidelity"], mine)
            self.assertEqual(c["score"], mine["share"])
            self.assertEqual(c["figures"]["fidelity"], mine["share"])
            self.assertEqual(c["figures"]["views"], mine["views"])
            self.assertEqual(c["figures"]["coverage"], c["coverage"])
            self.assertTrue(0.0 < c["coverage"] <= 1.0)
        flags = [bool(c["design"].get("two_hand_steps")) for c in found]
        for a, b, fa, fb in zip(found, found[1:], flags, flags[1:]):
            if fa == fb:
                self.assertGreaterEqual(a["score"], b["score"])

    def test_nearby_candidates_carry_their_looks(self):
        found, _s, _start = plane_search.nearby((self.V, self.F), PLANES, PRESETS["steel"], settings(), 1)
        self.assertEqual(len(found), 1)
        self.assertEqual(found[0]["changes"], [])  # the great circles are stable as given
        self.assertEqual(found[0]["figures"]["fidelity"], 1.0)
        self.assertEqual(found[0]["score"], 0.0)  # nearby's score stays its cost


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Batch(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.V, cls.F = sphere(R)

    def test_off_records_fidelity(self):
        design, _used = plane_search.run(self.V, self.F, PLANES, PRESETS["steel"], settings())
        self.assertTrue(design["stable"], design["reason"])
        self.assertEqual(design["fidelity"]["share"], 1.0)
        self.assertAlmostEqual(design["fidelity"]["tolerance"], 0.03 * 2 * R)
        self.assertNotIn("plane_search", design)
        json.dumps(design, allow_nan=False)  # written as JSON

    def test_off_with_one_plane_off_the_centre(self):
        planes = [PlaneSpec("A", (0, 0, 0.06), (0, 0, 1)), PlaneSpec("B", (0, 0, 0), (1, 0, 0)),
                  PlaneSpec("C", (0, 0, 0), (0, 1, 0))]
        design, _used = plane_search.run(self.V, self.F, planes, PRESETS["steel"], settings())
        views = design["fidelity"]["views"]
        self.assertEqual((views["front"], views["side"]), (1.0, 1.0))
        self.assertLess(views["top"], 0.2)  # the z = 0.06 circle lies 15 mm inside the top outline

    def test_auto_records_and_says_it(self):
        said = []
        design, _used = plane_search.run(self.V, self.F, [], PRESETS["steel"],
                                         settings(plane_search="auto", plane_count=4),
                                         progress=lambda stage, message: said.append(message))
        self.assertTrue(design["stable"], design["reason"])
        record = design["plane_search"]
        self.assertEqual(record["fidelity"], design["fidelity"]["share"])
        self.assertEqual(record["score"], record["fidelity"])
        self.assertTrue(0.0 < record["coverage"] <= 1.0)
        self.assertIn("score = fidelity", record["measure"])
        self.assertIn(f"traces {record['fidelity']:.0%} of the outline; covers {record['coverage']:.0%} of the mesh",
                      said[-1])


if __name__ == "__main__":
    unittest.main()
