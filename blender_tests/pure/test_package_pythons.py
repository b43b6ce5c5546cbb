"""Which Pythons scripts/package builds the module for (scripts/package_pythons.find): each
candidate is asked about itself; one without Python.h, an older one, a second interpreter of a
version already built and a non-CPython are left out with one line each. The candidates here are
stand-in executables that answer the probe as such interpreters would, plus the real pyenv 3.10
where this machine has it."""
import contextlib
import io
import json
import os
import stat
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                                "scripts"))
import package_pythons  # noqa: E402


def stand_in(folder, name, implementation, version, headers):
    """An executable that prints what package_pythons.PROBE prints for such an interpreter."""
    info = {"implementation": implementation, "version": version, "include": "/nowhere/include",
            "headers": headers, "ext_suffix": ".cpython-%d%d-x86_64-linux-gnu.so" % tuple(version)}
    path = os.path.join(folder, name)
    with open(path, "w") as f:
        f.write("#!/bin/sh\ncat <<'END'\n" + json.dumps(info) + "\nEND\n")
    os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR)
    return path


class FindTest(unittest.TestCase):
    def find(self, pythons):
        err = io.StringIO()
        old = os.environ.get("WIRESCULPT_PACKAGE_PYTHONS")
        os.environ["WIRESCULPT_PACKAGE_PYTHONS"] = " ".join(pythons)
        try:
            with contextlib.redirect_stderr(err):
                found = package_pythons.find("/usr/bin/python3.11", "3.11")
        finally:
            if old is None:
                del os.environ["WIRESCULPT_PACKAGE_PYTHONS"]
            else:
                os.environ["WIRESCULPT_PACKAGE_PYTHONS"] = old
        return found, err.getvalue().splitlines()

    def test_each_python_left_out_says_why_in_one_line(self):
        with tempfile.TemporaryDirectory() as tmp:
            no_headers = stand_in(tmp, "py312", "cpython", [3, 12], False)
            older = stand_in(tmp, "py39", "cpython", [3, 9], True)
            second = stand_in(tmp, "py311", "cpython", [3, 11], True)
            pypy = stand_in(tmp, "pypy310", "pypy", [3, 10], True)
            good = stand_in(tmp, "py313", "cpython", [3, 13], True)
            found, lines = self.find([no_headers, older, second, pypy, good, "/usr/bin/python3.11"])
        self.assertEqual(found, [(good, "3.13", ".cpython-313-x86_64-linux-gnu.so")])
        self.assertEqual(len(lines), 4, lines)
        self.assertIn(f"Python 3.12 at {no_headers} has no development headers (no Python.h in "
                      "/nowhere/include); skipped", lines[0])
        self.assertIn(f"Python 3.9 at {older} is older than 3.10", lines[1])
        self.assertIn(f"Python 3.11 at {second}: the module for 3.11 comes from /usr/bin/python3.11; skipped",
                      lines[2])
        self.assertIn("is pypy, not CPython; skipped", lines[3])

    def test_a_real_python_with_headers_is_found(self):
        pyenv = os.environ.get("PYENV_ROOT") or os.path.expanduser("~/.pyenv")
        real = sorted(p for p in (os.path.join(pyenv, "versions", v, "bin", "python3")
                                  for v in (os.listdir(os.path.join(pyenv, "versions"))
                                            if os.path.isdir(os.path.join(pyenv, "versions")) else []))
                      if os.path.basename(os.path.dirname(os.path.dirname(p))).startswith("3.10."))
        if not real:
            self.skipTest("no pyenv Python 3.10 on this machine")
        found, lines = self.find(real[:1])
        self.assertEqual(lines, [])
        self.assertEqual(found, [(real[0], "3.10", ".cpython-310-x86_64-linux-gnu.so")])


if __name__ == "__main__":
    unittest.main()
