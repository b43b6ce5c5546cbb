"""The solver as a wheel (scripts/wheels.py), on Linux: the cp311 manylinux wheel made from the
default build's module, checked as pip would read it (tag, RECORD hashes) and imported from where
it is unpacked by a fresh Python 3.11 (`-I`, no LD_LIBRARY_PATH), both directly and through the
add-on's native.py when the add-on folder carries no module of its own (as in an extension made
of wheels), and read by PyPI's auditwheel, which must find it consistent with its tag. The answers
are known by hand: stream_lines drops comments and blank lines.
"""
import base64
import csv
import glob
import hashlib
import io
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "scripts"))

import package  # noqa: E402
import wheels  # noqa: E402

PYTHON = "/usr/bin/python3.11"
GCODE = "G0 X1 ; note\n(comment)\n\nG1 Y2\n"


def system_glibc():
    out = subprocess.run(["ldd", "--version"], capture_output=True, text=True).stdout
    major, minor = re.search(r"(\d+)\.(\d+)\s*$", out.splitlines()[0]).groups()
    return int(major), int(minor)


class LinuxWheel(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        default = glob.glob(os.path.join(ROOT, "addon", "wiresculpt", "_wiresculpt.cpython-311-*.so"))
        if not default:
            raise unittest.SkipTest("the default build's module is missing: scripts/setup builds it")
        cls.tmp = tempfile.mkdtemp(prefix="wiresculpt-wheel-")
        version = package.versions()["CMakeLists.txt"]
        with tempfile.TemporaryDirectory() as stage:
            staged = package.bundle(default[0], stage)
            cls.floor = wheels.glibc_floor(staged)
            cls.wheel = wheels.write_wheel(cls.tmp, version, "cp311", f"manylinux_{cls.floor[0]}_{cls.floor[1]}_x86_64",
                                           [(p, os.path.relpath(p, stage)) for p in staged])
        cls.site = os.path.join(cls.tmp, "site")
        with zipfile.ZipFile(cls.wheel) as z:
            z.extractall(cls.site)
            cls.names = z.namelist()
            cls.record = z.read(f"wiresculpt_solver-{version}.dist-info/RECORD").decode()
            cls.data = {n: z.read(n) for n in cls.names}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_tag_names_the_glibc_it_needs(self):
        name = os.path.basename(self.wheel)
        self.assertRegex(name, r"^wiresculpt_solver-[0-9.]+-cp311-cp311-manylinux_2_\d+_x86_64\.whl$")
        self.assertGreaterEqual(self.floor, (2, 17))
        self.assertLessEqual(self.floor, system_glibc())  # it loads here, so it cannot need a newer one

    @unittest.skipIf(os.environ.get("WIRESCULPT_AUDITWHEEL") == "0", "WIRESCULPT_AUDITWHEEL=0: auditwheel not run")
    def test_auditwheel_finds_the_same_tag(self):
        # auditwheel's own reading of the needed libraries and symbol versions against the
        # manylinux policies, not glibc_floor's
        found, text = wheels.audited_tag(self.wheel)
        self.assertEqual(found, f"manylinux_{self.floor[0]}_{self.floor[1]}_x86_64", text)

    def test_record_lists_every_file_with_its_hash(self):
        rows = list(csv.reader(io.StringIO(self.record)))
        listed = {r[0] for r in rows}
        self.assertEqual(listed, set(self.names))
        for path, digest, size in rows:
            if path.endswith("RECORD"):
                continue
            want = base64.urlsafe_b64encode(hashlib.sha256(self.data[path]).digest()).rstrip(b"=").decode()
            self.assertEqual(digest, "sha256=" + want, path)
            self.assertEqual(int(size), len(self.data[path]), path)
        self.assertTrue(any(n.startswith("wiresculpt_solver/libs/libglpk") for n in self.names), self.names)

    def run_fresh(self, code, *paths):
        env = {"PATH": os.environ.get("PATH", "/usr/bin:/bin")}
        prelude = "import sys; sys.path[:0] = %r\n" % (list(paths),)
        return subprocess.run([PYTHON, "-I", "-c", prelude + code], capture_output=True, text=True, env=env, timeout=300)

    def test_imports_from_where_it_is_unpacked(self):
        r = self.run_fresh(
            "from wiresculpt_solver import _wiresculpt as m\n"
            f"print(m.stream_lines({GCODE!r}))\n"
            "maps = {l.split()[-1] for l in open('/proc/self/maps') if '/' in l.split()[-1]}\n"
            "print(sorted(p for p in maps if 'libglpk' in p or 'libnlopt' in p))\n", self.site)
        self.assertEqual(r.returncode, 0, r.stderr)
        lines, mapped = r.stdout.splitlines()
        self.assertEqual(lines, "['G0 X1', 'G1 Y2']")
        libs = eval(mapped)  # a printed list of paths
        self.assertEqual(len(libs), 2, libs)
        for lib in libs:
            self.assertTrue(lib.startswith(os.path.join(self.site, "wiresculpt_solver", "libs")), lib)

    def test_the_addon_without_a_module_uses_the_wheel(self):
        addons = os.path.join(self.tmp, "addons")
        shutil.copytree(os.path.join(ROOT, "addon", "wiresculpt"), os.path.join(addons, "wiresculpt"),
                        ignore=shutil.ignore_patterns("__pycache__", "*.so", "libs"))
        code = ("from wiresculpt import native\n"
                "print(native.available(), native.module.__file__ if native.module else native.LOAD_ERROR)\n"
                f"print(native.stream_lines({GCODE!r}))\n")
        r = self.run_fresh(code, addons, self.site)
        self.assertEqual(r.returncode, 0, r.stderr)
        first, second = r.stdout.splitlines()
        self.assertTrue(first.startswith("True " + os.path.join(self.site, "wiresculpt_solver")), first)
        self.assertEqual(second, "['G0 X1', 'G1 Y2']")
        # without the wheel the add-on explains itself (the module is not built), as before
        r = self.run_fresh("from wiresculpt import native\nprint(native.available())\nprint(native.LOAD_ERROR)\n", addons)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(r.stdout.startswith("False\nThe wiresculpt solver (_wiresculpt) is not built"), r.stdout)

    def test_an_extension_of_wheels_names_their_pythons(self):
        """A wheel for another Python in wheels/ (the extension's layout) is named in the load error."""
        addons = os.path.join(self.tmp, "addons-other")
        target = os.path.join(addons, "wiresculpt")
        shutil.copytree(os.path.join(ROOT, "addon", "wiresculpt"), target,
                        ignore=shutil.ignore_patterns("__pycache__", "*.so", "libs"))
        os.makedirs(os.path.join(target, "wheels"))
        wheel = os.path.join(target, "wheels", "wiresculpt_solver-0.1.0-cp313-cp313-manylinux_2_36_x86_64.whl")
        open(wheel, "w").close()
        r = self.run_fresh("from wiresculpt import native\nprint(native.LOAD_ERROR)\n", addons)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("this zip has the solver for Python 3.13; this Python uses 3.11", r.stdout)
        # the Windows extension's wheels on Linux: the platform is named first
        os.rename(wheel, os.path.join(target, "wheels", "wiresculpt_solver-0.1.0-cp311-cp311-win_amd64.whl"))
        r = self.run_fresh("from wiresculpt import native\nprint(native.LOAD_ERROR)\n", addons)
        self.assertIn("this zip has the solver for Windows x64; this Python runs on Linux x86_64", r.stdout)


if __name__ == "__main__":
    unittest.main()
