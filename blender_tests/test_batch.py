"""The headless batch run (docs/formats.md) as a user runs it: a separate Blender process per run."""
import json
import math
import os
import tempfile
import unittest

from helpers import (BATCH, ROOT, box_faces, box_vertices, polyline_length, run_blender,
                     wiresculpt_lines, write_obj, write_ply, write_stl)

GLOBE = os.path.join(ROOT, "scripts", "examples", "globe", "scene.json")
# A box placed off-centre with unequal sides, so any axis swap or recentring shows.
LO, HI = (0.1, -0.2, 0.02), (0.3, 0.05, 0.5)
CORNERS = [(x, y, 0.2) for x in (0.1, 0.3) for y in (-0.2, 0.05)]


class BatchTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.out = os.path.join(self.dir.name, "out")

    def tearDown(self):
        self.dir.cleanup()

    def scene(self, **data):
        path = os.path.join(self.dir.name, "scene.json")
        with open(path, "w") as f:
            f.write(data.pop("_text", None) or json.dumps(data))
        return path

    def batch(self, scene):
        return run_blender(BATCH, scene, "--out", self.out)

    def design(self):
        with open(os.path.join(self.out, "design.json")) as f:
            return json.load(f)

    def assertFailsWith(self, fragment, scene):
        r = self.batch(scene)
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        errors = wiresculpt_lines(r.stderr)
        self.assertEqual(len(errors), 1, r.stderr)
        self.assertTrue(errors[0].startswith("wiresculpt: error: "), errors[0])
        self.assertIn(fragment, errors[0])
        self.assertFalse(os.path.exists(self.out), "a failed run must leave no output behind")

    def box_scene(self, writer, ext, **extra):
        mesh = os.path.join(self.dir.name, "box" + ext)
        writer(mesh, box_vertices(LO, HI), box_faces())
        return self.scene(mesh="box" + ext, planes=[{"name": "Z", "origin": [0, 0, 0.2], "normal": [0, 0, 3]}],
                          **extra)

    def test_globe_example(self):
        r = self.batch(GLOBE)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        stages = [line.split(":")[1].strip() for line in wiresculpt_lines(r.stdout)]
        self.assertIn("slicing", stages)
        self.assertIn("layering", stages)
        d = self.design()
        self.assertEqual((d["format"], d["version"], d["units"]), ("wiresculpt-design", 1, "m"))
        self.assertEqual(len(d["wires"]), 3)
        for w in d["wires"]:
            self.assertTrue(w["closed"])
            # size 0.25 m: a great circle of radius 0.125 m sampled by 48 points, plus the
            # crossing points inserted on its chords (which leave the length unchanged)
            expected = 2 * 0.125 * 48 * math.sin(math.pi / 48)
            self.assertAlmostEqual(polyline_length(w["contour"], True), expected, delta=1e-6)
            n, o = w["plane"]["normal"], w["plane"]["origin"]
            for p in w["contour"]:
                self.assertLess(abs(sum(n[k] * (p[k] - o[k]) for k in range(3))), 1e-9)
            self.assertNotEqual(w["contour"][0], w["contour"][-1])
        # Three great circles meet pairwise at two antipodal points: six crossings, each on the
        # common line of its two planes at distance 0.125 from the centre.
        self.assertEqual(len(d["crossings"]), 6)
        for c in d["crossings"]:
            self.assertIn(c["hook"], (-1, 1))
            self.assertAlmostEqual(math.dist(c["point"], (0, 0, 0)), 0.125, delta=1e-9)
            for k in (0, 1):
                wire = d["wires"][c["wires"][k]]
                self.assertEqual(wire["contour"][c["contour_vertices"][k]], c["point"])
        self.assertEqual(sorted(d["assembly_order"]), [0, 1, 2])
        self.assertTrue(d["stable"])
        self.assertEqual(d["reason"], "")
        for key in ("seconds", "lp_solves", "nodes"):
            self.assertIn(key, d["stages"]["layering"])
        self.assertGreater(d["stages"]["layering"]["lp_solves"], 0)
        self.assertEqual(d["pending_stages"], [])
        for w in d["wires"]:
            self.assertIn("rest", w)
            self.assertIn("cut", w)
        for c in d["crossings"]:
            self.assertEqual(len(c["force"]), 3)
        self.check_targets(d)
        for folder, ext in (("svg", ".svg"), ("dxf", ".dxf"), ("gcode", ".gcode"), ("bends", ".csv"),
                            ("bendlist", ".txt")):
            names = os.listdir(os.path.join(self.out, folder))
            self.assertTrue(names and all(n.endswith(ext) for n in names), (folder, names))
        self.assertEqual(len(d["fabrication"]["wires"]), 3)
        self.assertEqual(d["fabrication"]["errors"], [])
        for w in d["fabrication"]["wires"]:  # the default profile compensates and predicts: only the
            # small-bend rule moves the predicted wire off the rest shape
            self.assertAlmostEqual(w["preview_distance"], w["shape_error"], delta=1e-9)
            self.assertNotIn("predicted", w)

    def check_targets(self, d):
        """The target shapes against docs/formats.md and the machine, computed from the points alone."""
        l_min, max_bend = d["machine"]["min_segment"], math.radians(d["machine"]["max_bend_deg"])
        for w in d["wires"]:
            t, n, o = w["target"], w["plane"]["normal"], w["plane"]["origin"]
            for p in t:
                self.assertLess(abs(sum(n[k] * (p[k] - o[k]) for k in range(3))), 1e-9)
            m = len(t)
            for i in range(m):
                a, b, c = t[i - 1], t[i], t[(i + 1) % m]
                self.assertGreaterEqual(math.dist(b, c), l_min - 1e-6, f"short segment on {w['name']}")
                e0 = [b[k] - a[k] for k in range(3)]
                e1 = [c[k] - b[k] for k in range(3)]
                cos = sum(e0[k] * e1[k] for k in range(3)) / (math.hypot(*e0) * math.hypot(*e1))
                self.assertLessEqual(math.acos(max(-1.0, min(1.0, cos))), max_bend + 1e-6)
            self.assertAlmostEqual(w["length"], polyline_length(t, True), delta=1e-9)
            self.assertLess(w["target_max_distance"], 0.02)
        for c in d["crossings"]:
            w0, w1 = (d["wires"][k] for k in c["wires"])
            n0, n1 = w0["plane"]["normal"], w1["plane"]["normal"]
            dvec = [n0[1] * n1[2] - n0[2] * n1[1], n0[2] * n1[0] - n0[0] * n1[2], n0[0] * n1[1] - n0[1] * n1[0]]
            for k, wire in enumerate((w0, w1)):
                t = wire["target"]
                r = c["vertices"][k]
                self.assertLess(math.dist(t[r], c["point"]), 1e-9)
                prev, here, nxt = t[r - 1], t[r], t[(r + 1) % len(t)]
                def unit(a, b):
                    e = [b[i] - a[i] for i in range(3)]
                    return [x / math.hypot(*e) for x in e]
                h = [x - y for x, y in zip(unit(here, nxt), unit(prev, here))]  # Sec. 4.1 bisector
                side = sum(h[i] * dvec[i] for i in range(3))
                expected = c["hook"] if k == 0 else -c["hook"]
                if expected:
                    self.assertGreater(side * expected, 0, f"crossing {c['id']}: wire {wire['name']} opens the wrong way")

    def check_box(self, scene, scale=1.0):
        r = self.batch(scene)
        self.assertIn(r.returncode, (0, 2), r.stdout + r.stderr)
        wires = self.design()["wires"]
        self.assertEqual(len(wires), 1)
        contour = wires[0]["contour"]
        for corner in CORNERS:
            nearest = min(math.dist(p, [scale * c for c in corner]) for p in contour)
            self.assertLess(nearest, 1e-6 * scale, f"corner {corner} missing from {contour}")
        self.assertAlmostEqual(polyline_length(contour, True), scale * 0.9, delta=1e-6 * scale)
        self.assertEqual(wires[0]["plane"]["normal"], [0.0, 0.0, 1.0])

    def test_obj_coordinates_are_used_as_written(self):
        self.check_box(self.box_scene(write_obj, ".obj"))

    def test_stl_coordinates_are_used_as_written(self):
        self.check_box(self.box_scene(write_stl, ".stl"))

    def test_ply_coordinates_are_used_as_written(self):
        self.check_box(self.box_scene(write_ply, ".ply"))

    def test_size_scales_mesh_and_plane_origins(self):
        # The largest side is z (0.48); size 1.2 scales everything by 2.5 about the origin.
        self.check_box(self.box_scene(write_obj, ".obj", size=1.2), scale=2.5)

    def test_plane_that_misses_gives_no_wire(self):
        write_obj(os.path.join(self.dir.name, "box.obj"), box_vertices(LO, HI), box_faces())
        r = self.batch(self.scene(mesh="box.obj", planes=[{"origin": [0, 0, 3], "normal": [0, 0, 1]}]))
        self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
        d = self.design()
        self.assertEqual(d["wires"], [])
        self.assertFalse(d["stable"])
        self.assertIn("no plane cuts the mesh", d["reason"])

    def test_bad_input(self):
        write_obj(os.path.join(self.dir.name, "box.obj"), box_vertices(LO, HI), box_faces())
        plane = {"origin": [0, 0, 0.2], "normal": [0, 0, 1]}
        cases = [
            ('unknown scene key "colour"', dict(mesh="box.obj", planes=[plane], colour="red")),
            ("file not found", dict(mesh="nothere.obj", planes=[plane])),
            ('"planes[0].normal" (plane A) is zero', dict(mesh="box.obj", planes=[{"origin": [0, 0, 0], "normal": [0, 0, 0]}])),
            ('"planes[0].origin[1]" must be a finite number', dict(_text='{"mesh": "box.obj", "planes": [{"origin": [0, NaN, 0], "normal": [0, 0, 1]}]}')),
            ("line 1: not valid JSON", dict(_text='{"mesh": "box.obj", "planes": [}')),
            ('unknown scene key "speed" in settings', dict(mesh="box.obj", planes=[plane], settings={"speed": 2})),
        ]
        for fragment, data in cases:
            with self.subTest(fragment):
                self.assertFailsWith(fragment, self.scene(**data))

    def test_bad_mesh_files(self):
        for name, text, fragment in [("mesh.xyz", "1 2 3\n", "unsupported format .xyz"),
                                     ("empty.obj", "# nothing\n", "holds no mesh")]:
            with self.subTest(name):
                with open(os.path.join(self.dir.name, name), "w") as f:
                    f.write(text)
                self.assertFailsWith(fragment, self.scene(mesh=name, planes=[{"origin": [0, 0, 0], "normal": [0, 0, 1]}]))

    def test_machine_profile_from_the_scene_or_the_command_line(self):
        """A saved machine profile reaches the fabrication files: the scene's "machine_profile"
        (relative to the scene file), overridden by --profile; a missing one is refused first."""
        with open(GLOBE) as f:
            globe = json.load(f)
        globe["mesh"] = os.path.join(os.path.dirname(GLOBE), globe["mesh"])
        for name, a, paper in (("scene.json-bender", 0.9, "Letter"), ("option-bender", 0.95, "A4")):
            with open(os.path.join(self.dir.name, name + ".json"), "w") as f:
                json.dump({"format": "wiresculpt-machine-profile", "version": 1, "name": name,
                           "springback_a": a, "springback_b_deg": -2.0, "paper": paper}, f)
        scene = self.scene(**globe, machine_profile="scene.json-bender.json")
        # the second run also predicts what a machine keeping 0.9 c - 2 deg makes of programs compensated for 0.95
        runs = (((), "scene.json-bender", 0.9, "215.900mm"),
                (("--profile", os.path.join(self.dir.name, "option-bender.json"), "--machine-model",
                  os.path.join(self.dir.name, "scene.json-bender.json")), "option-bender", 0.95, "210.000mm"))
        for extra, name, a, width in runs:
            with self.subTest(name):
                r = run_blender(BATCH, scene, "--out", self.out, *extra)
                self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
                self.assertIn(f"wiresculpt: profile: {name} (", r.stdout)
                gcode = os.path.join(self.out, "gcode")
                for g in os.listdir(gcode):
                    with open(os.path.join(gcode, g)) as f:
                        self.assertIn(f"measured = {a:.4f} * commanded + -2.000 deg", f.read())
                pages = os.path.join(self.out, "templates", "pages")
                with open(os.path.join(pages, sorted(os.listdir(pages))[0])) as f:
                    self.assertIn(f'width="{width}"', f.read())
                with open(os.path.join(self.out, "design.json")) as f:
                    fab = json.load(f)["fabrication"]
                if extra:  # every bend comes out short: the loops drift by centimetres
                    self.assertIn("wiresculpt: machine model: scene.json-bender (", r.stdout)
                    self.assertIn("0.9000 × commanded -2.000°", fab["preview_model"])
                    self.assertTrue(all(w["preview_distance"] > 0.01 for w in fab["wires"]), fab["wires"])
                else:  # compensated and predicted with one line: only the small-bend rule moves it
                    self.assertTrue(all(abs(w["preview_distance"] - w["shape_error"]) < 1e-9 for w in fab["wires"]))
        missing = self.scene(**globe, machine_profile="nowhere.json")
        self.out = os.path.join(self.dir.name, "out-missing")
        self.assertFailsWith('"machine_profile": file not found', missing)
        os.remove(os.path.join(self.dir.name, "option-bender.json"))
        scene = self.scene(**globe, machine_profile="scene.json-bender.json")
        r = run_blender(BATCH, scene, "--out", os.path.join(self.dir.name, "out2"), "--profile",
                        os.path.join(self.dir.name, "option-bender.json"))
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        self.assertIn("option-bender.json does not exist", r.stderr)

    def test_missing_arguments(self):
        r = run_blender(BATCH)
        self.assertEqual(r.returncode, 1)
        self.assertIn("usage:", r.stderr)


if __name__ == "__main__":
    unittest.main()
