"""Every numeric option of the bindings has a documented range checked on entry
(docs/robustness.md); values that would hang, eat memory or abort are refused in one sentence,
and the target shape has a wall-clock budget. The messages are written out by hand."""
import math
import os
import subprocess
import sys
import unittest

import numpy as np

from wiresculpt import native

ROOT_ADDON = native.__file__.rsplit("/wiresculpt/", 1)[0]
GLOBE_DIR = os.path.join(os.path.dirname(ROOT_ADDON), "scripts", "examples", "globe")

# The globe example through the bpy-free pipeline, as the batch run scales it, with a material
# whose density is argv[3]; prints the error's type and sentence.
GLOBE_CHILD = r"""
import json, os, sys
sys.path.insert(0, sys.argv[1])
import numpy as np
from wiresculpt import pipeline
from wiresculpt.core import materials, settings
from wiresculpt.core.scene import PlaneSpec
V, F = [], []
for line in open(os.path.join(sys.argv[2], "globe.obj")):
    w = line.split()
    if w and w[0] == "v":
        V.append([float(x) for x in w[1:4]])
    elif w and w[0] == "f":  # polygons as fans, as Blender triangulates them
        k = [int(x.split("/")[0]) - 1 for x in w[1:]]
        F.extend([k[0], k[i], k[i + 1]] for i in range(1, len(k) - 1))
V, F = np.array(V), np.array(F, dtype=np.int32)
scene = json.load(open(os.path.join(sys.argv[2], "scene.json")))
factor = scene["size"] / float(np.max(V.max(axis=0) - V.min(axis=0)))
planes = [PlaneSpec(p["name"], tuple(factor * c for c in p["origin"]), tuple(p["normal"]), p["contours"])
          for p in scene["planes"]]
material = dict(materials.PRESETS["steel"], density=float(sys.argv[3]))
s = settings.defaults()
s["cuts"] = {}
try:
    pipeline.run(V * factor, F, planes, material, s)
    print("solved")
except (ValueError, RuntimeError) as exc:
    print(f"{type(exc).__name__}: {exc}")
"""


def ring(n=64, radius=0.1):
    t = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    return np.stack([radius * np.cos(t), radius * np.sin(t)], axis=1)


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class OptionRanges(unittest.TestCase):
    def refused(self, call, message):
        with self.assertRaises(ValueError) as ctx:
            call()
        self.assertEqual(str(ctx.exception), message)

    def test_target_shape_options(self):
        m = native.module
        cases = [
            ({"window": 2 ** 31 - 1}, "target shape of wire wire: window must be 0 (one block) or from 4 to 10000 points"),
            ({"spacing": 1e-12}, "target shape of wire wire: spacing must be 0 (1.5 x min_segment) or from "
                                 "min_segment/10 (1.5 mm) to 10 metres"),
            ({"max_iterations": 2 ** 31 - 1}, "target shape of wire wire: max_iterations must be from 1 to 10000000"),
            ({"max_sweeps": 0}, "target shape of wire wire: max_sweeps must be from 1 to 100000"),
            ({"max_seconds": 0.0}, "target shape of wire wire: max_seconds must be more than 0 and at most 86400 "
                                   "seconds"),
            ({"max_seconds": float("nan")}, "options['max_seconds']: expected a finite number, got nan"),
            ({"min_segment": 20.0}, "target shape of wire wire: min_segment must be at most 10 metres"),
        ]
        for options, message in cases:
            with self.subTest(options):
                self.refused(lambda: m.optimize_target_shape(ring(), True, [], options), message)
        # a 1e9 m wire (a mesh in no unit at all) would need 10^11 points at the default spacing
        self.refused(lambda: m.optimize_target_shape(ring(radius=1e9), True, []),
                     "target shape of wire wire: the wire is 6.281e+09 m long, which at a spacing of 22.5 mm is more "
                     "than 1e+06 points; is the model in millimetres? scale it to its real size (size) or raise "
                     "min_segment")

    def test_mma_stops_at_its_time_budget_with_a_word(self):
        # mma did not finish in 120 s on this circle; with a budget it stops and says so (or
        # converges first on a fast machine): never a silent hang.
        r = native.module.optimize_target_shape(ring(), True, [], {"algorithm": "mma", "max_seconds": 0.2,
                                                                   "max_iterations": 10 ** 7})
        if r["nlopt_result"] == "NLOPT_MAXTIME_REACHED":
            self.assertIn("wire wire: the target shape stopped at its time budget of 0.2 s (max_seconds) before it "
                          "converged", r["warnings"])
        self.assertEqual(len(r["points"]) > 0, True)

    def test_stream_and_cantilever_options(self):
        m = native.module
        self.refused(lambda: m.stream_program("/dev/null-port", ["G21"], {}, {}, settle=float("inf")),
                     "settle must be from 0 to 60 seconds, got inf")
        self.refused(lambda: m.stream_program("/dev/null-port", ["G21"], {}, {}, response_timeout=-1.0),
                     "response_timeout must be more than 0 and at most 3600 seconds, got -1")
        self.refused(lambda: m.simulate_cantilever(0.7, segments=2 ** 31 - 1),
                     "cantilever: segments must be from 2 to 100000")

    def test_density_extremes_do_not_abort_the_process(self):
        """GLPK aborted the whole process (Blender with it, exit 134) on these densities when they
        reached the load-capacity LP. The globe is solved in a child process with each density given
        past the scene's own check: an abort fails here instead of ending the test run."""
        for density in (1e-300, 1e200):
            with self.subTest(density=density):
                r = subprocess.run([sys.executable, "-c", GLOBE_CHILD, ROOT_ADDON, GLOBE_DIR, repr(density)],
                                   capture_output=True, text=True, timeout=600)
                self.assertEqual(r.returncode, 0, r.stderr[-2000:])
                self.assertEqual(r.stdout.strip().splitlines()[-1],
                                 "ValueError: density must be a number of kg/m^3 from 1 to 100000 (steel 7850)")


if __name__ == "__main__":
    unittest.main()
