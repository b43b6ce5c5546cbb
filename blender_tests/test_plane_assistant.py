"""Find Stable Planes / Suggest Planes / Apply in Blender, background mode (the search
runs inline): the globe with five slicing planes of which "Slice E" (x = 0.8 R) crosses only the
plane y = 0, on one line (a hinge: planes z = c1 and x = c2 cut circles of the unit sphere that
cross iff c1^2 + c2^2 < 1, and Slice A/B are at z = +-0.7).

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- plane_assistant
"""
import json
import math
import os
import sys

import bpy
import numpy as np

from wiresculpt import native
from wiresculpt.blend import results as scene_results
from wiresculpt.blend.handles import handles
from wiresculpt.operators import plane_search as ops
from wiresculpt.ui import plane_search as panel

from helpers import GLOBE_RADIUS as R
from helpers import BlenderCase as Case
from helpers import add_handle, draw, globe_target, hinge_scene, placements

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "pure"))
import recheck  # noqa: E402


def scene_state():
    """Every object's type, matrix and visibility, every text, and the contour ticks."""
    objects = {o.name: (o.type, [list(r) for r in o.matrix_world], o.hide_viewport) for o in bpy.data.objects}
    ticks = [(i.plane, i.index, i.use) for i in bpy.context.scene.wiresculpt.contours]
    return json.dumps([objects, {t.name: t.as_string() for t in bpy.data.texts}, ticks], sort_keys=True)


def wire_names():
    return sorted(o.name for o in bpy.context.scene.objects if scene_results.WIRE_KEY in o)


def start_without_results(case):
    """Skips `case` when the native module is missing, else forgets any search and preview."""
    if not native.available():
        case.skipTest(native.LOAD_ERROR)
    ops.RESULT = None
    ops.PREVIEW = None


