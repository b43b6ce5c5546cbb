"""core/fidelity.py: the share of the model's outline (front, side, top) that the wires trace.

bpy-free. The expected shares are worked out by hand from masks whose outlines lie on the pixel
grid: every crack (unit edge between an inside and an outside pixel) has its midpoint at a half
pixel along the outline, so a crack at distance 0.5 + k (k = 0, 1, ...) from the end of a traced
stretch is traced exactly when 0.5 + k <= tolerance.
"""
import math
import unittest

import numpy as np

from wiresculpt import native, pipeline
from wiresculpt.core import fidelity
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.scene import PlaneSpec
from wiresculpt.core.settings import defaults

from helpers import PLANES, box_faces, box_vertices, sphere


def rectangle(x0, y0, x1, y1):
    """The closed outline of the pixels x0 <= x < x1, y0 <= y < y1 (pixel units)."""
    return (np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float), True)


def pixels(*boxes, shape=(120, 120)):
    """A mask (rows = y, columns = x) of the union of the pixel boxes (x0, y0, x1, y1)."""
    mask = np.zeros(shape, dtype=bool)
    for x0, y0, x1, y1 in boxes:
        mask[y0:y1, x0:x1] = True
    return mask


class Masks(unittest.TestCase):
    """Known masks, known outlines."""

    def test_a_box_traced_by_its_outline_is_one_and_by_one_side_its_share(self):
        mask = pixels((10, 20, 50, 40))  # 40 x 20 pixels: 120 cracks
        self.assertEqual(fidelity.traced(mask, [rectangle(10, 20, 50, 40)], 4.0), (120, 120))
        # only the bottom side (y = 20, 40 cracks) drawn: the two 20-pixel sides are traced for 4
        # pixels each (their cracks at 0.5, 1.5, 2.5, 3.5 from it), the top not at all
        bottom = (np.array([[10, 20], [50, 20]], dtype=float), False)
        self.assertEqual(fidelity.traced(mask, [bottom], 4.0), (48, 120))
        self.assertAlmostEqual(fidelity.share(mask, [bottom], 4.0), 48 / 120)

    def test_an_l_shape(self):
        # a bar 60 x 20 along x and a bar 20 x 60 along y sharing the corner square: an outline of
        # 60 + 20 + 40 + 40 + 20 + 60 = 240 pixels
        mask = pixels((10, 10, 70, 30), (10, 10, 30, 70))
        outline = (np.array([[10, 10], [70, 10], [70, 30], [30, 30], [30, 70], [10, 70]], dtype=float), True)
        self.assertEqual(fidelity.traced(mask, [outline], 4.0), (240, 240))
        # the bar along x alone (its rectangle): its bottom 60, its end 20, its top beyond the other
        # bar 40 and the left side up to y = 30 (20) are outline; the two sides of the bar along y
        # are traced for 4 pixels each above y = 30: 148 of 240
        self.assertEqual(fidelity.traced(mask, [rectangle(10, 10, 70, 30)], 4.0), (148, 240))

    def test_a_cross_missing_one_bar(self):
        # a bar 100 x 20 along x and one 20 x 100 along y crossing in the middle: 2 (100 + 100) = 400
        mask = pixels((10, 50, 110, 70), (50, 10, 70, 110))
        bar_x, bar_y = rectangle(10, 50, 110, 70), rectangle(50, 10, 70, 110)
        cross = (np.array([[10, 50], [50, 50], [50, 10], [70, 10], [70, 50], [110, 50], [110, 70], [70, 70],
                           [70, 110], [50, 110], [50, 70], [10, 70]], dtype=float), True)
        self.assertEqual(fidelity.traced(mask, [cross], 4.0), (400, 400))
        # one wire per bar (a limb's contour crossing the body's): every crack lies on one of them
        self.assertEqual(fidelity.share(mask, [bar_x, bar_y], 4.0), 1.0)
        # the bar along y missing: the x bar's two ends (2 x 20) and its sides outside the other bar
        # (2 x 80), and 4 pixels of each of the four sides of the missing bar: 216 of 400
        self.assertEqual(fidelity.traced(mask, [bar_x], 4.0), (216, 400))
        # the tolerance grows the traced stretches: 10 pixels each, 240 of 400
        self.assertEqual(fidelity.traced(mask, [bar_x], 10.0), (240, 400))

    def test_a_wire_away_from_the_outline_traces_nothing(self):
        mask = pixels((10, 10, 50, 50))
        inside = rectangle(20, 20, 40, 40)  # 10 pixels inside, beyond a tolerance of 4
        self.assertEqual(fidelity.traced(mask, [inside], 4.0), (0, 160))
        # within 10 pixels: on each side the 20 cracks facing the inner square's side (at 10), not
        # the next (at sqrt(10^2 + 0.5^2) from its corner); within 10.5 also 3 more at each end
        # (at sqrt(10^2 + 0.5^2), sqrt(10^2 + 1.5^2), sqrt(10^2 + 2.5^2) = 10.31; the 4th at 10.59)
        self.assertEqual(fidelity.traced(mask, [inside], 10.0), (4 * 20, 160))
        self.assertEqual(fidelity.traced(mask, [inside], 10.5), (4 * 26, 160))

    def test_an_empty_mask_has_no_share(self):
        self.assertIsNone(fidelity.share(np.zeros((8, 8), dtype=bool), [rectangle(1, 1, 4, 4)], 2.0))

    def test_cracks_of_a_hole_count(self):
        mask = pixels((10, 10, 50, 50))
        mask[20:30, 20:30] = False  # a 10 x 10 hole: 160 + 40 cracks
        self.assertEqual(len(fidelity.cracks(mask)), 200)
        self.assertEqual(fidelity.traced(mask, [rectangle(10, 10, 50, 50)], 4.0), (160, 200))


