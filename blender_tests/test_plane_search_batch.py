"""settings.plane_search in the headless batch: exit status, design.json's record, the
wires' planes and the saved slicing handles are the planes used. The globe (radius 1 in the file,
size 0.25: radius 0.125 m) with planes whose circles cross by hand (z = c1, x = c2 cross iff
c1^2 + c2^2 < 1): W at x = 0.8 crosses only Y, on one line (a hinge)."""
import json
import os
import sys
import tempfile
import time
import unittest

import numpy as np

from helpers import BATCH, ROOT, run_blender, wiresculpt_lines

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "pure"))
import recheck  # noqa: E402

OUTPUTS = ("design.json", "sculpture.blend", "render.png", "assembly", "svg", "dxf", "templates", "gcode", "bends",
           "bendlist")

GLOBE_OBJ = os.path.join(ROOT, "scripts", "examples", "globe", "globe.obj")
HINGE = [{"name": "Z1", "origin": [0, 0, 0.7], "normal": [0, 0, 1]},
         {"name": "Z2", "origin": [0, 0, -0.7], "normal": [0, 0, 1]},
         {"name": "X1", "origin": [-0.3, 0, 0], "normal": [1, 0, 0]},
         {"name": "Y", "origin": [0, 0, 0], "normal": [0, 1, 0]},
         {"name": "W", "origin": [0.8, 0, 0], "normal": [1, 0, 0]}]


class PlaneSearchBatch(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.out = os.path.join(self.dir.name, "out")

    def tearDown(self):
        self.dir.cleanup()

    def run_scene(self, planes, **settings):
        path = os.path.join(self.dir.name, "scene.json")
        with open(path, "w") as f:
            json.dump({"mesh": GLOBE_OBJ, "size": 0.25, "planes": planes, "settings": settings}, f)
        r = run_blender(BATCH, path, "--out", self.out)
        design = None
        if os.path.exists(os.path.join(self.out, "design.json")):
            with open(os.path.join(self.out, "design.json")) as f:
                design = json.load(f)
        return r, design

    def test_off_keeps_the_hinge_and_exits_2(self):
        r, d = self.run_scene(HINGE)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertNotIn("plane_search", d)
        self.assertIn("W/0", d["reason"])

    def test_nearby_moves_a_plane_and_exits_0(self):
        r, d = self.run_scene(HINGE, plane_search="nearby")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertTrue(d["stable"])
        self.assertEqual(recheck.recheck(d), [])
        rec = d["plane_search"]
        self.assertEqual(rec["mode"], "nearby")
        # before: the scene's planes scaled by 0.125 (size 0.25 over the globe's 2 units)
        self.assertEqual([p["origin"] for p in rec["planes_before"]],
                         [[0.125 * c for c in p["origin"]] for p in HINGE])
        moved = [a["name"] for a, b in zip(rec["planes_after"], rec["planes_before"])
                 if a["origin"] != b["origin"] or a["normal"] != b["normal"]]
        self.assertTrue(moved)
        self.assertTrue(rec["changes"])
        for key in ("candidates", "full_solves", "seconds", "score"):
            self.assertIn(key, rec)
        # the design's looks (core/fidelity.py), also in the record and the batch's line
        self.assertEqual(rec["fidelity"], d["fidelity"]["share"])
        self.assertEqual(set(d["fidelity"]["views"]), {"front", "side", "top"})
        self.assertTrue(0.0 < rec["coverage"] <= 1.0)
        self.assertTrue(any(f"traces {rec['fidelity']:.0%} of the outline" in line for line in wiresculpt_lines(r.stdout)))
        after = {p["name"]: p for p in rec["planes_after"]}
        for w in d["wires"]:
            p = after[w["name"].split("/")[0]]
            self.assertLess(abs(np.dot(np.subtract(w["plane"]["origin"], p["origin"]), p["normal"])), 1e-9)
            self.assertLess(np.linalg.norm(np.subtract(w["plane"]["normal"], p["normal"])), 1e-9)
        self.assertTrue(any(line.startswith("wiresculpt: plane_search: nearby:") for line in wiresculpt_lines(r.stdout)))

    def test_nearby_that_finds_nothing_exits_2_and_says_so(self):
        # bad_input.json's no_stable_layering: B (z = 0.999) is parallel to A and 0.1 m above it, and
        # T is the only wire both cross; no offset or small tilt of one or two planes makes A and B meet.
        planes = [{"name": "A", "origin": [0, 0, 0], "normal": [0, 0, 1]},
                  {"name": "B", "origin": [0, 0, 0.999], "normal": [0, 0, 1]},
                  {"name": "T", "origin": [0, 0, 0], "normal": [1, 0, 0]}]
        r, d = self.run_scene(planes, plane_search="nearby")
        self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
        self.assertFalse(d["stable"])
        self.assertEqual(d["plane_search"]["planes_after"], [])
        self.assertIsNone(d["plane_search"]["score"])
        # the reason is the search's (what it searched, why each family failed, what to change), then the
        # given planes'; it names wires A/0 and B/0, hinged on T/0
        self.assertTrue(d["reason"].startswith(
            "no nearby placement gives a stable design. Searched: planes A, B, T "), d["reason"])
        self.assertIn("Why: the planes as given: 1 hinge", d["reason"])
        self.assertIn("wire A/0 on wire T/0", d["reason"])
        self.assertIn("wire B/0 on wire T/0", d["reason"])
        self.assertIn("To change: ", d["reason"])
        self.assertIn(". The planes as given: ", d["reason"])

    def test_auto_with_no_planes(self):
        r, d = self.run_scene([], plane_search="auto", plane_count=4)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertEqual(recheck.recheck(d), [])
        self.assertEqual(len(d["plane_search"]["planes_after"]), 4)
        self.assertEqual(len({w["name"].split("/")[0] for w in d["wires"]}), 4)

    def test_max_solve_seconds_bounds_the_whole_search_and_nothing_is_written(self):
        # one budget for the run, the plane search and its solves included: 12 auto planes on the globe
        # take far longer than 0.5 s (screens and full solves of seconds), so the run ends at the budget
        # with one line naming the key, exit 1, and no output file
        started = time.monotonic()
        r, d = self.run_scene([], plane_search="auto", plane_count=12, max_solve_seconds=0.5)
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        errors = wiresculpt_lines(r.stderr)
        self.assertEqual(len(errors), 1, r.stderr)
        self.assertIn("the solve stopped at its time budget, settings.max_solve_seconds = 0.5 s, during the ",
                      errors[0])
        self.assertIsNone(d)
        left = os.listdir(self.out) if os.path.isdir(self.out) else []
        self.assertEqual([n for n in left if n in OUTPUTS], [])
        self.assertLess(time.monotonic() - started, 120.0)  # Blender's start and the mesh, not a 12-plane search

    def test_bad_mode_is_one_clear_error(self):
        r, _d = self.run_scene(HINGE, plane_search="everywhere")
        self.assertEqual(r.returncode, 1)
        errors = wiresculpt_lines(r.stderr)
        self.assertEqual(len(errors), 1, r.stderr)
        self.assertIn('scene key "settings.plane_search" must be one of "off", "nearby", "auto"', errors[0])


if __name__ == "__main__":
    unittest.main()
