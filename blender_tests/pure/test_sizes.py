"""Size sense (core.sizes): wires longer than the stock and models over 1.5 m are warnings with
their figure; lengths and sizes are measured here from the points, independently."""
import math
import unittest

import numpy as np

from wiresculpt.core import sizes


def ring(radius, normal_axis, n=64):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    pts = np.zeros((n, 3))
    a, b = [k for k in range(3) if k != normal_axis]
    pts[:, a], pts[:, b] = radius * np.cos(t), radius * np.sin(t)
    return pts.tolist()


def design(radius):
    wires = [{"id": k, "name": f"{'ABC'[k]}/0", "closed": True, "contour": ring(radius, k)} for k in range(3)]
    return {"wires": wires}


class SizeTest(unittest.TestCase):
    def test_a_small_globe_says_nothing(self):
        self.assertEqual(sizes.size_warnings(design(0.125)), [])

    def test_a_large_model_names_its_size_and_every_long_wire(self):
        d = design(1.35)  # 2.7 m across
        perimeter = 64 * 2 * 1.35 * math.sin(math.pi / 64)  # the closed 64-gon, by hand
        found = sizes.size_warnings(d)
        self.assertEqual(len(found), 4)
        self.assertIn("2.70 m across, over 1.50 m", found[0])
        for k, text in enumerate(found[1:]):
            self.assertIn(f"wire {'ABC'[k]}/0 is {perimeter * 1000:.0f} mm long", text)
            self.assertIn("1000 mm stock", text)

    def test_the_profile_stock_decides(self):
        d = design(0.2)  # 1.26 m of wire each, 0.4 m across
        self.assertEqual(len(sizes.size_warnings(d)), 3)
        self.assertEqual(sizes.size_warnings(d, stock_length=2.0), [])
        self.assertIn("3000 mm stock of my bender", sizes.size_warnings(design(0.5), 3.0, "my bender")[0])
        with self.assertRaisesRegex(ValueError, "stock_length"):
            sizes.size_warnings(d, stock_length=0)

    def test_the_stock_sentences_alone(self):
        """stock_warnings: the wires' sentences of size_warnings (what an export notes), not the model's."""
        d = design(1.35)
        perimeter = 64 * 2 * 1.35 * math.sin(math.pi / 64)
        found = sizes.stock_warnings(d, 1.0, "my bender")
        self.assertEqual(found, [f"wire {'ABC'[k]}/0 is {perimeter * 1000:.0f} mm long, longer than the 1000 mm stock "
                                 "of my bender: it needs a longer stock or a joint" for k in range(3)])
        self.assertEqual(found, sizes.size_warnings(d, 1.0, "my bender")[1:])
        with self.assertRaisesRegex(ValueError, "stock_length"):
            sizes.stock_warnings(d, stock_length=float("nan"))


if __name__ == "__main__":
    unittest.main()