class FindStablePlanes(Case):
    def setUp(self):
        super().setUp()
        start_without_results(self)
        hinge_scene()

    def test_the_scene_is_a_hinge(self):
        self.assertEqual(bpy.ops.wiresculpt.optimize(), {'FINISHED'})
        design = json.loads(bpy.data.texts[scene_results.DESIGN_TEXT].as_string())
        self.assertFalse(design["stable"])
        self.assertIn("Slice E/0", design["reason"])

    def test_find_then_apply(self):
        before = placements()
        self.assertEqual(bpy.ops.wiresculpt.find_planes(), {'FINISHED'})
        self.assertEqual(placements(), before)  # searching changes nothing
        result = ops.RESULT
        self.assertTrue(1 <= len(result["candidates"]) <= 3)
        for c in result["candidates"]:
            d = json.loads(json.dumps(c["design"]))
            self.assertTrue(d["stable"])
            self.assertEqual(recheck.recheck(d), [], c["changes"])
            self.assertTrue(c["changes"])
        log = draw(panel.VIEW3D_PT_wiresculpt_planes, bpy.context)
        texts = [kw.get("text", "") for _name, _a, kw in log]
        for k in range(len(result["candidates"])):
            self.assertIn(f"Apply candidate {k + 1}", texts)
        self.assertTrue(any(t.startswith(("move plane", "tilt plane", "plane ")) for t in texts), texts)
        self.assertEqual(bpy.ops.wiresculpt.apply_planes(index=0), {'FINISHED'})
        after = placements()
        chosen = {p.name: p for p in result["candidates"][0]["planes"]}
        moved = 0
        for name, (origin, normal) in after.items():
            p = chosen[name]
            self.assertLess(np.linalg.norm(np.subtract(normal, p.normal)), 1e-5, name)
            self.assertLess(abs(np.dot(np.subtract(origin, p.origin), p.normal)), 1e-6, name)
            b_origin, b_normal = before[name]
            moved += (np.linalg.norm(np.subtract(normal, b_normal)) > 1e-6
                      or abs(np.dot(np.subtract(origin, b_origin), b_normal)) > 1e-6)
        self.assertGreaterEqual(moved, 1)
        # the candidate's wires are in the scene and its contours are the ticked ones
        self.assertEqual(len(wire_names()), len(result["candidates"][0]["design"]["wires"]))
        ticked = sorted(f"{i.plane}/{i.index}" for i in bpy.context.scene.wiresculpt.contours if i.use)
        self.assertEqual(ticked, sorted(w["name"] for w in result["candidates"][0]["design"]["wires"]))
        # and Optimize from the panel now gives a stable design from the moved planes
        self.assertEqual(bpy.ops.wiresculpt.optimize(), {'FINISHED'})
        self.assertTrue(json.loads(bpy.data.texts[scene_results.DESIGN_TEXT].as_string())["stable"])

    def test_preview_on_click_shows_the_candidate_and_changes_nothing(self):
        _V, _F, given, _material, _settings = ops.gather(bpy.context)  # the planes the search starts from
        given = {p.name: p for p in given}
        self.assertEqual(bpy.ops.wiresculpt.find_planes(), {'FINISHED'})
        candidates = ops.RESULT["candidates"]
        self.assertGreaterEqual(len(candidates), 2)
        self.assertIsNone(ops.PREVIEW)
        before = scene_state()
        for k, c in enumerate(candidates):
            self.assertEqual(bpy.ops.wiresculpt.preview_planes(index=k), {'FINISHED'})
            self.assertEqual(scene_state(), before)  # no scene data written
            self.assertEqual(ops.PREVIEW["index"], k)
            # the overlay holds each design wire's polyline (its target), as segments, in the design's order
            design = json.loads(json.dumps(c["design"]))
            self.assertEqual(len(ops.PREVIEW["wires"]), len(design["wires"]))
            for (_colour, lines), w in zip(ops.PREVIEW["wires"], design["wires"]):
                points = w["target"]
                pairs = [(points[i], points[i + 1]) for i in range(len(points) - 1)]
                if w["closed"]:
                    pairs.append((points[-1], points[0]))
                expected = [p for pair in pairs for p in pair]
                self.assertEqual(np.shape(lines), (len(expected), 3), w["name"])
                np.testing.assert_allclose(lines, expected, atol=1e-6, err_msg=w["name"])
            # and an outline in the plane of each plane the candidate changes, centred on it
            changed = [p for p in c["planes"] if p.contours != given[p.name].contours
                       or np.linalg.norm(np.subtract(p.normal, given[p.name].normal)) > 1e-9
                       or abs(np.dot(np.subtract(p.origin, given[p.name].origin), p.normal)) > 1e-9]
            self.assertTrue(changed, c["changes"])
            self.assertEqual(len(ops.PREVIEW["planes"]), len(changed))
            for (_colour, lines), p in zip(ops.PREVIEW["planes"], changed):
                self.assertEqual(np.shape(lines), (8, 3))
                self.assertLess(np.abs((np.asarray(lines) - p.origin) @ np.asarray(p.normal)).max(), 1e-6)
                np.testing.assert_allclose(np.mean(lines, axis=0), p.origin, atol=1e-6)
        log = draw(panel.VIEW3D_PT_wiresculpt_planes, bpy.context)
        pressed = [kw.get("depress") for name, a, kw in log if name == "operator" and a == ("wiresculpt.preview_planes",)]
        self.assertEqual(pressed, [k == len(candidates) - 1 for k in range(len(candidates))])
        self.assertIn("wiresculpt.preview_planes_clear", [a[0] for name, a, _kw in log if name == "operator" and a])
        # a second click on the shown candidate hides it; Clear hides it too
        self.assertEqual(bpy.ops.wiresculpt.preview_planes(index=len(candidates) - 1), {'FINISHED'})
        self.assertIsNone(ops.PREVIEW)
        self.assertEqual(bpy.ops.wiresculpt.preview_planes(index=0), {'FINISHED'})
        self.assertEqual(bpy.ops.wiresculpt.preview_planes_clear(), {'FINISHED'})
        self.assertIsNone(ops.PREVIEW)
        self.assertEqual(scene_state(), before)
        # Apply ends the preview: the candidate is the scene's own then
        self.assertEqual(bpy.ops.wiresculpt.preview_planes(index=1), {'FINISHED'})
        self.assertEqual(bpy.ops.wiresculpt.apply_planes(index=1), {'FINISHED'})
        self.assertIsNone(ops.PREVIEW)
        self.assertNotEqual(scene_state(), before)

    def test_a_preview_of_no_candidate_is_refused(self):
        self.assertFalse(ops.WIRESCULPT_OT_preview_planes.poll(bpy.context))
        with self.assertRaises(ValueError):
            ops.preview_candidate(bpy.context, 0)
        self.assertIsNone(ops.PREVIEW)

    def test_a_cancelled_search_leaves_the_scene_and_the_candidates(self):
        before = placements()
        objects = sorted(bpy.data.objects.keys())
        V, F, planes, material, settings = ops.gather(bpy.context)
        job = ops.SearchJob("nearby", V, F, planes, material, settings, 5)
        job.cancel_event.set()  # Esc before the first candidate
        job.run()
        self.assertTrue(job.cancelled)
        self.assertIsNone(job.error)
        self.assertEqual(placements(), before)
        self.assertEqual(sorted(bpy.data.objects.keys()), objects)
        self.assertIsNone(ops.RESULT)

    def test_apply_without_a_search_is_refused(self):
        """The button stays pressable (poll) and says why it does nothing."""
        before = placements()
        with self.assertRaises(ops.Refused) as ctx:
            ops.apply_candidate(bpy.context, 0)
        self.assertEqual(ctx.exception.code, ops.NO_RESULT)
        with self.assertRaises(RuntimeError) as op:  # an ERROR report, which bpy.ops raises
            bpy.ops.wiresculpt.apply_planes(index=0)
        self.assertIn("Cannot apply: " + ops.refusal(ops.NO_RESULT), str(op.exception))
        self.assertEqual(placements(), before)


