"""Captures that parse and fit but were probably not meant: one load, a tilt in
radians, a 200° command, deflections typed in millimetres. Each gives a sentence naming the
number; a plausible capture gives none."""
import unittest

from wiresculpt import native
from wiresculpt.core import calibration as cal

HEAD = "load_g,state,s_m,deflection_m\n"


def frames(loads, deflection_scale=1.0):
    rows = []
    for g in loads:
        for s in (0.1, 0.2, 0.3):  # deflection of a cantilever tip-loaded, roughly in metres
            rows.append(f"{g},loaded,{s},{deflection_scale * g * 1e-5 * s * s * 30:.6g}")
    return HEAD + "\n".join(rows) + "\n"


class CalibrationWarnings(unittest.TestCase):
    def test_cantilever(self):
        self.assertEqual(cal.cantilever_warnings(cal.read_cantilever(frames([0, 20, 50]))), [])
        [one] = cal.cantilever_warnings(cal.read_cantilever(frames([0, 50])))
        self.assertIn("only one load (50 g)", one)
        typed_mm = cal.cantilever_warnings(cal.read_cantilever(frames([0, 20, 50], deflection_scale=1000.0)))
        self.assertEqual(len(typed_mm), 1)
        self.assertIn("millimetres", typed_mm[0])
        self.assertIn("line ", typed_mm[0])

    def test_tilt(self):
        self.assertEqual(cal.tilt_warnings([17.5, 18.2, 17.9]), [])
        [w] = cal.tilt_warnings([0.31, 0.3, 0.32])
        self.assertIn("0.32 rad is 18.3°", w)

    def test_springback(self):
        self.assertEqual(cal.springback_warnings([10, 50, 90, 150]), [])
        [w] = cal.springback_warnings([10, 90, 200])
        self.assertIn("200° is beyond 180°", w)
        [w] = cal.springback_warnings([0.2, 0.9, 1.5])
        self.assertIn("radians", w)

    @unittest.skipUnless(native.available(), native.LOAD_ERROR)
    def test_the_fits_carry_them(self):
        fit = cal.fit_springback("commanded_deg,measured_deg\n10,8.8\n90,82.4\n200,185\n")
        self.assertEqual(len(fit["warnings"]), 1)
        self.assertIn("200", fit["warnings"][0])
        fit = cal.fit_friction("repeat,angle_deg\n1,0.31\n2,0.3\n3,0.33\n")
        self.assertEqual(len(fit["warnings"]), 1)


if __name__ == "__main__":
    unittest.main()