class Rasterise(unittest.TestCase):
    def test_a_triangle_covers_its_area(self):
        # the right triangle (0, 0), (100, 0), (0, 100): a pixel (i, j) has its centre inside when
        # (i + 0.5) + (j + 0.5) <= 100, i.e. i + j <= 99: 100 * 101 / 2 pixels
        mask = fidelity.rasterise(np.array([[0, 0], [100, 0], [0, 100]], dtype=float), [(0, 1, 2)], (120, 120))
        self.assertEqual(int(mask.sum()), 5050)
        self.assertTrue(mask[0, 99] and not mask[0, 100] and mask[99, 0] and not mask[1, 99])

    def test_orientation_and_edge_on_triangles(self):
        cw = fidelity.rasterise(np.array([[0, 0], [0, 100], [100, 0]], dtype=float), [(0, 1, 2)], (120, 120))
        self.assertEqual(int(cw.sum()), 5050)
        flat = fidelity.rasterise(np.array([[0, 0], [50, 50], [100, 100]], dtype=float), [(0, 1, 2)], (120, 120))
        self.assertEqual(int(flat.sum()), 0)

    def test_many_triangles_in_several_chunks(self):
        # a 100 x 100 square as 2 x 50 x 50 triangles of 2 x 2 pixels, rasterised in steps of 64 pixels
        n = 50
        P = np.array([[2.0 * i, 2.0 * j] for j in range(n + 1) for i in range(n + 1)]) + 5
        at = lambda i, j: j * (n + 1) + i
        F = [t for j in range(n) for i in range(n)
             for t in ((at(i, j), at(i + 1, j), at(i + 1, j + 1)), (at(i, j), at(i + 1, j + 1), at(i, j + 1)))]
        chunk = fidelity.CHUNK
        try:
            fidelity.CHUNK = 64
            mask = fidelity.rasterise(P, F, (120, 120))
        finally:
            fidelity.CHUNK = chunk
        self.assertEqual(int(mask.sum()), 100 * 100)
        self.assertTrue(mask[5:105, 5:105].all())


