"""The batch run's scene outputs: sculpture.blend, render.png and the assembly guide,
next to design.json, from a separate headless Blender as a user runs it."""
import json
import os
import re
import subprocess
import tempfile
import unittest

import numpy as np

from helpers import BATCH, ROOT, run_blender, run_under_xvfb, wiresculpt_lines
from wiresculpt.core import blendfile

GLOBE = os.path.join(ROOT, "scripts", "examples", "globe", "scene.json")
PNG = b"\x89PNG\r\n\x1a\n"

# Opens the written .blend in another Blender and prints what it holds, as JSON on one line.
CHECK_BLEND = r'''
import json, sys
sys.path.insert(0, sys.argv[sys.argv.index("--") + 2])
import bpy, wiresculpt
wiresculpt.register()
bpy.ops.wm.open_mainfile(filepath=sys.argv[sys.argv.index("--") + 1])
from wiresculpt.blend import results as scene_results
design = scene_results.stored_design()
wires = [o for o in bpy.context.scene.objects if scene_results.WIRE_KEY in o]
print("CHECK " + json.dumps({
    "stable": design["stable"], "wires": sorted(o[scene_results.WIRE_KEY] for o in wires),
    "bevel": [o.data.bevel_depth for o in wires],
    "ticked": sorted(f"{i.plane}/{i.index}" for i in bpy.context.scene.wiresculpt.contours if i.use),
    "optimize": sorted(bpy.ops.wiresculpt.optimize()),
    "after": len([o for o in bpy.context.scene.objects if scene_results.WIRE_KEY in o])}))
'''