class NoNearbyPlacement(Case):
    """The globe with handles at z = 0.5 R, z = -0.5 R and x = 0: the two z circles cross only the
    x = 0 circle, each at two points on one line (a hinge), and no nearby change of one or two planes
    makes them cross each other (blender_tests/pure/test_plane_faults.py says why, by hand)."""

    def setUp(self):
        super().setUp()
        start_without_results(self)
        globe_target()
        for rotation, location in (((0, 0, 0), (0, 0, 0.5 * R)), ((0, 0, 0), (0, 0, -0.5 * R)),
                                   ((0, math.pi / 2, 0), (0, 0, 0))):
            add_handle(rotation, location)
        bpy.context.view_layer.update()
        assert bpy.ops.wiresculpt.slice() == {'FINISHED'}

    def test_the_panel_says_why_no_nearby_placement_exists(self):
        before = placements()
        self.assertEqual(bpy.ops.wiresculpt.find_planes(), {'FINISHED'})
        self.assertEqual(placements(), before)
        result = ops.RESULT
        self.assertEqual(result["candidates"], [])
        self.assertTrue(result["message"].startswith("No stable placement found: no nearby placement gives a "
                                                     "stable design. Searched: planes "), result["message"])
        self.assertEqual(len(before), 3)
        a, c, b = sorted(before, key=lambda n: -before[n][0][2])  # z = 0.5 R, x = 0 (at z = 0), z = -0.5 R
        first, second = sorted((a, b))
        self.assertIn(f"(wire {first}/0 on wire {c}/0 in 1875, wire {second}/0 on wire {c}/0 in 1875)",
                      result["message"])
        self.assertIn(f"move or tilt planes {first} and {second} towards each other", result["message"])
        log = draw(panel.VIEW3D_PT_wiresculpt_planes, bpy.context)
        shown = " ".join(kw.get("text", "") for _name, _a, kw in log)
        self.assertIn("No stable placement found: no nearby placement gives a stable design.", shown)
        self.assertIn("towards each other", shown)
        self.assertFalse(any(kw.get("text", "").startswith("Apply candidate") for _name, _a, kw in log))


class SuggestPlanes(Case):
    def setUp(self):
        super().setUp()
        start_without_results(self)
        globe_target()

    def test_suggest_then_apply_adds_ordinary_planes(self):
        self.assertEqual(bpy.ops.wiresculpt.suggest_planes(count=4), {'FINISHED'})
        self.assertEqual(handles(bpy.context.scene), [])  # nothing added before Apply
        candidates = ops.RESULT["candidates"]
        self.assertTrue(candidates)
        for c in candidates:
            self.assertEqual(len(c["planes"]), 4)
            self.assertEqual(recheck.recheck(json.loads(json.dumps(c["design"]))), [])
        # each candidate shows its fidelity (by view) beside its coverage; they are ranked by fidelity
        texts = [kw.get("text", "") for _name, _a, kw in draw(panel.VIEW3D_PT_wiresculpt_planes, bpy.context)]
        for c in candidates:
            f = c["figures"]
            self.assertEqual(f["fidelity"], c["design"]["fidelity"]["share"])
            line = (f"traces {f['fidelity']:.0%} of the outline (front {f['views']['front']:.0%}, side "
                    f"{f['views']['side']:.0%}, top {f['views']['top']:.0%}), covers {f['coverage']:.0%} of the mesh")
            self.assertIn(line, " ".join(texts))  # wrapped over labels
        # ranked: those that stand in the 3D check first, each group by fidelity (the score)
        order = [(not c["figures"]["stands_3d"], -c["score"]) for c in candidates]
        self.assertEqual(order, sorted(order))
        for c in candidates:  # the panel line carries the 3D verdict beside the load capacity
            self.assertEqual(c["figures"]["stands_3d"], c["design"]["stands_3d"]["stands"])
        # the preview of a suggestion outlines every plane it would add, and adds none
        self.assertEqual(bpy.ops.wiresculpt.preview_planes(index=0), {'FINISHED'})
        self.assertEqual(handles(bpy.context.scene), [])
        self.assertEqual(len(ops.PREVIEW["planes"]), 4)
        for (_colour, lines), p in zip(ops.PREVIEW["planes"], candidates[0]["planes"]):
            np.testing.assert_allclose(np.mean(lines, axis=0), p.origin, atol=1e-6)
            self.assertLess(np.abs((np.asarray(lines) - p.origin) @ np.asarray(p.normal)).max(), 1e-6)
        self.assertEqual(len(ops.PREVIEW["wires"]), len(candidates[0]["design"]["wires"]))
        self.assertEqual(bpy.ops.wiresculpt.apply_planes(index=0), {'FINISHED'})
        self.assertIsNone(ops.PREVIEW)
        added = handles(bpy.context.scene)
        self.assertEqual(len(added), 4)
        self.assertEqual(len(wire_names()), len(candidates[0]["design"]["wires"]))
        self.assertEqual(bpy.ops.wiresculpt.optimize(), {'FINISHED'})
        self.assertTrue(json.loads(bpy.data.texts[scene_results.DESIGN_TEXT].as_string())["stable"])
