"""What the assembly slider (Show After Step) hides, overlays included, and Suggest Planes' count
set in the panel, in the background (the Live timer's steps run by hand):
    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- assembly_view
The wires each step adds are the design's own assembly_steps; what is shown is checked against them."""
import os
import tempfile
import time
import unittest
from unittest import mock

import bpy

from helpers import BlenderCase, draw, globe
from wiresculpt import native
from wiresculpt.blend import preview
from wiresculpt.blend import results as scene_results


def ghosts(scene):
    return {o[preview.PREVIEW_KEY]: o for o in scene.objects if preview.PREVIEW_KEY in o}


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class SliderHidesLaterSteps(BlenderCase):
    def setUp(self):
        super().setUp()
        globe()
        self.scene = bpy.context.scene
        self.ws = self.scene.wiresculpt
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)

    def tearDown(self):
        self.ws.live = False
        self.ws.assembly_step = 0

    def export(self):
        folder = os.path.join(self.tmp.name, f"out{time.monotonic_ns()}")
        self.assertEqual(bpy.ops.wiresculpt.export_fabrication(directory=folder), {'FINISHED'})

    def test_the_machine_previews_ghosts_follow_the_slider(self):
        self.assertEqual(bpy.ops.wiresculpt.optimize(), {'FINISHED'})
        design = scene_results.stored_design()
        steps = design["assembly_steps"]
        name = {w["id"]: w["name"] for w in design["wires"]}
        self.assertGreaterEqual(len(steps), 2)
        self.export()
        self.assertEqual(sorted(ghosts(self.scene)), sorted(name.values()))
        for k in range(1, len(steps) + 1):
            self.ws.assembly_step = k
            present = {name[w] for s in steps[:k] for w in s}
            for wire_name, obj in ghosts(self.scene).items():
                self.assertEqual(obj.hide_viewport, wire_name not in present, (k, wire_name))
        # an export while a step is shown: the new ghosts of later wires are hidden at once
        self.ws.assembly_step = 1
        self.export()
        first = {name[w] for w in steps[0]}
        self.assertEqual({n for n, o in ghosts(self.scene).items() if not o.hide_viewport}, first)
        self.ws.assembly_step = 0
        self.assertFalse(any(o.hide_viewport for o in ghosts(self.scene).values()))

    def test_the_live_overlay_draws_only_the_wires_added(self):
        from wiresculpt.live import engine as live
        from wiresculpt.ui import overlay

        self.ws.live = True
        began = time.monotonic()
        while not (live.observed().job is None and live.observed().solved == live.snapshot(self.scene)):
            self.assertIsNotNone(live.tick(), "the live timer ended")
            self.assertLess(time.monotonic() - began, 120, "no live verdict")
            time.sleep(0.02)
        steps = live.observed().preview_steps
        self.assertGreaterEqual(len(steps), 2, live.observed().verdict)
        everything = overlay.live_lines(self.scene)
        self.assertEqual(len(everything), 3)  # the globe's three wires, step 0
        for k in range(1, len(steps) + 1):
            self.ws.assembly_step = k
            present = [w for s in steps[:k] for w in s]
            drawn = overlay.live_lines(self.scene)
            # each wire drawn in its own colour: the colours drawn are those of the wires added
            self.assertEqual(sorted(tuple(c) for c, _l in drawn),
                             sorted(tuple(scene_results.wire_colour(w)) for w in present), k)
        self.ws.assembly_step = 1
        self.assertEqual(len(overlay.live_lines(self.scene)), len(steps[0]))
        self.assertLess(len(steps[0]), 3)


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class PlaneCountInThePanel(BlenderCase):
    def setUp(self):
        super().setUp()
        globe()
        from wiresculpt.operators import plane_search as ops

        ops.RESULT, ops.PREVIEW = None, None

    def test_the_panel_shows_the_count_and_the_search_gets_it(self):
        from wiresculpt import plane_search
        from wiresculpt.ui import plane_search as panel

        ws = bpy.context.scene.wiresculpt
        shown = draw(panel.VIEW3D_PT_wiresculpt_planes, bpy.context)
        self.assertIn(("prop", (ws, "plane_count")), [(m, a[:2]) for m, a, _k in shown if m == "prop"])
        ws.plane_count = 3
        asked = []

        def auto(mesh, count, material, settings, *args, **kwargs):
            asked.append((count, settings.get("plane_count")))
            return [], type("Searched", (), {"screened": 0, "full_solves": 0})(), 0.0
        with mock.patch.object(plane_search, "auto", auto):
            self.assertEqual(bpy.ops.wiresculpt.suggest_planes(), {'FINISHED'})
            self.assertEqual(bpy.ops.wiresculpt.suggest_planes(count=7), {'FINISHED'})  # the operator's own
        self.assertEqual(asked, [(3, 3), (7, 7)])


if __name__ == "__main__":
    unittest.main()