class BatchOutputs(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        cls.out = os.path.join(cls.dir.name, "out")
        cls.result = run_blender(BATCH, GLOBE, "--out", cls.out)

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def test_exit_status_and_progress_lines(self):
        r = self.result
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        stages = [line.split(":")[1].strip() for line in wiresculpt_lines(r.stdout)]
        for stage in ("slicing", "layering", "target_shape", "written", "scene", "render", "guide", "blend"):
            self.assertIn(stage, stages)

    def test_outputs_are_0644_and_the_blend_is_complete(self):
        """design.json and the guide are 0644, not 0600; the .blend is verified by its end block."""
        import stat
        for root, dirs, files in os.walk(self.out):
            for name in files:
                path = os.path.join(root, name)
                self.assertEqual(stat.S_IMODE(os.stat(path).st_mode), 0o644, path)
        with open(os.path.join(self.out, "sculpture.blend"), "rb") as f:
            data = f.read()
        self.assertTrue(data.startswith(b"BLENDER"))
        self.assertIn(b"ENDB", data[-32:])

    def test_render_and_guide(self):
        with open(os.path.join(self.out, "render.png"), "rb") as f:
            self.assertEqual(f.read(8), PNG)
        with open(os.path.join(self.out, "design.json")) as f:
            design = json.load(f)
        folder = os.path.join(self.out, "assembly")
        with open(os.path.join(folder, "index.html"), encoding="utf-8") as f:
            page = f.read()
        steps = design["assembly_steps"]
        self.assertEqual(len(re.findall(r'<div class="step">', page)), len(steps))
        for k in range(len(steps)):
            with open(os.path.join(folder, f"step_{k + 1:02d}.png"), "rb") as f:
                self.assertEqual(f.read(8), PNG)
        for wire in design["wires"]:
            self.assertIn(wire["name"], page)
        # every crossing is described once, at the step that closes it
        self.assertEqual(len(re.findall(r"<li>At crossing \d+", page)), len(design["crossings"]))
        self.assertFalse([n for d in (self.out, folder) for n in os.listdir(d) if n.startswith(".")])

    def test_blend_holds_the_design_and_optimizes_again(self):
        path = os.path.join(self.out, "sculpture.blend")
        self.assertTrue(os.path.isfile(path))
        script = os.path.join(self.dir.name, "check_blend.py")
        with open(script, "w") as f:
            f.write(CHECK_BLEND)
        r = run_blender(script, path, os.path.join(ROOT, "addon"))
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        [line] = [l for l in r.stdout.splitlines() if l.startswith("CHECK ")]
        found = json.loads(line[len("CHECK "):])
        names = ["Equator/0", "Meridian0/0", "Meridian90/0"]
        self.assertTrue(found["stable"])
        self.assertEqual(found["wires"], names)
        self.assertEqual(found["ticked"], names)
        for bevel in found["bevel"]:
            self.assertAlmostEqual(bevel, 0.0015, places=7)
        self.assertEqual(found["optimize"], ["FINISHED"])
        self.assertEqual(found["after"], 3)

    def test_blend_opens_framed_on_the_wire_tab_with_the_first_wire_selected(self):
        """Opened in a Blender with a window (the add-on enabled) and drawn: the 3D view looks at
        the sculpture's centre from within 3 model sizes, its sidebar is open, the first wire is
        selected and active, and the sidebar shows the Wire tab (Blender 3.4 has no Python for the
        tab: drawing replaces a tab that is not there by the first one there is, and the copy
        Blender saves after drawing holds the region's tab stack)."""
        with open(os.path.join(self.out, "design.json")) as f:
            design = json.load(f)
        points = np.concatenate([np.asarray(w["target"]) for w in design["wires"]])
        lo, hi = points.min(axis=0), points.max(axis=0)
        size, centre = float((hi - lo).max()), (lo + hi) / 2  # from the design, not from Blender
        self.assertGreater(size, 0.05)
        path = os.path.join(self.out, "sculpture.blend")
        # every 3D view of every screen in the file remembers the Wire tab
        saved = blendfile.read(path)
        sidebars = saved.view3d_sidebars()
        self.assertGreater(len(sidebars), 1)
        for screen, region in sidebars:
            self.assertEqual(saved.sidebar_tabs(region)[:1], ["Wire"], screen)
        copy = os.path.join(self.dir.name, "drawn.blend")
        r, seen = run_under_xvfb(os.path.join(ROOT, "blender_tests", "ui_open_blend.py"), "MODAL ",
                                 args=(path, copy))
        self.assertIsNotNone(seen, r.stdout + r.stderr)
        self.assertNotIn("error", seen)
        self.assertEqual(len(seen["views"]), 1, seen)
        view = seen["views"][0]
        self.assertTrue(view["sidebar"])
        self.assertLessEqual(view["distance"], 3 * size)
        self.assertGreaterEqual(view["distance"], 0.5 * size)  # not inside the sculpture either
        self.assertLess(float(np.linalg.norm(np.asarray(view["centre"]) - centre)), 0.1 * size)
        first = "Wire " + design["wires"][0]["name"]
        self.assertEqual(seen["active"], first)
        self.assertEqual(seen["selected"], [first])
        drawn = blendfile.read(copy)
        tabs = [drawn.sidebar_tabs(region) for screen, region in drawn.view3d_sidebars() if screen == seen["screen"]]
        self.assertEqual(tabs, [["Wire"]])

    def test_demo_closing_lines_list_every_output(self):
        """The demo's closing lines (scripts/lib.sh summarize_outputs) on this run's folder: one
        line per file and folder the run wrote, each folder with its slash and what it holds."""
        r = subprocess.run(["bash", "-c", 'source "$1/scripts/lib.sh"; summarize_outputs "$2" 0', "bash", ROOT,
                            self.out], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        lines = r.stderr.splitlines()
        entries = sorted(os.listdir(self.out))
        for folder in ("svg", "dxf", "templates", "gcode", "bends", "bendlist", "assembly"):
            self.assertIn(folder, entries)
        for name in entries:
            label = name + "/" if os.path.isdir(os.path.join(self.out, name)) else name
            [line] = [l for l in lines if l.split()[1:2] == [label]]
            self.assertGreater(len(line.split()), 3, f"{label} is listed without saying what it holds")
