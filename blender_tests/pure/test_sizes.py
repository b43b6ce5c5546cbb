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

    def test_the_model_size_is_the_recorded_mesh_size(self):
        # a box 0.4 x 0.25 x 0.1 m, its vertices' extremes by hand; the wires lie inside it
        box = [[x, y, z] for x in (-0.2, 0.2) for y in (0.0, 0.25) for z in (0.0, 0.1)]
        self.assertAlmostEqual(sizes.mesh_size(np.asarray(box)), 0.4, places=12)
        self.assertAlmostEqual(sizes.mesh_size(box), 0.4, places=12)
        self.assertEqual(sizes.mesh_size(np.zeros((0, 3))), 0.0)
        d = design(0.125)
        self.assertAlmostEqual(sizes.model_size(d), 0.25, places=3)  # the wires' own box without a record
        d["model_size"] = sizes.mesh_size(box)
        self.assertAlmostEqual(sizes.model_size(d), 0.4, places=12)

    def test_causes_carry_their_figures_and_what_they_were_measured_on(self):
        d = design(0.2)
        perimeter = 64 * 2 * 0.2 * math.sin(math.pi / 64)
        facts = sizes.size_facts(d, 1.0, "my bender")
        self.assertEqual([f["cause"] for f in facts], [sizes.OVER_STOCK] * 3)
        self.assertTrue(all(f["measured"] == sizes.MEASURED_CONTOUR for f in facts))
        self.assertAlmostEqual(facts[0]["length"], perimeter, places=12)
        self.assertIn("(its sliced contour", sizes.size_sentence(facts[0]))
        # a solved wire: its own length decides, and the sentence gives it without the contour's label
        d["wires"][0]["length"] = 1.125
        d["wires"][0]["target"] = d["wires"][0]["contour"]
        fact = sizes.size_facts(d, 1.0, "my bender")[0]
        self.assertEqual((fact["measured"], fact["length"]), (sizes.MEASURED_WIRE, 1.125))
        self.assertIn("wire A/0 is 1125 mm long, longer than the 1000 mm stock of my bender",
                      sizes.size_sentence(fact))
        big = {"wires": d["wires"], "model_size": 2.0}
        self.assertEqual(sizes.size_facts(big, 3.0)[0], {"cause": sizes.TOO_LARGE, "size": 2.0,
                                                          "limit": sizes.LARGEST_MODEL})

    def test_the_limits_and_the_warnings_give_the_same_figures(self):
        from wiresculpt.core.limits import broken_limits

        d = design(0.2)
        for k, w in enumerate(d["wires"]):  # solved: each wire its own length, 1.1 m and more
            w["target"], w["length"] = w["contour"], 1.1 + 0.05 * k
        d["model_size"] = 1.6  # the mesh's, recorded: the wires' own box is 0.4 m
        warned = sizes.size_warnings(d)
        limits = broken_limits(d)
        self.assertIn("the model is 1.60 m across", warned[0])
        self.assertIn("1.60 m across, over 1.50 m", limits)
        self.assertIn("wire C/0 is 1200 mm long", warned[3])
        self.assertIn("3 wires are longer than the 1000 mm stock, C/0 1200 mm", limits)

    def test_the_stock_sentences_alone(self):
        """stock_warnings: the wires' sentences of size_warnings (what an export notes), not the model's."""
        d = design(1.35)
        perimeter = 64 * 2 * 1.35 * math.sin(math.pi / 64)
        found = sizes.stock_warnings(d, 1.0, "my bender")
        self.assertEqual(found, [f"wire {'ABC'[k]}/0 is {perimeter * 1000:.0f} mm long (its sliced contour; the solve "
                                 "sets the wire's length), longer than the 1000 mm stock of my bender: it needs a "
                                 "longer stock or a joint" for k in range(3)])
        self.assertEqual(found, sizes.size_warnings(d, 1.0, "my bender")[1:])
        with self.assertRaisesRegex(ValueError, "stock_length"):
            sizes.stock_warnings(d, stock_length=float("nan"))


if __name__ == "__main__":
    unittest.main()
