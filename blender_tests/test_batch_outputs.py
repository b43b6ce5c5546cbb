"""The batch run's scene outputs (issue 7): sculpture.blend, render.png and the assembly guide,
next to design.json, from a separate headless Blender as a user runs it."""
import json
import os
import re
import tempfile
import unittest

from helpers import BATCH, ROOT, run_blender, wiresculpt_lines

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
        """Issue 18: design.json and the guide were 0600; the .blend is verified by its end block."""
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
