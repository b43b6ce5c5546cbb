"""The preview: each wire's bend program run forward through a spring-back line,
checked against walks computed here in closed form, not by the bend program's code.

- the same profile compensates and predicts: the predicted wire is the rest shape (within 0.1 mm,
  measured here by dense arc-length sampling);
- a machine whose slope is 5 % below the compensating fit's makes every bend short by
  theta * (1 - 1/1.05): for one bend the far arm's end is off by the chord 2 L sin(error / 2); for a
  regular polygon every corner k sits where the closed-form walk with the smaller turn puts it;
- the annotated template draws the predicted wire dashed and names it with its figure in the legend.
"""
import cmath
import math
import os
import tempfile
import unittest
import xml.etree.ElementTree as ET

import numpy as np

from wiresculpt import native
from wiresculpt.fab import export

SVG = "{http://www.w3.org/2000/svg}"


def walk(start, heading, feeds, turns):
    """The polyline of straight feeds and turns between them (radians), walked here."""
    p = complex(*start)
    out = [p]
    for k, f in enumerate(feeds):
        p += f * cmath.exp(1j * heading)
        out.append(p)
        if k < len(turns):
            heading += turns[k]
    return np.array([[z.real, z.imag] for z in out])


def dense_distance(a, b, samples=4000):
    """Largest |a(s) - b(s)| over arc length s, both sampled densely (the shorter held at its end)."""
    def at(p, s):
        seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
        cum = np.concatenate([[0.0], np.cumsum(seg)])
        return np.stack([np.interp(s, cum, p[:, 0]), np.interp(s, cum, p[:, 1])], axis=1)
    total = max(np.linalg.norm(np.diff(x, axis=0), axis=1).sum() for x in (a, b))
    s = np.linspace(0.0, total, samples + 1)
    return float(np.max(np.linalg.norm(at(a, s) - at(b, s), axis=1)))


def design_of(rests, closed):
    """A design dict holding the given rest shapes (2D, m) as wires, no crossings."""
    wires = []
    for k, (rest, c) in enumerate(zip(rests, closed)):
        target = [[x, y, 0.0] for x, y in (rest[:-1] if c else rest)]
        wires.append({"id": k, "name": f"W/{k}", "closed": c, "cut": 0 if c else -1, "target": target,
                      "contour": target, "rest": rest.tolist(), "plane": {"origin": [0, 0, 0], "normal": [0, 0, 1]}})
    return {"material": {"name": "steel", "wire_diameter": 0.002}, "machine": {"min_segment": 0.015,
            "max_bend_deg": 120.0, "min_bend_deg": 1.0}, "wires": wires, "crossings": [], "stable": True}