def two_bars():
    """A cross of two 1.0 x 0.2 x 0.2 m boxes (two closed shells): one along x (z 0.4-0.6), one
    along z (x 0.4-0.6), both y 0-0.2. S = 1 m: tolerance 0.03 m, 12 pixels of 2.5 mm."""
    V = box_vertices((0.0, 0.0, 0.4), (1.0, 0.2, 0.6)) + box_vertices((0.4, 0.0, 0.0), (0.6, 0.2, 1.0))
    F = box_faces() + [tuple(i + 8 for i in t) for t in box_faces()]
    return np.array(V), np.array(F)


def loop(points):
    return (np.array(points, dtype=float), True)


class Meshes(unittest.TestCase):
    def test_a_box_with_its_three_mid_sections(self):
        V = np.array(box_vertices((0.0, 0.0, 0.0), (0.4, 0.2, 0.3)))
        s = fidelity.Silhouettes(V, box_faces())
        self.assertAlmostEqual(s.tolerance, 0.03 * 0.4)
        # masks: 0.4 x 0.3, 0.2 x 0.3 and 0.4 x 0.2 m at 1 mm
        self.assertEqual([int(v.mask.sum()) for v in s.views], [400 * 300, 200 * 300, 400 * 200])
        front = loop([(0, 0.1, 0), (0.4, 0.1, 0), (0.4, 0.1, 0.3), (0, 0.1, 0.3)])
        side = loop([(0.2, 0, 0), (0.2, 0.2, 0), (0.2, 0.2, 0.3), (0.2, 0, 0.3)])
        top = loop([(0, 0, 0.15), (0.4, 0, 0.15), (0.4, 0.2, 0.15), (0, 0.2, 0.15)])
        record = s.fidelity([front, side, top])
        self.assertEqual(record["views"], {"front": 1.0, "side": 1.0, "top": 1.0})
        self.assertEqual(record["share"], 1.0)
        # the front section alone: seen from the side it is the line y = 0.1 across the 0.2 x 0.3
        # outline (1.0 m), traced 12 mm on each side of its two ends: 0.048; from the top the line
        # y = 0.1 across 0.4 x 0.2 (1.2 m): 0.048 / 1.2 = 0.04
        alone = s.fidelity([front])
        self.assertEqual(alone["views"]["front"], 1.0)
        self.assertAlmostEqual(alone["views"]["side"], 0.048, places=9)
        self.assertAlmostEqual(alone["views"]["top"], 0.04, places=9)
        self.assertAlmostEqual(alone["share"], (1.0 + 0.048 + 0.04) / 3, places=9)

    def test_a_cross_missing_a_bar(self):
        V, F = two_bars()
        s = fidelity.Silhouettes(V, F)
        front = s.views[0]
        # the front mask is the cross: 0.2 + 0.2 - 0.04 m^2 = 57,600 pixels of 2.5 mm
        self.assertEqual(int(front.mask.sum()), 57600)
        bar_x = loop([(0, 0.1, 0.4), (1, 0.1, 0.4), (1, 0.1, 0.6), (0, 0.1, 0.6)])
        bar_z = loop([(0.4, 0.1, 0), (0.6, 0.1, 0), (0.6, 0.1, 1), (0.4, 0.1, 1)])
        both = s.fidelity([bar_x, bar_z])
        self.assertEqual(both["views"]["front"], 1.0)
        # without the bar along z: of the cross's 4 m of outline, the x bar's ends (0.4 m), its
        # sides beside the other bar (1.6 m) and 0.03 m of each of the four sides of the missing
        # bar: 2.12 m, 0.53
        missing = s.fidelity([bar_x])
        self.assertAlmostEqual(missing["views"]["front"], 2.12 / 4.0, places=9)
        self.assertLess(missing["share"], both["share"])

    def test_the_target_is_what_is_traced(self):
        V = np.array(box_vertices((0.0, 0.0, 0.0), (0.4, 0.2, 0.3)))
        s = fidelity.Silhouettes(V, box_faces())
        outline = [[0, 0.1, 0], [0.4, 0.1, 0], [0.4, 0.1, 0.3], [0, 0.1, 0.3]]
        inner = [[0.1, 0.1, 0.1], [0.3, 0.1, 0.1], [0.3, 0.1, 0.2], [0.1, 0.1, 0.2]]
        wire = {"closed": True, "contour": inner, "target": outline}
        self.assertEqual(s.of_design({"wires": [wire]})["views"]["front"], 1.0)
        self.assertEqual(s.of_design({"wires": [dict(wire, target=[])]})["views"]["front"], 0.0)

    def test_a_sphere_and_its_great_circles(self):
        V, F = sphere(0.125)
        s = fidelity.Silhouettes(V, F)
        t = np.linspace(0, 2 * math.pi, 200, endpoint=False)
        c, n, z = 0.125 * np.cos(t), 0.125 * np.sin(t), np.zeros_like(t)
        circles = [(np.stack(p, axis=1), True) for p in ((c, n, z), (c, z, n), (z, c, n))]
        self.assertEqual(s.fidelity(circles)["share"], 1.0)
        # a circle of half the radius in each plane: 62.5 mm inside a tolerance of 7.5 mm
        self.assertEqual(s.fidelity([(0.5 * p, True) for p, _ in circles])["share"], 0.0)

    @unittest.skipUnless(native.available(), native.LOAD_ERROR)
    def test_a_sliced_cross_with_and_without_its_limb(self):
        # a 1.0 x 0.2 m bar along x (z 0.4-0.6) and a 0.2 x 0.8 m bar along z (x 0.4-0.6, z 0.1-0.9),
        # both y 0-0.2, cut by y = 0.1: the x bar's rectangle is the largest contour, the z bar's the
        # limb. Front outline 2 (1.0 + 0.8) = 3.6 m; the x bar's alone traces its ends (0.4), its
        # sides beside the z bar (1.6) and 0.03 m of each of the z bar's four sides: 2.12 m
        V = np.array(box_vertices((0.0, 0.0, 0.4), (1.0, 0.2, 0.6)) + box_vertices((0.4, 0.0, 0.1), (0.6, 0.2, 0.9)))
        F = np.array(box_faces() + [tuple(i + 8 for i in t) for t in box_faces()])
        shares = {}
        for rule in ("largest", "all"):
            design = pipeline.slice_and_pick(V, F, [PlaneSpec("Y", (0, 0.1, 0), (0, 1, 0), contours=rule)],
                                             PRESETS["steel"], defaults())
            shares[rule] = fidelity.record(design, V, F)["views"]["front"]
        self.assertEqual(shares["all"], 1.0)
        self.assertAlmostEqual(shares["largest"], 2.12 / 3.6, places=9)

    @unittest.skipUnless(native.available(), native.LOAD_ERROR)
    def test_a_sliced_sphere(self):
        V, F = sphere(0.125)
        design = pipeline.slice_and_pick(V, F, PLANES, PRESETS["steel"], defaults())
        record = fidelity.record(design, V, F)
        self.assertIs(design["fidelity"], record)
        self.assertEqual(record["share"], 1.0)
        self.assertAlmostEqual(record["tolerance"], 0.03 * 0.25)
        self.assertAlmostEqual(record["pixel"], 0.25 / fidelity.PIXELS)
        # the equator (plane A, z = 0) alone: 1 from the top, two 15 mm stretches of the 0.785 m
        # circle from the front and the side (the line z = 0 meets it at two points)
        design["wires"] = [w for w in design["wires"] if w["name"].startswith("A/")]
        alone = fidelity.record(design, V, F)
        self.assertEqual(alone["views"]["top"], 1.0)
        for view in ("front", "side"):
            self.assertAlmostEqual(alone["views"][view], 4 * 0.0075 / (2 * math.pi * 0.125), delta=0.01)


if __name__ == "__main__":
    unittest.main()
