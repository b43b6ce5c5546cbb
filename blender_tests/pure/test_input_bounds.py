"""Inputs bounded before any solve: plane normals cleaned of components that are zero
in all but representation, plane and wire names bounded and printable, --out checked, one writer
per output folder (two real processes), a folder where a result file belongs refused, and the
smaller cases (spring-back angles past a full turn, a pin axis of null or "\\n").

The same cases through the headless run are in blender_tests/bad_input.json and
test_bad_input.py's CommandLine."""
import os
import subprocess
import sys
import tempfile
import time
import unittest
from unittest import mock

from wiresculpt import native
from wiresculpt.core import meshcheck, scene, staging


def plane(name="A", normal=(0, 0, 1)):
    return {"name": name, "origin": [0, 0, 0], "normal": list(normal)}


class Normals(unittest.TestCase):
    def test_components_below_1e_12_of_the_largest_are_zero(self):
        for tiny in (1e-300, -1e-300, 1e-99, 5e-324, 9.9e-13):
            self.assertEqual(scene._plane(plane(normal=(tiny, 1, 0)), 0, set()).normal, (0.0, 1.0, 0.0), tiny)
        # relative to the largest: [1e-13, 0.5, 0] keeps nothing of 1e-13 (below 5e-13), a normal of
        # length 1e-6 keeps its components
        self.assertEqual(scene._plane(plane(normal=(1e-13, 0.5, 0)), 0, set()).normal, (0.0, 0.5, 0.0))
        self.assertEqual(scene._plane(plane(normal=(1e-6, 1e-6, 0)), 0, set()).normal, (1e-6, 1e-6, 0.0))
        self.assertEqual(scene._plane(plane(normal=(1e-11, 1, 0)), 0, set()).normal, (1e-11, 1.0, 0.0))


class Names(unittest.TestCase):
    def refused(self, name):
        with self.assertRaises(ValueError) as ctx:
            scene._plane(plane(name), 0, set())
        return str(ctx.exception)

    def test_bounded_in_utf8_bytes(self):
        self.assertEqual(scene._plane(plane("x" * 63), 0, set()).name, "x" * 63)
        self.assertEqual(scene._plane(plane("é" * 31), 0, set()).name, "é" * 31)  # 62 bytes
        message = self.refused("é" * 32)
        self.assertTrue(message.startswith('scene key "planes[0].name" is 64 bytes long ('), message)
        huge = self.refused("y" * 10_000_000)  # the whole name is never in the message
        self.assertLess(len(huge), 300)
        self.assertIn("(10000000 characters)", huge)

    def test_control_characters_and_separators(self):
        self.assertEqual(self.refused("a\nb"), 'scene key "planes[0].name" ("a\\nb") holds the control character \\n '
                                               "(U+000A); use printable characters")
        self.assertIn("\\u0000", self.refused("a\x00"))
        self.assertIn("\\u200b", self.refused("a\u200bb"))  # invisible
        self.assertIn("\\u2028", self.refused("a\u2028b"))  # a line separator
        for sep in ("/", "\\"):
            self.assertIn("a plane name may not hold / or \\", self.refused(f"a{sep}b"))
        for message in (self.refused("a\nb"), self.refused("x" * 100)):
            self.assertNotIn("\n", message)

    def test_cut_keys(self):
        with self.assertRaises(ValueError) as ctx:
            scene._settings({"cuts": {"A\r/0": 3}})
        self.assertIn('names the wire "A\\r/0"', str(ctx.exception))
        with self.assertRaises(ValueError):
            scene._settings({"cuts": {"A" * 100 + "/0": 3}})
        self.assertEqual(scene._settings({"cuts": {"A/0": 3}})["cuts"], {"A/0": 3})


class SceneSize(unittest.TestCase):
    def test_a_scene_file_over_16_mb_is_refused_unread(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "scene.json")
            with open(path, "w") as f:
                f.write('{"mesh": "m.obj", "planes": [{"name": "' + "n" * (17 * 1024 ** 2) + '"}]}')
            with self.assertRaises(ValueError) as ctx:
                scene.load_scene(path)
            self.assertEqual(str(ctx.exception), f"scene file {path} is 17 MB; a scene file is at most 16 MB (its "
                                                 "planes, settings and cuts take a few kB)")


