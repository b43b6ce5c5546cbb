"""The pipeline in-process: the Sec. 4.3 coupling between target and rest shape, and cancelling."""
import math
import unittest

import numpy as np

from wiresculpt import native, pipeline
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.scene import PlaneSpec
from wiresculpt.core.settings import defaults

from helpers import PLANES, sphere

def largest_rest_turn_deg(design):
    """The largest turning angle of any rest polyline, from its points alone."""
    worst = 0.0
    for w in design["wires"]:
        p = np.asarray(w["rest"])
        e = np.diff(p, axis=0)
        e = e[np.linalg.norm(e, axis=1) > 0]
        cross = e[:-1, 0] * e[1:, 1] - e[:-1, 1] * e[1:, 0]
        dot = np.sum(e[:-1] * e[1:], axis=1)
        worst = max(worst, float(np.max(np.degrees(np.abs(np.arctan2(cross, dot))))))
    return worst


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Coupling(unittest.TestCase):
    def solve(self, rounds):
        settings = defaults()
        # the plastic limit and the force LP as before issue 16: rest bends that need the coupling
        settings.update(contact_angle_deg=140.0, max_bend_deg=50.0, torque_fraction=1.0, least_out_of_plane=False)
        V, F = sphere()
        saved, module = pipeline.COUPLING_ROUNDS, native.require()
        pipeline.COUPLING_ROUNDS = rounds
        saved_patterns, pipeline.HOOK_PATTERNS = pipeline.HOOK_PATTERNS, 1  # one hook pattern: count its solves
        self.calls = 0

        class Counting:  # counts the native target-shape solves of every round
            def __getattr__(_self, name):
                if name != "optimize_target_shape":
                    return getattr(module, name)

                def solve(*args):
                    self.calls += 1
                    return module.optimize_target_shape(*args)
                return solve
        saved_require = native.require
        native.require = Counting
        try:
            # A soft, strong wire (k_b 0.1 N m², plastic torque 3 N m): its rest bends go past
            # 50 deg by about a degree uncoupled, which the coupling can take back.
            material = dict(PRESETS["steel"], bending_stiffness=0.1, max_torque=3.0)
            return pipeline.run(V, F, PLANES, material, settings)
        finally:
            pipeline.COUPLING_ROUNDS = saved
            pipeline.HOOK_PATTERNS = saved_patterns
            native.require = saved_require

    def test_rest_bends_respect_the_machine_after_coupling(self):
        once = self.solve(1)
        self.assertTrue(once["stable"])
        self.assertGreater(largest_rest_turn_deg(once), 50.0)  # the case needs the coupling
        coupled = self.solve(4)
        self.assertTrue(coupled["stable"])
        self.assertLessEqual(largest_rest_turn_deg(coupled), 50.0 + 1e-6)
        stage = coupled["stages"]["target_shape"]
        self.assertGreater(stage["coupling_rounds"], 1)
        # The stage's counts add every coupling round, as its time does.
        self.assertEqual(stage["wire_solves"], self.calls)
        self.assertGreater(stage["wire_solves"], len(coupled["wires"]))
        self.assertLess(stage["max_bend_deg"], 50.0)
        self.assertEqual(coupled["pending_stages"], [])


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Cuts(unittest.TestCase):
    def test_a_users_cut_starts_the_rest_shape(self):
        settings = defaults()
        settings["cuts"] = {"A/0": 7}
        V, F = sphere()
        design = pipeline.run(V, F, PLANES, PRESETS["steel"], settings)
        wire = next(w for w in design["wires"] if w["name"] == "A/0")
        self.assertEqual(wire["cut"], 7)
        # FORMATS: rest has the target's edge lengths walked from the cut, one point more.
        target, rest = np.asarray(wire["target"]), np.asarray(wire["rest"])
        m = len(target)
        self.assertEqual(len(rest), m + 1)
        walked = [np.linalg.norm(target[(7 + j + 1) % m] - target[(7 + j) % m]) for j in range(m)]
        np.testing.assert_allclose(np.linalg.norm(np.diff(rest, axis=0), axis=1), walked, atol=1e-12)


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Cancelling(unittest.TestCase):
    def test_cancel_at_once_and_after_layering(self):
        V, F = sphere()
        for after in (0, 1):
            calls = []

            def cancel():
                calls.append(1)
                return len(calls) > after

            design = pipeline.slice_and_pick(V, F, PLANES, PRESETS["steel"], defaults())
            with self.assertRaises(pipeline.Cancelled):
                pipeline.solve(design, PRESETS["steel"], defaults(), cancel=cancel)


if __name__ == "__main__":
    unittest.main()
