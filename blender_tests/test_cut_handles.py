"""Cut handles: Optimize puts one empty per closed wire at its cut; moving it moves the cut, deleting
it gives the automatic cut back.

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- cut_handles
"""
import unittest

import bpy
import numpy as np

from wiresculpt import native
from wiresculpt.blend import cut_handles
from wiresculpt.blend import results as scene_results
from wiresculpt.core.frames import plane_frame

from helpers import BlenderCase as Case, edge_lengths, globe


def handles():
    return {o[cut_handles.CUT_KEY]: o for o in bpy.context.scene.objects if cut_handles.CUT_KEY in o}


def wire_named(design, name):
    return next(w for w in design["wires"] if w["name"] == name)


def crossing_vertices(design, wire):
    return {c["vertices"][k] for c in design["crossings"] for k in (0, 1) if c["wires"][k] == wire["id"]}


def optimize():
    assert bpy.ops.wiresculpt.optimize() == {'FINISHED'}
    design = scene_results.stored_design()
    assert design["stable"], design["reason"]
    return design


@unittest.skipUnless(native.available(), "the native module is not built")
class CutHandles(Case):
    def test_one_handle_per_closed_wire_at_its_cut(self):
        globe()
        design = optimize()
        found = handles()
        self.assertEqual(sorted(found), sorted(w["name"] for w in design["wires"] if w["closed"]))
        self.assertEqual(len(found), 3)
        for name, obj in found.items():
            wire = wire_named(design, name)
            np.testing.assert_allclose(obj.location, wire["target"][wire["cut"]], atol=1e-9)
            self.assertIn(obj.name, bpy.data.collections[cut_handles.CUTS_COLLECTION].objects)
            self.assertFalse(cut_handles.is_moved(obj))
            self.assertNotIn("cut_point", wire)

    def test_moving_a_handle_moves_the_cut(self):
        globe()
        first = optimize()
        name = sorted(handles())[0]
        wire = wire_named(first, name)
        target = np.asarray(wire["target"])
        n = len(target)
        taken = crossing_vertices(first, wire)
        # a point a quarter of the way round from the automatic cut that is not a crossing
        j = next(k % n for k in range(wire["cut"] + n // 4, wire["cut"] + n) if k % n not in taken)
        normal, _u, _v = plane_frame(wire["plane"]["normal"])
        handles()[name].location = target[j] + 0.002 * normal  # 2 mm off the plane: still nearest to j
        second = optimize()
        moved = wire_named(second, name)
        self.assertEqual(moved["cut"], j)
        self.assertNotEqual(moved["cut"], wire["cut"])
        # the rest shape is walked from the new cut: its edges are the target's edges from j
        t = np.asarray(moved["target"])
        walked = np.concatenate([t[j:], t[:j + 1]])
        np.testing.assert_allclose(edge_lengths(moved["rest"]), edge_lengths(walked), rtol=1e-9, atol=1e-12)
        # the handle sits on the cut now, and stays the user's on the next run
        obj = handles()[name]
        np.testing.assert_allclose(obj.location, t[j], atol=1e-9)
        self.assertTrue(cut_handles.is_moved(obj))
        self.assertEqual(wire_named(optimize(), name)["cut"], j)
        # the other wires keep their automatic cuts
        for other in first["wires"]:
            if other["name"] != name:
                self.assertEqual(wire_named(second, other["name"])["cut"], other["cut"])

    def test_a_handle_on_a_crossing_cuts_beside_it(self):
        globe()
        first = optimize()
        name = sorted(handles())[0]
        wire = wire_named(first, name)
        target = np.asarray(wire["target"])
        crossing = sorted(crossing_vertices(first, wire))[0]
        handles()[name].location = target[crossing]
        moved = wire_named(optimize(), name)
        taken = crossing_vertices(first, wire)
        self.assertNotIn(moved["cut"], taken)
        free = [k for k in range(len(target)) if k not in taken]
        distance = np.linalg.norm(target[free] - target[crossing], axis=1)
        self.assertAlmostEqual(float(np.linalg.norm(target[moved["cut"]] - target[crossing])), float(distance.min()),
                               places=12)

    def test_deleting_a_handle_restores_the_automatic_cut(self):
        globe()
        first = optimize()
        name = sorted(handles())[0]
        wire = wire_named(first, name)
        n = len(wire["target"])
        taken = crossing_vertices(first, wire)
        j = next(k % n for k in range(wire["cut"] + n // 3, wire["cut"] + n) if k % n not in taken)
        handles()[name].location = wire["target"][j]
        self.assertEqual(wire_named(optimize(), name)["cut"], j)
        bpy.data.objects.remove(handles()[name], do_unlink=True)
        again = optimize()
        self.assertEqual(wire_named(again, name)["cut"], wire["cut"])
        self.assertFalse(cut_handles.is_moved(handles()[name]))

    def test_assembly_slider_hides_the_handles_of_wires_not_yet_added(self):
        globe()
        design = optimize()
        step = 1
        shown = {design["wires"][w]["name"] for w in design["assembly_steps"][0]}
        self.assertLess(len(shown), 3)
        bpy.context.scene.wiresculpt.assembly_step = step
        for name, obj in handles().items():
            self.assertEqual(obj.hide_viewport, name not in shown, name)
        bpy.context.scene.wiresculpt.assembly_step = 0
        self.assertFalse(any(obj.hide_viewport for obj in handles().values()))

    def test_clear_results_removes_the_handles(self):
        globe()
        optimize()
        scene_results.clear_results(bpy.context.scene)
        self.assertEqual(handles(), {})


if __name__ == "__main__":
    unittest.main()
