"""Live (issue 17 part 2) in a Blender with a window under Xvfb (timers need the event loop): a
plane moved in steps turns the live verdict stable -> not stable -> stable, the latest position
wins over a running solve, no tick of the live timer blocks the UI for more than 50 ms, and
turning Live off or loading a file stops the timer."""
import os
import shutil
import unittest

from helpers import ROOT, BlenderCase, run_under_xvfb

SCRIPT = os.path.join(ROOT, "blender_tests", "ui_live.py")
TICK_LIMIT = 0.050  # issue 17: no step blocks the UI for more than 50 ms (the one time assertion)


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
        self.assertEqual(len(lines), 3, lines)
        self.assertEqual(lines[0], "Live: stable")
        self.assertTrue(lines[1].startswith("Live: not stable — "), lines)
        self.assertGreater(len(lines[1]), len("Live: not stable — ") + 3, lines)  # the reason's first words
        self.assertEqual(lines[2], "Live: stable")
        # the preview: the three wires when stable, none when the plane cuts nothing
        self.assertEqual([v["preview_wires"] for v in self.seen["verdicts"]], [3, 0, 3])

    def test_preview_is_drawn(self):
        self.assertGreater(self.seen["verdicts"][-1]["drawn"], 0)  # the overlay drew the live wires
        self.assertNotIn("Traceback", self.result.stderr[-5000:])
        self.assertEqual(self.seen["off_preview"], 0)

    def test_latest_position_wins(self):
        self.assertTrue(self.seen["first_job_cancelled"])
        self.assertAlmostEqual(self.seen["latest_z_solved"], 0.3)
        self.assertEqual(len(self.seen["latest_results"]), 1, self.seen["latest_results"])
        self.assertTrue(self.seen["latest_line"].startswith("Live: not stable"), self.seen["latest_line"])
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


class LiveRefused(BlenderCase):
    """The toggle refuses targets over live.MAX_TRIANGLES with a sentence the panel shows."""

    def test_large_mesh_is_refused(self):
        import bpy

        from wiresculpt.operators import live

        bpy.ops.mesh.primitive_grid_add(x_subdivisions=320, y_subdivisions=320)  # 320² quads: 204,800 triangles
        target = bpy.context.view_layer.objects.active
        ws = bpy.context.scene.wiresculpt
        ws.target = target
        ws.live = True
        self.assertFalse(ws.live)
        self.assertFalse(bpy.app.timers.is_registered(live.tick))
        self.assertIn("204,800 triangles", live.STATE.message)
        self.assertIn("200,000", live.STATE.message)
        bpy.ops.mesh.primitive_cube_add()
        ws.target = bpy.context.view_layer.objects.active
        ws.live = True
        self.assertTrue(ws.live)
        self.assertTrue(bpy.app.timers.is_registered(live.tick))
        ws.live = False
        self.assertFalse(bpy.app.timers.is_registered(live.tick))