N, SIDE = 8, 0.04  # a regular octagon of 40 mm sides, cut at a corner (rest repeats the cut)
OCTAGON = walk((0.0, 0.0), 0.0, [SIDE] * N, [2 * math.pi / N] * (N - 1))
ELL = walk((0.0, 0.0), 0.0, [0.03, 0.05], [math.radians(90)])  # one 90 deg bend, arms 30 and 50 mm
FIT = {"name": "fitted", "springback_a": 0.9, "springback_b_deg": 0.0}
WRONG = {"name": "slope 5 % off", "springback_a": 0.9 * 1.05, "springback_b_deg": 0.0}


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class PreviewTest(unittest.TestCase):
    def export(self, profile, machine):
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        result = export.export(design_of([OCTAGON, ELL], [True, False]), tmp.name, profile, machine=machine)
        self.assertEqual(result["errors"], [])
        return tmp.name, {w["name"]: w for w in result["wires"]}, result

    def test_same_profile_predicts_the_rest_shape(self):
        for profile in (None, FIT):
            _, wires, _ = self.export(profile, None)
            for name, rest in (("W/0", OCTAGON), ("W/1", ELL)):
                predicted = wires[name]["predicted"]
                self.assertLess(dense_distance(predicted, rest), 1e-4, name)  # 0.1 mm
                self.assertLess(wires[name]["preview_distance"], 1e-4)

    def test_a_slope_five_percent_off_drifts_as_computed_by_hand(self):
        # compensated with WRONG (a = 0.945), made by a machine keeping 0.9 c: each bend theta comes
        # out theta * 0.9 / 0.945 = theta / 1.05
        folder, wires, result = self.export(WRONG, FIT)
        error = math.radians(90) * (1 - 1 / 1.05)
        chord = 2 * 0.05 * math.sin(error / 2)  # the 50 mm arm swings about the bend
        self.assertAlmostEqual(chord * 1000, 3.739, places=3)  # 50 mm x 4.29 deg, by hand: ~3.74 mm
        ell = wires["W/1"]
        self.assertAlmostEqual(dense_distance(ell["predicted"], ELL), chord, delta=1e-6)
        self.assertAlmostEqual(ell["preview_distance"], chord, delta=1e-9)
        # the octagon: corner k of a walk with constant turn phi is SIDE (1 - e^{ik phi}) / (1 - e^{i phi})
        phi, phi_made = 2 * math.pi / N, 2 * math.pi / N / 1.05

        def corner(k, turn):
            return SIDE * (1 - cmath.exp(1j * k * turn)) / (1 - cmath.exp(1j * turn))
        expected = max(abs(corner(k, phi) - corner(k, phi_made)) for k in range(N + 1))
        # the loop no longer closes: its end is SIDE sin(4 phi') / sin(phi' / 2) = 16.3 mm from its start
        gap = SIDE * math.sin(N / 2 * phi_made) / math.sin(phi_made / 2)
        self.assertAlmostEqual(gap * 1000, 16.32, places=2)
        self.assertAlmostEqual(expected, gap, delta=1e-12)  # and the far end is where it is largest
        octagon = wires["W/0"]
        self.assertAlmostEqual(octagon["preview_distance"], expected, delta=1e-9)
        self.assertAlmostEqual(dense_distance(octagon["predicted"], OCTAGON), expected, delta=1e-6)
        self.assertIn("0.9000 × commanded", result["preview_model"])
        level, text = export.summary(result, folder)
        self.assertIn(f"W/1: 1 bends, 80 mm, about", text)
        self.assertIn(f"predicted within {chord * 1000:.1f} mm", text)

    def test_the_template_draws_the_prediction_and_names_it(self):
        folder, wires, _ = self.export(WRONG, FIT)
        root = ET.parse(os.path.join(folder, "templates", "01-W-1.svg")).getroot()
        path = root.find(f".//{SVG}polyline[@class='wire-path']")
        preview = root.find(f".//{SVG}polyline[@class='preview']")
        self.assertIsNotNone(preview)
        self.assertTrue(preview.get("stroke-dasharray"))
        self.assertNotEqual(preview.get("stroke"), path.get("stroke"))

        def pts(el):
            return np.array([[float(v) for v in p.split(",")] for p in el.get("points").split()])
        a, b = pts(path), pts(preview)
        np.testing.assert_allclose(a[:2], b[:2], atol=1e-3)  # the first arm is made as drawn
        self.assertAlmostEqual(np.linalg.norm(a[-1] - b[-1]), wires["W/1"]["preview_distance"] * 1000, delta=1e-3)
        legend = "".join(root.find(f".//{SVG}g[@class='legend']").itertext())
        self.assertIn("predicted wire", legend)
        self.assertIn(f"up to {wires['W/1']['preview_distance'] * 1000:.1f} mm", legend)

    def test_a_bad_machine_model_is_one_message_naming_the_key(self):
        with tempfile.TemporaryDirectory() as folder:
            with self.assertRaisesRegex(ValueError, "springback_a"):
                export.export(design_of([ELL], [False]), folder, None, machine={"springback_a": -1.0})
            self.assertEqual(os.listdir(folder), [])


class RigidFitTest(unittest.TestCase):
    def test_a_rotated_moved_and_a_mirrored_copy_are_found(self):
        from wiresculpt.core.frames import rigid_fit_2d

        src = np.array([[0.0, 0.0], [0.05, 0.0], [0.05, 0.02], [0.01, 0.03]])
        c, s = math.cos(0.7), math.sin(0.7)
        R = np.array([[c, -s], [s, c]])
        for M in (R, R @ np.diag([1.0, -1.0])):
            dst = src @ M.T + np.array([0.3, -0.1])
            fit, t = rigid_fit_2d(src, dst)
            np.testing.assert_allclose(fit, M, atol=1e-12)
            np.testing.assert_allclose(t, [0.3, -0.1], atol=1e-12)


if __name__ == "__main__":
    unittest.main()
