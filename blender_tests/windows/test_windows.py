"""The win_amd64 solver for real: cross-built here (scripts/windows.py), imported by python.org's
Windows CPython 3.11 and 3.13 under Wine, solving the bundled globe through the add-on's bpy-free
pipeline to the same design as the Linux module does.

The answer compared against is independent of the Windows build: the same script
(globe_design.py) run by the Linux Python 3.11 with the Linux module, in this process's set-up.
What must match:

- the design, as compare.py says (exactly: stability, hooks, assembly order; within its
  tolerances: every point and force);
- the atomic write's result (the second text replaced the first, no temporary file left);
- serial streaming through a COM port (native/src/fab/serial_win32.cpp, Windows' own API): Wine
  maps COMn to a pty (windows.ComPorts) whose master end is the suite's GRBL emulator
  (blender_tests/helpers.py); a small program streamed to it arrives line by line and is
  acknowledged, an error:20 and a pulled cable stop it where they must, a second stream to a port
  one holds is refused (the same streams through the Linux module, straight on the ptys, give the
  same results); a port that does not exist and the port list (against the registry read by
  winreg) say what they must.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "scripts"))

import windows  # noqa: E402  scripts/windows.py

sys.path.insert(0, os.path.dirname(HERE))
import helpers  # noqa: E402  blender_tests/helpers.py: the GRBL emulator

import compare  # noqa: E402  blender_tests/windows/compare.py

SCRIPT = os.path.join(HERE, "globe_design.py")
PYTHONS = ("3.11", "3.13")


def winpath(path):
    """How the Windows side sees a Linux path (Wine maps / to drive Z:)."""
    return "Z:" + os.path.abspath(path).replace("/", "\\")


def stage_addon(module, folder):
    """The add-on's Python files in folder/wiresculpt/ with the Windows module beside them, as the
    zip lays them out; returns `folder`."""
    target = os.path.join(folder, "wiresculpt")
    shutil.copytree(os.path.join(ROOT, "addon", "wiresculpt"), target,
                    ignore=shutil.ignore_patterns("__pycache__", "*.so", "libs"))
    shutil.copy2(module, target)
    return folder


# The GRBL emulator behind each streamed port: answering ok to every line, error:20 to the 3rd,
# and pulling the cable on the 3rd (helpers.GrblEmulator).
EMULATORS = {"ok": {}, "error": {"error_on": 3}, "drop": {"drop_on": 3}}


def emulators():
    return {case: helpers.GrblEmulator(**kw) for case, kw in EMULATORS.items()}


class WindowsGlobe(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="wiresculpt-windows-")
        cls.received, cls.com = {}, {}
        linux_out = os.path.join(cls.tmp, "linux.json")
        emus = emulators()
        try:  # the Linux module straight on the ptys
            subprocess.run([sys.executable, SCRIPT, linux_out, os.path.join(ROOT, "addon"),
                            json.dumps({case: e.port for case, e in emus.items()})], check=True,
                           stdout=subprocess.DEVNULL)
        finally:
            cls.received["linux"] = {case: list(e.received) for case, e in emus.items()}
            for e in emus.values():
                e.close()
        with open(linux_out) as f:
            cls.linux = json.load(f)
        cls.modules, cls.reports = {}, {}
        for minor in PYTHONS:
            cls.modules[minor] = windows.module(minor)
            addons = stage_addon(cls.modules[minor], os.path.join(cls.tmp, "addon-" + minor))
            out = os.path.join(cls.tmp, f"windows-{minor}.json")
            emus = emulators()
            try:
                with windows.ComPorts() as com:
                    cls.com[minor] = {case: com.add(e.port) for case, e in emus.items()}
                    code = windows.python(minor, SCRIPT, [winpath(out), winpath(addons), json.dumps(cls.com[minor])])
            finally:
                cls.received[minor] = {case: list(e.received) for case, e in emus.items()}
                for e in emus.values():
                    e.close()
            if code == 0 and os.path.isfile(out):
                with open(out) as f:
                    cls.reports[minor] = json.load(f)
            else:
                cls.reports[minor] = f"globe_design.py exited with {code} under Wine (its output is above)"

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def report(self, minor):
        r = self.reports[minor]
        if isinstance(r, str):
            self.fail(r)
        return r

    def test_imports_only_windows_and_python(self):
        for minor in PYTHONS:
            with self.subTest(python=minor):
                dlls = [d.lower() for d in windows.dll_imports(self.modules[minor])]
                own = f"python{minor.replace('.', '')}.dll"
                self.assertIn(own, dlls)
                self.assertEqual([d for d in dlls if d not in windows.SYSTEM_DLLS | {own}], [])
                self.assertNotIn("libwinpthread-1.dll", dlls)
                self.assertNotIn("libstdc++-6.dll", dlls)

    def test_the_interpreter_is_windows(self):
        for minor in PYTHONS:
            with self.subTest(python=minor):
                r = self.report(minor)
                self.assertEqual(r["platform"], "win32")
                self.assertTrue(r["python"].startswith(minor + "."), r["python"])
                self.assertEqual(r["module"], f"_wiresculpt.cp{minor.replace('.', '')}-win_amd64.pyd")

    def test_globe_matches_linux(self):
        self.assertTrue(self.linux["design"]["stable"], self.linux["design"]["reason"])
        for minor in PYTHONS:
            with self.subTest(python=minor):
                r = self.report(minor)
                gap, rel = compare.measured(self.linux, r)
                print(f"windows {minor}: the globe's points within {gap:.3g} m of Linux's, forces within {rel:.3g}")
                self.assertEqual(compare.differences(self.linux, r), [])

    def test_atomic_write_replaces(self):
        for minor in PYTHONS:
            with self.subTest(python=minor):
                self.assertEqual(self.report(minor)["atomic_write"], {"text": "second, longer", "left": ["design.json"]})
        self.assertEqual(self.linux["atomic_write"], {"text": "second, longer", "left": ["design.json"]})

    def streams(self):
        """(label, that run's stream results, what its emulators received): Linux's, then each Windows'."""
        yield "linux", self.linux["streams"], self.received["linux"]
        for minor in PYTHONS:
            yield minor, self.report(minor)["streams"], self.received[minor]

    def test_stream_through_the_port(self):
        program = ["G21", "G91", "G1 X1 F100", "G4 P0", "G1 Y-2 F100", "G4 P0", "M2"]  # globe_design.SERIAL_PROGRAM
        for label, streams, received in self.streams():
            with self.subTest(run=label):
                r = streams["ok"]
                self.assertIsInstance(r, dict, r)
                self.assertEqual((r["status"], r["sent"], r["acknowledged"], r["failed_line"]), ("completed", 7, 7, -1))
                self.assertEqual((r["next_line"], r["confirmed"]), (7, 7))
                self.assertEqual(received["ok"], program)

    def test_error_stops_at_its_line(self):
        for label, streams, received in self.streams():
            with self.subTest(run=label):
                r = streams["error"]
                self.assertIsInstance(r, dict, r)
                # the 3rd line (index 2) is refused: nothing after it is sent, the resume starts at it
                self.assertEqual((r["status"], r["code"], r["failed_line"], r["acknowledged"]), ("error", 20, 2, 2))
                self.assertEqual(r["next_line"], 2)
                self.assertEqual(received["error"], ["G21", "G91", "G1 X1 F100"])

    def test_pulled_cable_is_a_disconnect(self):
        for label, streams, received in self.streams():
            with self.subTest(run=label):
                r = streams["drop"]
                self.assertIsInstance(r, dict, r)
                # the cable goes with the 3rd line in flight; the two mode lines before it are done
                self.assertEqual((r["status"], r["failed_line"], r["acknowledged"]), ("disconnected", 2, 2))
                self.assertEqual((r["next_line"], r["confirmed"]), (2, 2))
                self.assertEqual(received["drop"], ["G21", "G91", "G1 X1 F100"])

    def test_held_port_is_in_use(self):
        for label, streams, received in self.streams():
            with self.subTest(run=label):
                port = self.com[label]["ok"] if label in self.com else None
                held = streams["held"]
                self.assertTrue(held.startswith("ValueError: serial port '"), held)
                self.assertIn("' is in use by ", held)
                if port:
                    self.assertIn(f"'{port}' is in use by another wiresculpt stream", held)
                self.assertEqual(len(received["ok"]), 7)  # the refused stream sent nothing

    def test_absent_port_says_so(self):
        for minor in PYTHONS:
            with self.subTest(python=minor):
                r = self.report(minor)
                self.assertTrue(r["serial"].startswith("ValueError: could not open serial port 'COM199': no such port"),
                                r["serial"])

    def test_ports_listed_as_the_registry_has_them(self):
        for minor in PYTHONS:
            with self.subTest(python=minor):
                found = self.report(minor)["port_list"]
                registry = sorted(found["registry"], key=lambda p: int(p["name"][3:]))
                self.assertEqual(found["listed"], registry)
                names = [p["name"] for p in found["listed"]]
                self.assertLess(names.index("COM31"), names.index("COM249"))  # by number, not as text
                self.assertIn({"name": "COM31", "description": "\\Device\\WiresculptTestB"}, found["listed"])


class CompareCatches(unittest.TestCase):
    """compare.py finds what it must: a point moved past the tolerance, a flipped hook, another order."""

    def test_differences_found(self):
        import copy

        linux = {"design": {
            "stable": True, "reason": None,
            "wires": [{"name": "A/0", "closed": True, "contour": [[0.0, 0.0, 0.0]], "target": [[0.1, 0.0, 0.0]],
                       "rest": [[0.2, 0.0, 0.0]]}],
            "crossings": [{"wires": [0, 1], "hook": 1, "normal_force": 0.5}],
            "assembly_order": [0, 1],
            "load_capacity": dict({a: 3.0 for a in compare.AXES}, base={"+x": ["A/0"]})}}
        self.assertEqual(compare.differences(linux, copy.deepcopy(linux)), [])
        near = copy.deepcopy(linux)
        near["design"]["wires"][0]["rest"][0][1] += 0.5 * compare.POINT_TOL
        self.assertEqual(compare.differences(linux, near), [])
        far = copy.deepcopy(linux)
        far["design"]["wires"][0]["rest"][0][1] += 2 * compare.POINT_TOL
        far["design"]["crossings"][0]["hook"] = -1
        far["design"]["assembly_order"] = [1, 0]
        far["design"]["load_capacity"]["-z"] = 3.0 * (1 + 2 * compare.FORCE_RTOL)
        found = compare.differences(linux, far)
        self.assertEqual(len(found), 4, found)
        self.assertTrue(found[0].startswith("wire A/0 rest: points up to 2e-09 m apart"), found[0])


if __name__ == "__main__":
    unittest.main()
