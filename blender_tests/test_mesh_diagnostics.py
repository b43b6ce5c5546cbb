"""The mesh's faults in Blender's verdicts: a model of two separate spheres
(whose wires of one cannot hold the other's) makes Optimize, Find Stable Planes and Suggest
Planes say what is wrong with the mesh and what to do, with the figures design.json keeps.
    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- mesh_diagnostics"""
import re
import types
import unittest
from unittest import mock

import bpy
import numpy as np

from helpers import BlenderCase, add_handle, mesh_model, sphere
from wiresculpt import native, plane_search
from wiresculpt.blend import results as scene_results
from wiresculpt.core import mesh_faults
from wiresculpt.operators import optimize
from wiresculpt.operators import plane_search as ops

RADIUS, GAP = 0.125, 0.01


def two_spheres_target():
    V, F = sphere(RADIUS)
    V = np.concatenate([V, V + [2 * RADIUS + GAP, 0.0, 0.0]])
    F = np.concatenate([F, F + len(V) // 2])
    mesh_model("two spheres", V, F)
    for rotation in ((0, 0, 0), (0, np.pi / 2, 0), (np.pi / 2, 0, 0)):  # z = 0 and y = 0 cut both spheres
        add_handle(rotation)
    assert bpy.ops.wiresculpt.slice() == {'FINISHED'}
    for item in bpy.context.scene.wiresculpt.contours:
        item.use = True  # every contour a wire: the second sphere's two cross only each other


def run(operator_class):
    reports = []
    fake = types.SimpleNamespace(report=lambda kind, message: reports.append((kind, message)),
                                 _finish=lambda c, d, *a, **k: operator_class._finish(fake, c, d, *a, **k))
    return operator_class.execute(fake, bpy.context), reports


class Searched:
    screened, full_solves = 12, 0


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class MeshFaultsSaid(BlenderCase):
    def setUp(self):
        super().setUp()
        ops.RESULT = ops.PREVIEW = None
        two_spheres_target()

    def parts(self, text):
        said = re.search(r"the mesh has (\d+) separate parts .*voxel remesh \(about (\d+) mm\)", text)
        self.assertIsNotNone(said, text)
        return int(said[1]), int(said[2])

    def test_optimize_says_the_mesh_has_two_parts(self):
        result, reports = run(optimize.WIRESCULPT_OT_optimize)
        self.assertEqual(result, {'FINISHED'})
        design = scene_results.stored_design()
        self.assertFalse(design["stable"])
        fault = design["mesh_faults"][0]
        self.assertEqual(fault["cause"], mesh_faults.SHELLS)
        kind, text = reports[-1]
        self.assertEqual(kind, {'WARNING'})
        self.assertEqual(self.parts(text), (fault["shells"], round(fault["voxel"] * 1000)))
        self.assertEqual(fault["shells"], 2)
        self.assertGreaterEqual(fault["voxel"], GAP / 2)

    def test_the_plane_searches_say_it_when_they_find_nothing(self):
        for operator_class, name in ((ops.WIRESCULPT_OT_find_planes, "nearby"),
                                     (ops.WIRESCULPT_OT_suggest_planes, "auto")):
            with self.subTest(name), mock.patch.object(plane_search, name,
                                                       lambda *a, **k: ([], Searched(), 0.0)):
                self.assertEqual(getattr(bpy.ops.wiresculpt, operator_class.bl_idname.split(".")[1])(),
                                 {'FINISHED'})
                message = ops.RESULT["message"]
                self.assertEqual(self.parts(message)[0], 2)
                self.assertIn("(12 screened, 0 solved)", message)
                self.assertLess(len(message), 400)


if __name__ == "__main__":
    unittest.main()