class OutFolder(unittest.TestCase):
    def refused(self, out):
        with self.assertRaises(ValueError) as ctx:
            meshcheck.check_output_folder(out)
        self.assertTrue(str(ctx.exception).startswith("--out"), ctx.exception)
        return str(ctx.exception)

    def test_refused(self):
        self.assertIn("is empty", self.refused(""))
        self.assertIn("proc file system", self.refused("/proc/self/out"))
        self.assertIn("sysfs file system", self.refused("/sys/out"))
        self.assertIn("300 bytes long", self.refused("/tmp/" + "b" * 300))
        self.assertIn("over the 4095", self.refused("/tmp/" + "/".join(["c" * 200] * 25)))
        self.assertIn("control character", self.refused("/tmp/a\nb"))

    def test_read_only(self):
        with tempfile.TemporaryDirectory() as tmp:
            with mock.patch("os.access", return_value=False):
                self.assertEqual(self.refused(tmp), f"--out {tmp}: the folder is not writable")
                self.assertIn("is not writable", self.refused(os.path.join(tmp, "new")))
            meshcheck.check_output_folder(os.path.join(tmp, "new", "deeper"))
            self.assertEqual(os.listdir(tmp), [])


HOLDER = r"""
import sys, time
sys.path.insert(0, sys.argv[2])
from wiresculpt.core import staging
with staging.hold(sys.argv[1]):
    print("held", flush=True)
    time.sleep(float(sys.argv[3]))
"""


class OneWriter(unittest.TestCase):
    ADDON = os.path.dirname(os.path.dirname(os.path.abspath(staging.__file__)))

    def holder(self, out, seconds):
        child = subprocess.Popen([sys.executable, "-c", HOLDER, out, os.path.dirname(self.ADDON), str(seconds)],
                                 stdout=subprocess.PIPE, text=True)
        self.assertEqual(child.stdout.readline().strip(), "held")
        return child

    def test_a_second_process_is_refused_naming_the_folder_and_the_holder(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "out")
            os.makedirs(os.path.join(out, staging.STAGING_PREFIX + "live"))  # the holder's live staging
            child = self.holder(out, 30)
            try:
                for attempt in (lambda: staging.recover(out),
                                lambda: staging.staged(out, ("design.json",)).__enter__()):
                    with self.assertRaises(staging.FolderBusy) as ctx:
                        attempt()
                    self.assertEqual(ctx.exception.pid, child.pid)
                    self.assertEqual(str(ctx.exception), f"--out {out}: another wiresculpt run (process {child.pid}) "
                                                         "is writing to this folder; wait for it to end or choose "
                                                         "another --out")
                # recovery never removed the folder the live run owns
                self.assertIn(staging.STAGING_PREFIX + "live", os.listdir(out))
            finally:
                child.kill()
                child.wait()
            # the holder is gone (killed: its lock went with it); the next run recovers and writes
            self.assertEqual(staging.recover(out), "")
            with staging.staged(out, ("design.json",)) as folder:
                with open(os.path.join(folder, "design.json"), "w") as f:
                    f.write('{"format": "wiresculpt-design"}')
            self.assertEqual(sorted(os.listdir(out)), ["design.json"])

    def test_claim_removes_the_folder_it_made_when_left_empty(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "a", "b")
            with self.assertRaises(ValueError):
                with staging.claim(out):
                    self.assertTrue(os.path.exists(os.path.join(out, staging.LOCK)))
                    raise ValueError("a refused scene")
            self.assertEqual(os.listdir(tmp), [])
            with staging.claim(out):
                with staging.staged(out, ("design.json",)) as folder:  # re-entrant: this process holds it
                    with open(os.path.join(folder, "design.json"), "w") as f:
                        f.write('{"format": "wiresculpt-design"}')
            self.assertEqual(os.listdir(out), ["design.json"])

    def test_a_waiter_on_a_removed_lock_file_locks_the_new_one(self):
        with tempfile.TemporaryDirectory() as tmp:
            child = self.holder(tmp, 0.5)
            time.sleep(1.0)
            child.wait()
            with staging.hold(tmp):
                with open(os.path.join(tmp, staging.LOCK)) as f:
                    self.assertEqual(f.read().strip(), str(os.getpid()))
            self.assertEqual(os.listdir(tmp), [])


