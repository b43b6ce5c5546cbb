"""A figure said against the limit it breaks (core/figures.versus): the same precision for both,
and digits enough that the two never read alike; then the warnings and errors that say one (core
sizes, scene, meshcheck). Expected texts are written out by hand."""
import json
import os
import tempfile
import unittest

import numpy as np

from wiresculpt.core import meshcheck, sizes
from wiresculpt.core.figures import mass_text, versus
from wiresculpt.core.scene import parse_scene


class Versus(unittest.TestCase):
    def test_same_decimals_and_more_until_they_differ(self):
        self.assertEqual(versus(61.234, 60.0, 1), ("61.2", "60.0"))
        self.assertEqual(versus(60.01, 60.0, 1), ("60.01", "60.00"))  # not "60.0 … 60.0"
        self.assertEqual(versus(60.01, 60.0, 2), ("60.01", "60.00"))  # not "60.01 … 60.0"
        self.assertEqual(versus(60.0000004, 60.0, 2), ("60.0000004", "60.0000000"))
        self.assertEqual(versus(14.99999, 15.0, 3), ("14.99999", "15.00000"))  # under a least value

    def test_a_signed_value_is_compared_by_its_magnitude(self):
        self.assertEqual(versus(-60.23, 60.0, 2), ("-60.23", "60.00"))
        self.assertEqual(versus(-60.001, 60.0, 2), ("-60.001", "60.000"))

    def test_significant_digits(self):
        self.assertEqual(versus(3e9, 1e9, 6, "g"), ("3e+09", "1e+09"))
        self.assertEqual(versus(100.0000001, 100.0, 6, "g"), ("100.0000001", "100"))
        self.assertEqual(versus(0.0009999999, 0.001, 6, "g"), ("0.0009999999", "0.001"))

    def test_equal_or_endless_figures_keep_their_digits(self):
        self.assertEqual(versus(60.0, 60.0, 1), ("60.0", "60.0"))
        self.assertEqual(versus(float("inf"), 60.0, 1), ("inf", "60.0"))
        self.assertEqual(versus(float("nan"), 60.0, 1), ("nan", "60.0"))


class Masses(unittest.TestCase):
    def test_grams_below_a_kilogram_kilograms_from_one(self):
        self.assertEqual(mass_text(136.2), "136 g")
        self.assertEqual(mass_text(999.4), "999 g")
        self.assertEqual(mass_text(999.6), "1.0 kg")  # not "1000 g"
        self.assertEqual(mass_text(37692.0), "37.7 kg")
        self.assertEqual(mass_text(456764.0), "456.8 kg")


def ring(radius, n=4):
    """A closed square of wire in the xy plane, corners at distance `radius`: side radius * sqrt(2)."""
    t = np.arange(n) * 2 * np.pi / n
    return np.stack([radius * np.cos(t), radius * np.sin(t), np.zeros(n)], axis=1).tolist()


class Warnings(unittest.TestCase):
    def test_a_model_just_over_the_largest_reads_over(self):
        # corners at +-0.7502 m: 1.5004 m across, over LARGEST_MODEL 1.5 m by 0.4 mm
        found = sizes.size_warnings({"wires": [{"name": "A/0", "closed": True, "contour": ring(0.7502)}]}, 100.0)
        self.assertEqual(len(found), 1)
        self.assertIn("the model is 1.5004 m across, over 1.5000 m:", found[0])

    def test_a_wire_just_over_the_stock_reads_longer(self):
        found = sizes.size_warnings({"wires": [{"name": "A/0", "closed": True, "length": 1.0004, "contour": ring(0.1)}]})
        self.assertEqual(len(found), 1)
        self.assertIn("wire A/0 is 1000.4 mm long, longer than the 1000.0 mm stock", found[0])


class Errors(unittest.TestCase):
    def test_a_scene_value_just_over_its_limit(self):
        with tempfile.TemporaryDirectory() as folder:
            open(os.path.join(folder, "m.obj"), "w").close()
            scene = {"mesh": "m.obj", "size": 100.0000001, "planes": [{"origin": [0, 0, 0], "normal": [0, 0, 1]}]}
            with self.assertRaises(ValueError) as ctx:
                parse_scene(json.loads(json.dumps(scene)), os.path.join(folder, "scene.json"))
        self.assertEqual(str(ctx.exception), 'scene key "size" must be at most 100, got 100.0000001')

    def test_a_mesh_just_over_ten_metres(self):
        with self.assertRaises(ValueError) as ctx:
            meshcheck.check_vertices(np.array([[0, 0, 0], [10.0000001, 0, 0]]), "m.obj", None)
        self.assertIn("mesh file m.obj is 10.0000001 units across, read as metres that is over 10 m;",
                      str(ctx.exception))


if __name__ == "__main__":
    unittest.main()
