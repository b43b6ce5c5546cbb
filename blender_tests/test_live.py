"""Live in a Blender with a window under Xvfb (timers need the event loop): a
plane moved in steps turns the live verdict stable -> not stable (near the top of the mesh) ->
cannot solve (the plane left the mesh: its ticked contour is gone) -> stable, the latest position wins over a running solve, no tick of the
live timer blocks the UI for more than 50 ms, and turning Live off or loading a file stops the
timer."""
import os
import shutil
import unittest

from helpers import ROOT, BlenderCase, run_under_xvfb

SCRIPT = os.path.join(ROOT, "blender_tests", "ui_live.py")
TICK_LIMIT = 0.050  # no step blocks the UI for more than 50 ms (the one time assertion)


def stands(verdict):
    """Whether a verdict (without "Live: ") says the design stands: "stable", or "stable, over its
    limits — …" (Live solves with the layering's own hooks; on the globe those give a stable design
    that bends its wires out of their planes, core/limits.py)."""
    return verdict == "stable" or verdict.startswith("stable, over its limits — ")


@unittest.skipUnless(shutil.which("xvfb-run"), "xvfb-run is not installed")
class Live(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.result, cls.seen = run_under_xvfb(SCRIPT, "MODAL ", timeout=300)
        if cls.seen:
            d = cls.seen.get("durations") or [0]
            print(f"\nlive: verdicts {[v['line'] for v in cls.seen.get('verdicts', [])]}; "
                  f"{len(d)} ticks, longest {1000 * max(d):.1f} ms", flush=True)

    def setUp(self):
        self.assertIsNotNone(self.seen, self.result.stdout[-3000:] + self.result.stderr[-3000:])
        self.assertNotIn("error", self.seen, self.result.stdout[-3000:] + self.result.stderr[-3000:])

    def test_verdict_follows_the_plane(self):
        self.assertTrue(self.seen["timer_on"])
        lines = [v["line"] for v in self.seen["verdicts"]]
        self.assertEqual(len(lines), 4, lines)
        self.assertTrue(stands(lines[0][len("Live: "):]), lines[0])
        # 5 mm below the top of the globe: the design's own verdict, not stable, with the reason
        self.assertTrue(lines[1].startswith("Live: not stable — the target shape cannot realise crossing "), lines)
        # the plane cuts nothing: its ticked contour does not exist, a setup problem, not a verdict
        self.assertTrue(lines[2].startswith("Live: cannot solve — plane Slice A cuts no contour of the mesh now"),
                        lines)
        self.assertTrue(stands(lines[3][len("Live: "):]), lines[3])
        # the preview: the three wires of a solved design (stable or not), none when the plane cuts nothing
        self.assertEqual([v["preview_wires"] for v in self.seen["verdicts"]], [3, 3, 0, 3])

    def test_preview_is_drawn(self):
        self.assertGreater(self.seen["verdicts"][-1]["drawn"], 0)  # the overlay drew the live wires
        self.assertNotIn("Traceback", self.result.stderr[-5000:])
        self.assertEqual(self.seen["off_preview"], 0)

    def test_latest_position_wins(self):
        self.assertTrue(self.seen["first_job_cancelled"])
        self.assertAlmostEqual(self.seen["latest_z_solved"], 0.3)
        self.assertEqual(len(self.seen["latest_results"]), 1, self.seen["latest_results"])
        self.assertTrue(self.seen["latest_line"].startswith("Live: cannot solve — "), self.seen["latest_line"])
        self.assertEqual(self.seen["results"][-1], self.seen["latest_line"][len("Live: "):])

    def test_no_tick_blocks_the_ui(self):
        durations = self.seen["durations"]
        self.assertGreater(len(durations), 10)
        self.assertLessEqual(max(durations), TICK_LIMIT, f"longest tick {1000 * max(durations):.1f} ms")

    def test_live_writes_no_data(self):  # so no live update is an undo step
        self.assertTrue(self.seen["data_unchanged"])

    def test_off_and_load_stop_the_timer(self):
        self.assertFalse(self.seen["off_timer"])
        self.assertEqual(self.seen["off_line"], "")
        self.assertTrue(self.seen["before_load_timer"])
        self.assertFalse(self.seen["load_timer"])
        self.assertTrue(self.seen["load_job_cancelled"])
        self.assertEqual(self.seen["load_line"], "")


@unittest.skipUnless(shutil.which("xvfb-run"), "xvfb-run is not installed")
class LiveAcrossScenes(unittest.TestCase):
    """The window shows another scene and comes back: the timer follows each scene's toggle."""

    def test_timer_follows_the_shown_scene(self):
        result, seen = run_under_xvfb(os.path.join(ROOT, "blender_tests", "ui_live_scenes.py"), "MODAL ", timeout=180)
        self.assertIsNotNone(seen, result.stdout[-3000:] + result.stderr[-3000:])
        self.assertNotIn("error", seen, result.stderr[-3000:])
        self.assertTrue(seen["on"])
        self.assertFalse(seen["other_timer"])  # Live is off in the new scene
        self.assertEqual(seen["other_line"], "")
        self.assertTrue(seen["back_timer"])  # and on again in the first
        self.assertTrue(seen["back_line"].startswith("Live: "), seen["back_line"])


class LiveRefused(BlenderCase):
    """The toggle refuses targets over live.MAX_TRIANGLES, counted with their modifiers, with a
    sentence the panel shows while that model is picked."""

    def test_large_mesh_is_refused(self):
        import bpy

        from wiresculpt.live import engine as live

        bpy.ops.mesh.primitive_grid_add(x_subdivisions=320, y_subdivisions=320)  # 320² quads: 204,800 triangles
        model = bpy.context.view_layer.objects.active
        ws = bpy.context.scene.wiresculpt
        ws.model = model
        ws.live = True
        self.assertFalse(ws.live)
        self.assertFalse(bpy.app.timers.is_registered(live.tick))
        self.assertIn("204,800 triangles", live.refused_message(ws))
        self.assertIn("100,000", live.refused_message(ws))
        bpy.ops.mesh.primitive_cube_add()
        ws.model = bpy.context.view_layer.objects.active
        self.assertEqual(live.refused_message(ws), "")  # it spoke of the grid
        ws.live = True
        self.assertTrue(ws.live)
        self.assertTrue(bpy.app.timers.is_registered(live.tick))
        ws.live = False
        self.assertFalse(bpy.app.timers.is_registered(live.tick))

    def test_modifiers_count(self):
        import bpy

        from wiresculpt.live import engine as live

        bpy.ops.mesh.primitive_cube_add()  # 12 triangles of its own
        cube = bpy.context.view_layer.objects.active
        subsurf = cube.modifiers.new("Subdivision", 'SUBSURF')
        subsurf.levels = 7  # 6 · 4⁷ quads: 196,608 triangles
        ws = bpy.context.scene.wiresculpt
        ws.model = cube
        ws.live = True
        self.assertFalse(ws.live)
        self.assertIn("196,608 triangles", live.refused_message(ws))
        subsurf.levels = 2
        ws.live = True
        self.assertTrue(ws.live)
        ws.live = False


def drawn_live():
    """A stand-in layout after the Wire panel drew the live line on it (ui/panel.draw_live)."""
    from types import SimpleNamespace
    from unittest import mock

    from wiresculpt.ui import panel

    layout = mock.MagicMock()
    panel.draw_live(layout, SimpleNamespace(region=None))
    return layout


class LiveFollowsTheScene(BlenderCase):
    """What Live sees besides moved planes (a maker's trial under Xvfb): the panel's
    settings, the target's geometry and presence, the toggle set without its update (undo, a scene
    switch), and errors. The timer's steps are run by hand (no timers run in the background)."""

    def setUp(self):
        super().setUp()
        from helpers import globe

        self.model = globe()
        self.ws = self.scene().wiresculpt

    def tearDown(self):
        self.ws.live = False

    @staticmethod
    def scene():
        import bpy

        return bpy.context.scene

    def assertStands(self, verdict):
        self.assertTrue(stands(verdict), verdict)

    def settle(self, timeout=60.0):
        """Runs the timer's steps until the verdict of the scene as it is now is shown."""
        import time

        from wiresculpt.live import engine as live

        began = time.monotonic()
        while True:
            self.assertIsNotNone(live.tick(), "the live timer ended")
            now = live.observed()
            if now.job is None and now.solved == live.snapshot(self.scene()):
                return live.observed().verdict
            if time.monotonic() - began > timeout:
                self.fail(f"no verdict within {timeout} s: {live.observed().verdict!r}")
            time.sleep(0.02)

    def extent(self):
        """The largest distance of the live preview's points from the target's centre (m)."""
        import numpy as np

        from wiresculpt.live import engine as live

        return max(float(np.max(np.linalg.norm(lines - np.asarray(self.model.location), axis=1)))
                   for _colour, lines in live.observed().preview)

    def test_settings_are_part_of_the_verdict(self):
        import math

        import bpy

        from wiresculpt.live import engine as live

        self.ws.live = True
        self.assertStands(self.settle())
        max_bend, min_bend = self.ws.max_bend_deg, self.ws.min_bend_deg
        self.addCleanup(setattr, self.ws, "min_bend_deg", min_bend)  # also when an assertion fails: the scene's
        self.addCleanup(setattr, self.ws, "max_bend_deg", max_bend)  # settings outlive the test
        # A limit the globe's kinks cannot meet: solved again without a plane moving.
        self.ws.max_bend_deg = math.radians(30.0)
        verdict = self.settle()
        self.assertTrue(verdict.startswith("not stable — "), verdict)
        # Settings the solver refuses: a setup problem that says why (no verdict on the design), and Live goes on.
        self.ws.min_bend_deg = math.radians(40.0)
        verdict = self.settle()
        self.assertEqual(verdict, "cannot solve — the smallest bend must be smaller than the largest bend "
                                  "(Machine settings)")
        self.assertEqual(live.observed().preview, [])
        self.assertTrue(bpy.app.timers.is_registered(live.tick))
        self.ws.max_bend_deg, self.ws.min_bend_deg = max_bend, min_bend
        self.assertStands(self.settle())

    def test_edits_and_modifiers_of_the_model_are_seen(self):
        import bpy
        from mathutils import Matrix

        from wiresculpt.live import engine as live

        self.ws.live = True
        self.assertStands(self.settle())
        before, seen = self.extent(), live.observed().geometry
        self.assertAlmostEqual(before, 0.125, delta=0.01)  # the wires lie on the globe
        self.model.data.transform(Matrix.Scale(0.6, 4))  # an edit of the mesh, its matrix unchanged
        self.model.data.update()
        bpy.context.view_layer.update()
        self.assertGreater(live.observed().geometry, seen)
        self.settle()
        self.assertAlmostEqual(self.extent(), 0.6 * 0.125, delta=0.01)
        seen = live.observed().geometry
        self.model.modifiers.new("Subdivision", 'SUBSURF')
        bpy.context.view_layer.update()
        self.assertGreater(live.observed().geometry, seen)
        seen = live.observed().geometry
        self.settle()
        self.assertEqual(live.observed().geometry, seen)  # reading the mesh is no edit: no endless re-solving

    def test_a_model_taken_out_of_the_scene(self):
        from wiresculpt.live import engine as live

        self.ws.live = True
        self.assertStands(self.settle())
        for collection in self.model.users_collection:
            collection.objects.unlink(self.model)
        verdict = self.settle()
        self.assertTrue(verdict.startswith(f"cannot solve — Model '{self.model.name}' is not in scene"), verdict)
        self.assertEqual(live.observed().preview, [])

    def test_setup_problems_cannot_solve(self):
        """A scene that cannot be solved as set up says so, and never reads as a verdict on the design."""
        from unittest import mock

        import bpy

        from wiresculpt import native
        from wiresculpt.core import live_verdict
        from wiresculpt.live import engine as live
        from wiresculpt.ui import panel

        self.ws.live = True
        self.assertStands(self.settle())
        for item in self.ws.contours:
            item.use = False
        self.assertEqual(self.settle(), "cannot solve — No contour is ticked: Slice, then tick the contours that "
                                        "become wires")
        self.assertEqual(live.line(), "Live: cannot solve — No contour is ticked: Slice, then tick the contours "
                                      "that become wires")
        self.assertEqual(live.observed().preview, [])
        self.assertEqual(live.whole_reason(), "")  # shown whole: no button for it
        layout = drawn_live()
        layout.operator.assert_not_called()
        self.assertIs(layout.column.return_value.alert, False)
        labels = layout.column.return_value.label.call_args_list
        self.assertEqual(labels[0].kwargs["icon"], 'INFO')
        self.assertEqual(" ".join(c.kwargs["text"] for c in labels), live.line())
        # drawn unlike a verdict: neither the stable tick nor the not-stable warning, not red
        self.assertEqual(live.observed().kind, live_verdict.CANNOT_SOLVE)
        self.assertEqual(panel.live_look(live.observed().kind), ('INFO', False))
        self.assertNotIn(panel.live_look(live.observed().kind)[0],
                         (panel.live_look(live_verdict.STABLE)[0], panel.live_look(live_verdict.NOT_STABLE)[0]))
        for item in self.ws.contours:
            item.use = True
        self.assertStands(self.settle())
        with mock.patch.object(native, "available", return_value=False):
            self.model.location.x += 0.001
            bpy.context.view_layer.update()
            self.assertEqual(self.settle(),
                             "cannot solve — the solver is not loaded (the panel's first box says why)")
        model, self.ws.model = self.ws.model, None
        self.assertEqual(self.settle(), "cannot solve — No model mesh: pick one in the Wire panel (Model)")
        self.ws.model = model
        self.assertStands(self.settle())

    def test_one_wire_cannot_solve(self):
        """One contour ticked: the solve ends with the pipeline's "at least two wires", a setup problem
        drawn as the others (info icon, not red), not "not stable"."""
        from wiresculpt.live import engine as live
        from wiresculpt.ui import panel

        self.ws.live = True
        self.assertStands(self.settle())
        for item in list(self.ws.contours)[1:]:
            item.use = False
        self.assertEqual(self.settle(), "cannot solve — a sculpture needs at least two wires: add a plane or pick "
                                        "more contours")
        self.assertEqual(panel.live_look(live.observed().kind), ('INFO', False))
        for item in self.ws.contours:
            item.use = True
        self.assertStands(self.settle())

    def test_a_plane_moved_off_the_mesh_cannot_solve(self):
        """Its ticked contour is gone (the solve's ValueError): what the window test's second step sees."""
        import bpy

        from wiresculpt.live import engine as live

        self.ws.live = True
        self.assertStands(self.settle())
        plane = self.scene().objects["Slice A"]
        plane.location.z = 0.3
        bpy.context.view_layer.update()
        self.assertEqual(self.settle(), "cannot solve — plane Slice A cuts no contour of the mesh now (contour index 0 "
                                        "does not exist)")
        self.assertEqual(live.observed().preview, [])
        plane.location.z = 0.0
        bpy.context.view_layer.update()
        self.assertStands(self.settle())

    def test_errors_of_a_solve(self):
        """The solver refusing the input is a setup problem; any other exception is our error, said as such."""
        from unittest import mock

        import bpy

        from wiresculpt.live import engine as live
        from wiresculpt.ui import panel

        self.ws.live = True
        self.assertStands(self.settle())
        refused = ValueError("three wires pass through one point: move one of the planes slightly")
        with mock.patch.object(live.pipeline, "solve", side_effect=refused):
            self.model.location.x += 0.001
            bpy.context.view_layer.update()
            self.assertEqual(self.settle(), "cannot solve — three wires pass through one point: move one of the "
                                            "planes slightly")
        with mock.patch.object(live.pipeline, "solve", side_effect=KeyError("hook")):
            self.model.location.x += 0.001
            bpy.context.view_layer.update()
            verdict = self.settle()
        self.assertEqual(verdict, "error — internal error (KeyError: 'hook'); please report it")
        self.assertEqual(panel.live_look(live.observed().kind), ('CANCEL', True))
        self.assertEqual(live.observed().preview, [])
        self.model.location.x -= 0.002
        bpy.context.view_layer.update()
        self.assertStands(self.settle())

    def test_a_long_reason_shows_its_first_clause(self):
        """The globe with Max Bend 30°: the reason repeats "crossing k on wire …" for every crossing; the
        line shows the first clause up to its deciding figure (30 words ended before it), the button's
        tooltip the whole reason."""
        import math

        import bpy

        from wiresculpt.live import engine as live
        from wiresculpt.operators.live import WIRESCULPT_OT_live_reason
        from wiresculpt.ui import panel

        self.ws.live = True
        self.assertStands(self.settle())
        self.addCleanup(setattr, self.ws, "max_bend_deg", self.ws.max_bend_deg)  # the scene's settings stay
        self.ws.max_bend_deg = math.radians(30.0)
        verdict = self.settle()
        reason = live.observed().reason
        first = reason[:reason.index(";")]
        # each crossing named once ("crossing 0 on wire Slice A/0: it needs …", not "…: crossing 0 on wire
        # Slice A/0 needs …")
        self.assertRegex(first, r"^the target shape cannot realise crossing \d+ on wire Slice [A-C]/0: it needs a bend")
        self.assertEqual(first.count(" on wire "), 1, first)
        self.assertGreater(len(first.split()), 30)
        # its deciding figures, and what to change: 180° - 30° (no friction here) = 150°
        self.assertTrue(first.endswith("(180° less the contact angle 120°) but the machine bends at most 30°: "
                                       "a contact angle of at least 150° fits"), first)
        self.assertEqual(verdict, "not stable — " + first + "…")
        self.assertEqual(panel.live_look(live.observed().kind), ('ERROR', False))
        self.assertEqual(live.whole_reason(), reason)
        self.assertEqual(WIRESCULPT_OT_live_reason.description(bpy.context, None), reason)
        self.assertEqual(bpy.ops.wiresculpt.live_reason(), {'FINISHED'})
        layout = drawn_live()
        layout.operator.assert_called_once_with(WIRESCULPT_OT_live_reason.bl_idname, icon='COPYDOWN')

    def test_the_toggle_set_without_its_update(self):
        import bpy

        from wiresculpt.live import engine as live

        self.ws["live"] = 1  # as undo or a scene switch sets it: no update called
        self.assertFalse(bpy.app.timers.is_registered(live.tick))
        live._sync_shown()
        self.assertTrue(bpy.app.timers.is_registered(live.tick))
        self.assertStands(self.settle())
        self.ws["live"] = 0
        self.scene().update_tag()
        bpy.context.view_layer.update()  # a depsgraph update: the registered handler stops the timer
        self.assertFalse(bpy.app.timers.is_registered(live.tick))
        self.assertEqual(live.line(), "")

    def test_an_unexpected_error_is_shown_and_live_goes_on(self):
        import time
        from unittest import mock

        import bpy

        from wiresculpt.live import engine as live

        self.ws.live = True
        failure = RuntimeError("the solver's thread could not start")
        with mock.patch.object(live, "_start", side_effect=failure) as start:
            began = time.monotonic()
            while not start.called and time.monotonic() - began < 10.0:
                returned = live.tick()  # a timer that raises is unregistered for good
                time.sleep(0.02)
            self.assertTrue(start.called)
            self.assertEqual(returned, live.TICK_SECONDS)
            time.sleep(0.1)
            self.assertEqual(live.tick(), live.TICK_SECONDS)
            self.assertEqual(start.call_count, 1)  # tried again only once something changes
        self.assertEqual(live.line(), "Live: error — RuntimeError: the solver's thread could not start")
        self.model.location.x += 0.001
        bpy.context.view_layer.update()  # matrix_world follows (a window's event loop does it)
        self.assertStands(self.settle())

    def test_a_mesh_read_over_the_limit_turns_live_off(self):
        import time
        from unittest import mock

        import bpy

        from wiresculpt.live import engine as live

        # As with GPU subdivision, the evaluated mesh the refusal counts is the cage (2,208
        # triangles); the triangles read for slicing are the subdivided ones, over 100,000.
        self.model.modifiers.new("Subdivision", 'SUBSURF').levels = 3
        bpy.context.view_layer.update()
        with mock.patch.object(live, "triangle_count", return_value=2208):
            self.ws.live = True
            self.assertTrue(self.ws.live)
            for _ in range(500):
                returned = live.tick()
                if returned is None:
                    break
                time.sleep(0.01)
        self.assertIsNone(returned)  # the timer that ran this tick ends
        self.assertFalse(self.ws.live)
        import re

        found = re.match(r"Live is off: globe has ([0-9,]+) triangles", live.refused_message(self.ws))
        self.assertIsNotNone(found, live.refused_message(self.ws))
        self.assertGreater(int(found.group(1).replace(",", "")), live.MAX_TRIANGLES)
        self.assertEqual(live.line(), "")