class Kinds(unittest.TestCase):
    def test_a_folder_where_a_file_belongs_is_refused_and_kept(self):
        with tempfile.TemporaryDirectory() as tmp:
            os.makedirs(os.path.join(tmp, "design.json"))
            with open(os.path.join(tmp, "design.json", "mine.txt"), "w") as f:
                f.write("the user's")
            with open(os.path.join(tmp, "svg"), "w") as f:
                f.write("a file named svg")
            with self.assertRaises(ValueError) as ctx:
                staging.check_kinds(tmp, ("design.json",), ())
            self.assertIn("design.json is a folder, where the run writes the file design.json", str(ctx.exception))
            with self.assertRaises(ValueError) as ctx:
                staging.check_kinds(tmp, (), ("svg",))
            self.assertIn("svg is a file, where the run writes the folder svg/", str(ctx.exception))
            # the switch itself refuses too, leaving both as they were
            with self.assertRaises(ValueError):
                with staging.staged(tmp, ("design.json", "svg")) as folder:
                    with open(os.path.join(folder, "design.json"), "w") as f:
                        f.write('{"format": "wiresculpt-design"}')
            self.assertEqual(sorted(os.listdir(tmp)), ["design.json", "svg"])
            self.assertEqual(os.listdir(os.path.join(tmp, "design.json")), ["mine.txt"])


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class TinyNormalsInTheSolver(unittest.TestCase):
    """The native side of item 2, past the scene reader's cleaning (the add-on's planes, a caller
    of pipeline.run): a normal [1e-300, 1, 0] stopped GLPK in the stability check's equality LP,
    [1e-99, 1, 0] was refused by the force LP for a 9e-101 coefficient. The LP layer drops such
    entries as the zeros they are: the same verdict, hooks and order as [0, 1, 0]."""

    def solve(self, tiny):
        from wiresculpt import pipeline
        from wiresculpt.core.materials import PRESETS
        from wiresculpt.core.settings import defaults

        from helpers import PLANES, sphere

        planes = [p if k != 2 else scene.PlaneSpec(p.name, p.origin, (tiny, 1.0, 0.0), p.contours)
                  for k, p in enumerate(PLANES)]
        self.assertEqual(PLANES[2].normal, (0.0, 1.0, 0.0))
        V, F = sphere()
        return pipeline.run(V, F, planes, PRESETS["steel"], defaults())

    def test_the_same_design_as_zero(self):
        clean = self.solve(0.0)
        self.assertTrue(clean["stable"], clean["reason"])
        for tiny in (1e-300, 1e-99):
            design = self.solve(tiny)
            self.assertTrue(design["stable"], design["reason"])
            self.assertEqual(design["assembly_order"], clean["assembly_order"], tiny)
            self.assertEqual([c["hook"] for c in design["crossings"]], [c["hook"] for c in clean["crossings"]])
            self.assertEqual([len(w["target"]) for w in design["wires"]], [len(w["target"]) for w in clean["wires"]])


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Smaller(unittest.TestCase):
    def test_springback_angles_past_a_full_turn(self):
        from wiresculpt.core import calibration

        with self.assertRaises(ValueError) as ctx:
            calibration.fit_springback("commanded_deg,measured_deg\n1e300,1e300\n2e300,2e300\n")
        self.assertIn("the commanded angle (1e+300 deg) is beyond a full turn (360 deg)", str(ctx.exception))
        self.assertNotIn("same commanded angle", str(ctx.exception))

    def test_pin_axis(self):
        from wiresculpt.core import calibration

        profile = calibration.default_profile()
        for value, message in ((None, "profile: profile['pin_axis']: expected a string, got None"),
                               ("\n", "profile: profile['pin_axis']: expected one letter, got '\\n'"),
                               ("Z\n", "profile: profile['pin_axis']: expected one letter, got 'Z\\n'")):
            with self.assertRaises(ValueError) as ctx:
                calibration.validate_profile(dict(profile, pin_axis=value), "profile")
            self.assertEqual(str(ctx.exception), message)
        calibration.validate_profile(dict(profile, pin_axis=""), "profile")  # "" is no pin
        calibration.validate_profile(dict(profile, pin_axis="z"), "profile")


if __name__ == "__main__":
    unittest.main()
