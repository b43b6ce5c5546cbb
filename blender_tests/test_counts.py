"""One count, one figure in Blender: Apply of a plane candidate says as many
contours "used as wires" as it ticks (the candidate's wires), not the Slice defaults it started
from; and Optimize's messages give the design's own wire lengths.
    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- counts"""
import math
import re
import types
import unittest.mock
import unittest

import bpy

from helpers import GLOBE_RADIUS as R
from helpers import BlenderCase, add_handle, globe
from wiresculpt import native, pipeline, plane_search
from wiresculpt.blend.handles import handle_plane, handles
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.scene import PlaneSpec
from wiresculpt.core.settings import defaults
from wiresculpt.blend import mesh, ownership
from wiresculpt.core import session
from wiresculpt.operators import plane_search as ops


def run(operator_class, **props):
    reports = []
    fake = types.SimpleNamespace(report=lambda kind, message: reports.append((kind, message)), **props)
    return operator_class.execute(fake, bpy.context), reports


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class ApplySaysWhatItTicks(BlenderCase):
    def test_apply_counts_the_candidates_wires(self):
        target = globe()  # handles z, x, y through the centre: one contour each, all ticked
        add_handle((0, 0, 0), (0, 0, 0.5 * R))  # a fourth, parallel to the first: Slice ticks its contour too
        bpy.context.view_layer.update()
        self.assertEqual(bpy.ops.wiresculpt.slice(), {'FINISHED'})
        scene = bpy.context.scene
        self.assertEqual(sum(i.use for i in scene.wiresculpt.contours), 4)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        placed = [handle_plane(h, depsgraph) for h in handles(scene)]
        V, F = mesh.object_triangles(target, depsgraph)
        # the candidate: the globe's three great circles, solved apart from the operators
        three = [PlaneSpec(name, origin, normal) for name, origin, normal in placed[:3]]
        design = pipeline.run(V, F, three, PRESETS["steel"], defaults())
        self.assertEqual(len(design["wires"]), 3)
        candidate = {"planes": [plane_search.Placement(n, o, d, "largest") for n, o, d in placed],
                     "changes": [], "design": design, "figures": {}}
        owner = ownership.stamp(scene, ops.OWNER_KIND, session.generation())  # made for this scene and file
        ops.RESULT = {"owner": owner, "scene": scene.name, "mode": "nearby", "candidates": [candidate], "message": ""}
        self.addCleanup(setattr, ops, "RESULT", None)
        result, reports = run(ops.WIRESCULPT_OT_apply_planes, index=0)
        self.assertEqual(result, {'FINISHED'}, reports)
        ticked = sum(i.use for i in scene.wiresculpt.contours)
        self.assertEqual(ticked, 3)
        said = re.search(r"(\d+) contours, (\d+) used as wires", reports[-1][1])
        self.assertIsNotNone(said, reports)
        self.assertEqual((int(said[1]), int(said[2])), (len(scene.wiresculpt.contours), ticked))


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class StockWarningsGiveTheWiresLength(BlenderCase):
    def test_optimize_warns_with_the_solved_length(self):
        from wiresculpt.operators import optimize

        globe()
        stock = 0.5  # the globe's wires are about 2 pi R = 785 mm
        with unittest.mock.patch.object(optimize, "chosen_stock", lambda scene: (stock, "a short bender")):
            self.assertEqual(bpy.ops.wiresculpt.optimize(), {'FINISHED'})
        from wiresculpt.blend import results as scene_results

        design = scene_results.stored_design()
        said = {}
        for text in design.get("warnings", []):
            found = re.search(r"wire (.+?) is (\d+) mm long, longer than the 500 mm stock of a short bender", text)
            if found:
                said[found[1]] = int(found[2])
        self.assertEqual(sorted(said), sorted(w["name"] for w in design["wires"]))
        for w in design["wires"]:
            target = w["target"] + w["target"][:1]
            walked = sum(math.dist(a, b) for a, b in zip(target, target[1:]))  # the wire's own polyline
            self.assertEqual(said[w["name"]], round(walked * 1000), w["name"])


if __name__ == "__main__":
    unittest.main()
