"""The mesh's faults in the pipeline's verdict (core/mesh_faults.explain through pipeline.solve):
a mesh of two separate spheres, whose wires of one sphere cannot hold the other's, fails with the
mesh's words first; one sphere does not get them. The figures are known by construction."""
import re
import unittest

import numpy as np

from wiresculpt import native, pipeline, plane_search
from wiresculpt.core import mesh_faults, sizes
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.scene import PlaneSpec
from wiresculpt.core.settings import defaults

from helpers import PLANES, sphere

RADIUS = 0.125


def two_spheres(gap):
    V, F = sphere(RADIUS)
    return np.concatenate([V, V + [2 * RADIUS + gap, 0.0, 0.0]]), np.concatenate([F, F + len(V)])


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class MeshVerdictTest(unittest.TestCase):
    def test_two_separate_spheres_fail_with_the_mesh_first(self):
        gap = 0.01
        V, F = two_spheres(gap)
        # A (z = 0) and C (y = 0) cut both spheres, B (x = 0) only the first: every contour a wire
        planes = [PlaneSpec(p.name, p.origin, p.normal, "all") for p in PLANES]
        design = pipeline.slice_and_pick(V, F, planes, PRESETS["steel"], defaults())
        self.assertEqual(len(design["wires"]), 5)
        self.assertAlmostEqual(design["model_size"], 4 * RADIUS + gap, places=9)  # the two spheres side by side
        solved = pipeline.solve(design, PRESETS["steel"], defaults())
        self.assertFalse(solved["stable"])
        self.assertIn(mesh_faults.SHELLS, solved["reason_causes"])
        self.assertEqual([f["cause"] for f in solved["mesh_faults"]], [mesh_faults.SHELLS])
        said = re.match(r"the mesh has (\d+) separate parts \(the largest (\d+) % of its surface\).*"
                        r"voxel remesh \(about (\d+) mm\)", solved["reason"])
        self.assertIsNotNone(said, solved["reason"])
        self.assertEqual(int(said[1]), 2)
        self.assertEqual(int(said[2]), 50)
        voxel = solved["mesh_faults"][0]["voxel"]
        self.assertGreaterEqual(voxel, gap / 2)  # points two voxels apart never fuse
        self.assertEqual(int(said[3]), round(voxel * 1000))
        self.assertIn("(the solver: ", solved["reason"])  # the solver's own reason still follows

    def test_one_sphere_has_no_mesh_faults(self):
        V, F = sphere(RADIUS)
        design = pipeline.slice_and_pick(V, F, PLANES, PRESETS["steel"], defaults())
        self.assertEqual(design["mesh_faults"], [])
        self.assertAlmostEqual(sizes.model_size(design), 2 * RADIUS, places=9)
        # the nearby search's "the model's N mm" is the same figure (its frame's size S)
        self.assertEqual(plane_search.mesh_frame(V, F)[2], design["model_size"])


if __name__ == "__main__":
    unittest.main()
