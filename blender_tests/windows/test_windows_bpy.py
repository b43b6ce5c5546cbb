"""The Windows extension inside the Windows Blender: PyPI's win_amd64 `bpy` 4.5 LTS in python.org's
Windows CPython 3.11 under Wine installs the Windows extension zip (scripts/wheels.py: the add-on's
files and the cp311/cp313 win_amd64 wheels) through Install from Disk, enables it, and the solver
loads from the wheel Blender installed; the globe is sliced, optimized (stable, the hooks and
assembly order the Linux bpy-free pipeline finds for these planes are checked by test_windows)
and its fabrication files exported.

About 330 MB downloaded and 600 MB unpacked once (~/.cache/wiresculpt/windows/site/), and a
minute or two a run (bpy's import under Wine alone takes 30-80 s on the shared machine);
WIRESCULPT_WINDOWS_BPY=0 leaves it out.
"""
import json
import os
import shutil
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "scripts"))

import windows  # noqa: E402

from helpers import GLOBE_OBJ, GLOBE_RADIUS  # noqa: E402  blender_tests/helpers.py
from test_windows import winpath  # noqa: E402

WINDOWS_BPY = "4.5.15"  # the LTS line, Python 3.11


@unittest.skipIf(os.environ.get("WIRESCULPT_WINDOWS_BPY") == "0", "WIRESCULPT_WINDOWS_BPY=0")
class WindowsBlender(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        import package
        import wheels

        cls.tmp = tempfile.mkdtemp(prefix="wiresculpt-winbpy-")
        version = package.versions()["CMakeLists.txt"]
        made = [wheels.write_wheel(cls.tmp, version, "cp" + m.replace(".", ""), "win_amd64",
                                   [(p, os.path.basename(p))]) for m in wheels.PYTHONS for p in [windows.module(m)]]
        cls.zip = wheels.extension_zip(cls.tmp, version, "windows-x64", made)
        site = windows.bpy_site(WINDOWS_BPY)
        out, report = os.path.join(cls.tmp, "out"), os.path.join(cls.tmp, "report.json")
        os.makedirs(out)
        cls.code = windows.python("3.11", os.path.join(HERE, "bpy_install.py"),
                                  [winpath(cls.zip), winpath(os.path.join(cls.tmp, "repo")), winpath(GLOBE_OBJ), str(GLOBE_RADIUS),
                                   winpath(out), winpath(report)],
                                  paths=[site], env={"BLENDER_USER_RESOURCES": winpath(os.path.join(cls.tmp, "user"))})
        cls.report = None
        if os.path.isfile(report):
            with open(report) as f:
                cls.report = json.load(f)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def setUp(self):
        if self.report is None:
            self.fail(f"bpy_install.py wrote no report (exit {self.code}; its output is above)")

    def test_it_is_the_windows_blender(self):
        self.assertEqual(self.report["platform"], "win32")
        self.assertTrue(self.report["bpy"].startswith("4.5."), self.report["bpy"])

    def test_installs_and_loads_from_its_wheel(self):
        r = self.report
        self.assertNotIn("install_error", r, r.get("install_error"))
        self.assertEqual(r["install"], ["FINISHED"])
        self.assertTrue(r["enabled"])
        self.assertEqual(r["load_error"], "")
        # the module Blender unpacked from the cp311 wheel into the extensions' site-packages
        self.assertTrue(r["module"].endswith(os.path.join("wiresculpt_solver", "_wiresculpt.cp311-win_amd64.pyd")
                                             .replace("/", "\\")), r["module"])

    def test_optimizes_the_globe_and_exports(self):
        r = self.report
        self.assertEqual((r.get("slice"), r.get("optimize")), (["FINISHED"], ["FINISHED"]))
        self.assertTrue(r["stable"], r["reason"])
        self.assertEqual(len(r["wires"]), 3)
        self.assertEqual(len(r["hooks"]), 6)
        self.assertEqual(r["export"], ["FINISHED"])
        for folder in ("svg", "dxf", "gcode", "bends"):
            self.assertIn(folder, r["exported"])
        self.assertEqual(len(r["exported"]["gcode"]), 3, r["exported"])


if __name__ == "__main__":
    unittest.main()
