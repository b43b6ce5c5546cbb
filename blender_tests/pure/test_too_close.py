"""The hooks the plane search's screen forbids as too close (native too_close_hooks, reached through
stages.layering.run(too_close=...) as Searcher._layer calls it) against the target-shape stage's own
verdicts, reached the way the pipeline reaches them (stages.target_shape.prepare_wire and solve_job:
the wire's plane frame, each hook's desired bisector, friction 0, the 0.1 deg tolerance). On random
cuts of a sphere, whose crossings often come closer than 2 x min_segment along a wire, a hook is
forbidden exactly when, with that hook at every crossing, the stage reports the crossing too_close on
one of its two wires. The stage gives that verdict before solving, so one evaluation is enough."""
import copy
import random
import unittest

import numpy as np

from wiresculpt import native, pipeline
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.scene import PlaneSpec
from wiresculpt.core.settings import defaults
from wiresculpt.stages import layering, target_shape

from helpers import sphere

R = 0.1


def random_planes(rng, count=4):
    planes = []
    for k in range(count):
        n = np.array([rng.uniform(-1, 1) for _ in range(3)])
        n = n / np.linalg.norm(n) if np.linalg.norm(n) > 0.2 else np.array([0.0, 0.0, 1.0])
        planes.append(PlaneSpec(f"P{k}", tuple(n * rng.uniform(-0.6, 0.6) * R), tuple(n), "largest"))
    return planes


def stage_too_close(probe, settings):
    """{(crossing id, hook)} that the target-shape stage reports too_close on either wire, with that
    hook at every crossing."""
    close = set()
    for hook in (-1, 1):
        design = copy.deepcopy(probe)
        for c in design["crossings"]:
            c["hook"] = hook
        for wire in design["wires"]:
            job = target_shape.prepare_wire(design, wire, settings, 2 * R)
            if not job["specs"]:
                continue
            job["options"]["max_iterations"] = 1
            result = target_shape.solve_job(job)
            for (c, _k), status in zip(job["refs"], result["crossings"]):
                if status["status"] == "too_close":
                    close.add((c["id"], hook))
    return close


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class TooCloseMatchesTheStage(unittest.TestCase):
    def test_random_cuts_of_a_sphere(self):
        V, F = sphere(R)
        rng = random.Random(20261202)
        settings = dict(defaults(), cuts={})
        material = PRESETS["steel"]
        scenes, counts = 0, {0: 0, 1: 0, 2: 0}
        for _attempt in range(300):
            if scenes >= 15:
                break
            design = pipeline.slice_and_pick(V, F, random_planes(rng), material, settings)
            if len(design["wires"]) < 2:
                continue
            probe = copy.deepcopy(design)
            try:
                layering.run(probe, material, settings, too_close=target_shape.REALISED_ANGLE)
            except ValueError:  # planes the network refuses (two nearly coincide)
                continue
            if len(probe["crossings"]) < 2:
                continue
            scenes += 1
            forbidden = {tuple(p) for p in probe["too_close_forbidden"]}
            self.assertEqual(forbidden, stage_too_close(probe, settings))
            for c in probe["crossings"]:
                counts[sum((c["id"], h) in forbidden for h in (-1, 1))] += 1
        self.assertGreaterEqual(scenes, 15)
        self.assertGreaterEqual(counts[2], 5)   # too short a piece, or neither hook's cone holds it
        self.assertGreaterEqual(counts[1], 3)   # one hook's cone holds the fixed piece
        self.assertGreaterEqual(counts[0], 30)


if __name__ == "__main__":
    unittest.main()
