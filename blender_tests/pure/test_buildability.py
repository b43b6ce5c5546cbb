""""Stable" means buildable (docs/formats.md, beyond the FORMATS contract): the verdict of fab/buildability.py on designs
whose rest shapes are drawn by hand, so every number in the messages is known without the solver:
a bend 0.1 deg over the machine's limit, a straight piece between two crossings shorter than the
minimum segment, a rest shape that crosses itself (and its mark on the SVG template)."""
import math
import os
import tempfile
import unittest

import numpy as np

from wiresculpt import native
from wiresculpt.core.polylines import self_crossings
from wiresculpt.fab import buildability, export


def walk(feeds, turns_deg):
    """A 2D polyline from the origin heading +x: feeds (m) with the turns (degrees, left positive)
    between them."""
    points, heading, p = [np.zeros(2)], 0.0, np.zeros(2)
    for k, feed in enumerate(feeds):
        p = p + feed * np.array([math.cos(heading), math.sin(heading)])
        points.append(p)
        if k < len(turns_deg):
            heading += math.radians(turns_deg[k])
    return np.array(points)


def design_of(rest, crossing_vertices=(), size=0.1):
    """One open wire 'T/0' in the plane z = 0 whose target is its rest shape (so target indices are
    rest indices), a second wire only to carry the crossings, and a contour `size` m wide."""
    target = np.column_stack([rest, np.zeros(len(rest))])
    wire = {"id": 0, "name": "T/0", "plane": {"origin": [0, 0, 0], "normal": [0, 0, 1]}, "closed": False,
            "contour": [[0, 0, 0], [size, 0, 0]], "target": target.tolist(), "rest": rest.tolist(), "cut": -1}
    other = {"id": 1, "name": "U/0", "plane": {"origin": [0, 0, 0], "normal": [1, 0, 0]}, "closed": True,
             "contour": [[0, 0, 0], [0, 0.01, 0], [0, 0, 0.01]]}
    crossings = [{"id": k, "wires": [0, 1], "vertices": [v, 0], "hook": 1} for k, v in enumerate(crossing_vertices)]
    return {"wires": [wire, other], "crossings": crossings, "stable": True, "reason": "", "warnings": [],
            "machine": {"min_segment": 0.015, "max_bend_deg": 120.0, "min_bend_deg": 1.0},
            "material": {"name": "steel"}}


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Verdict(unittest.TestCase):
    def test_a_bend_a_tenth_of_a_degree_over_the_limit_is_not_stable(self):
        design = design_of(walk([0.02, 0.02, 0.02], [30.0, 120.1]))
        buildability.apply(design)
        self.assertFalse(design["stable"])
        self.assertIn("wire T/0: bend 2 (40.0 mm from the cut) turns 120.10 deg", design["reason"])
        problem, = design["buildability"]["problems"]
        self.assertEqual((problem["kind"], problem["number"], problem["from"]), ("over_bend", 2, 2))
        self.assertAlmostEqual(problem["value"], 120.1, places=9)

    def test_a_bend_a_tenth_of_a_degree_inside_the_limit_is_stable(self):
        design = design_of(walk([0.02, 0.02, 0.02], [30.0, -119.9]))
        buildability.apply(design)
        self.assertTrue(design["stable"], design["reason"])
        self.assertEqual(design["buildability"]["problems"], [])

    def test_a_too_short_straight_piece_between_crossings_asks_for_a_scale_up(self):
        # 20 mm, then 5 mm between the crossings at rest points 1 and 2 (both bent 30 deg), then 20 mm:
        # room for a free bending point between the two crossings, 2 x 15 / 5 = 6 times, the 0.1 m
        # model to 0.6 m.
        design = design_of(walk([0.02, 0.005, 0.02], [30.0, 30.0]), crossing_vertices=(1, 2))
        buildability.apply(design)
        self.assertFalse(design["stable"])
        self.assertIn("wire T/0: step 2 feeds 5.000 mm (between bends 1 and 2, 20.0 mm from the cut)",
                      design["reason"])
        self.assertIn("crossings 0 and 1", design["reason"])
        self.assertIn("scale the model up at least 6.00 times (largest side 0.1 m -> 0.6 m)", design["reason"])
        self.assertEqual(design["buildability"]["problems"][0]["crossings"], [0, 1])

    def test_a_too_short_feed_with_no_crossings_at_its_ends_asks_for_that_feed_only(self):
        # the same 5 mm feed with no crossing at its ends: one straight piece, 15 / 5 = 3 times
        design = design_of(walk([0.02, 0.005, 0.02], [30.0, 30.0]))
        buildability.apply(design)
        self.assertFalse(design["stable"])
        self.assertIn("scale the model up at least 3.00 times (largest side 0.1 m -> 0.3 m)", design["reason"])

    def test_a_rest_shape_the_bend_program_cannot_read_is_a_reason_not_a_crash(self):
        rest = walk([0.02, 0.02, 0.02], [30.0, 30.0])
        design = design_of(np.vstack([rest[:2], rest[1:]]))  # point 1 repeated: a zero-length segment
        buildability.apply(design)
        self.assertFalse(design["stable"])
        self.assertIn("wire T/0: segment 1 (points 1 and 2) has zero length", design["reason"])

    def test_an_unstable_design_keeps_its_own_reason(self):
        design = design_of(walk([0.02, 0.02, 0.02], [30.0, 125.0]))
        design.update(stable=False, reason="the layering's reason")
        buildability.apply(design)
        self.assertEqual(design["reason"], "the layering's reason")
        self.assertEqual(len(design["buildability"]["problems"]), 1)


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class SelfCrossing(unittest.TestCase):
    # 100 mm along +x, left 90, 50 mm, left 90, 50 mm, left 90, 100 mm: the last edge, going down
    # x = 50 mm, crosses the first at (50, 0) mm, 50 mm and 100 + 50 + 50 + 50 = 250 mm from the cut.
    REST = walk([0.1, 0.05, 0.05, 0.1], [90.0, 90.0, 90.0])

    def test_the_crossing_is_found_where_drawn(self):
        (i, j, point, s_i, s_j), = self_crossings(self.REST, closed=False)
        self.assertEqual((i, j), (0, 3))
        np.testing.assert_allclose(point, [0.05, 0.0], atol=1e-12)
        self.assertAlmostEqual(s_i, 0.05, places=12)
        self.assertAlmostEqual(s_j, 0.25, places=12)
        # a square's sides only meet at their shared corners: no crossing
        self.assertEqual(self_crossings(walk([0.1, 0.1, 0.1, 0.1], [90.0, 90.0, 90.0]), closed=False), [])

    def test_a_self_crossing_is_a_warning_naming_the_two_places(self):
        design = design_of(self.REST)
        buildability.apply(design)
        self.assertTrue(design["stable"], design["reason"])  # a warning, not a verdict
        warning, = [w for w in design["warnings"] if "crosses itself" in w]
        self.assertIn("wire T/0: the rest shape crosses itself 50.0 mm and 250.0 mm from the cut "
                      "(before bend 1 and after bend 3, the last)", warning)
        entry, = design["buildability"]["self_crossings"]
        self.assertEqual(entry["edges"], [0, 3])

    def test_the_template_marks_it(self):
        design = design_of(self.REST)
        with tempfile.TemporaryDirectory() as out:
            result = export.export(design, out)
            self.assertEqual(result["errors"], [])
            svg = open(os.path.join(out, "templates", "00-T-0.svg"), encoding="utf-8").read()  # the annotated template (svg/ holds the machine file)
        self.assertEqual(svg.count('class="self-crossing"'), 1)
        self.assertIn("crosses itself", svg)


if __name__ == "__main__":
    unittest.main()
