"""The sentence a failed load of the solver gives (native.explain_load_error), for the cases a
real import cannot make on this machine: another Blender's Python."""
import ctypes
import ctypes.util
import os
import shutil
import subprocess
import tempfile
import unittest

from wiresculpt import native


class LoadErrorTest(unittest.TestCase):
    def test_older_blender(self):
        text = native.explain_load_error(ImportError("No module named 'wiresculpt._wiresculpt'"), ["3.11"],
                                         python="3.10", host="Blender 4.0.2")
        self.assertIn("this zip has the solver for Python 3.11; Blender 4.0.2 uses 3.10: install it in a "
                      "Blender whose Python is 3.11 (Blender 4.1 to 5.0), or build the zip from source with "
                      "scripts/package on a machine that has Python 3.10 and its headers.", text)

    def test_newer_python(self):
        text = native.explain_load_error(ImportError("x"), ["3.11"], python="3.13", host="Blender 5.1.0")
        self.assertIn("Blender 5.1.0 uses 3.13: install it in a Blender whose Python is 3.11", text)

    def test_zip_of_several_pythons_lacks_this_one(self):
        # a zip made where Python 3.10, 3.11 and 3.13 had headers, loaded by a distribution's Blender
        # built against Python 3.12 (no Blender release embeds 3.12, so it gets no range)
        text = native.explain_load_error(ImportError("No module named 'wiresculpt._wiresculpt'"),
                                         ["3.10", "3.11", "3.13"], python="3.12", host="Blender 4.0.2")
        self.assertEqual(
            "The wiresculpt solver did not load: this zip has the solver for Python 3.10, 3.11 and 3.13; "
            "Blender 4.0.2 uses 3.12: install it in a Blender whose Python is 3.10 or 3.11 or 3.13 "
            "(Blender 3.4 to 4.0, Blender 4.1 to 5.0, Blender 5.1 and later), or build the zip from "
            "source with scripts/package on a machine that has Python 3.12 and its headers.", text)

    def test_python_the_zip_has_is_not_blamed(self):
        # the running Python is among the builds: the cause is something else (here a library)
        exc = ImportError("libglpk.so.40: cannot open shared object file: No such file or directory")
        text = native.explain_load_error(exc, ["3.10", "3.11", "3.13"], python="3.13", host="Blender 5.1.0",
                                         missing="libglpk.so.40")
        self.assertNotIn("this zip has the solver for", text)
        self.assertIn("the library libglpk.so.40 is missing", text)

    def test_missing_library_named(self):
        exc = ImportError("libnlopt_cxx.so.0: cannot open shared object file: No such file or directory")
        text = native.explain_load_error(exc, ["3.11"], python="3.11", host="Blender 4.2.0", missing="libnlopt_cxx.so.0")
        self.assertIn("the library libnlopt_cxx.so.0 is missing", text)

    def test_the_words_do_not_decide(self):
        # the loader's text naming a library is not read: without a library found missing, the text is said as it is
        exc = ImportError("libglpk.so.40: cannot open shared object file: No such file or directory")
        text = native.explain_load_error(exc, ["3.11"], python="3.11", host="Blender 4.2.0")
        self.assertEqual(text, "The wiresculpt solver (_wiresculpt) did not load in Blender 4.2.0: " + str(exc))
        self.assertEqual(native.load_cause(["3.11"], "3.11", "libx.so.1"), (native.MISSING_LIBRARY, {"library": "libx.so.1"}))

    def test_not_built(self):
        text = native.explain_load_error(ImportError("No module named 'wiresculpt._wiresculpt'"), [], python="3.11")
        self.assertIn("not built", text)
        self.assertIn("scripts/setup", text)

    def test_builds_read_from_file_names(self):
        # the running checkout: whatever modules are there name their Python in the file name
        for version in native.built_for():
            self.assertRegex(version, r"^3\.\d+$")



@unittest.skipUnless(native.module_file() and shutil.which("patchelf"), "needs the built module and patchelf")
class MissingLibrary(unittest.TestCase):
    """native.missing_library on copies of the built module whose needs patchelf edits; the
    loader's own error (ctypes) is the independent answer."""

    def setUp(self):
        self.folder = tempfile.mkdtemp()
        self.addCleanup(shutil.rmtree, self.folder)

    def copy(self, source, name, *edits):
        path = os.path.join(self.folder, name)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        shutil.copy(source, path)
        for edit in edits:
            subprocess.run(["patchelf", *edit, path], check=True, capture_output=True)
        return path

    def loader_says(self, path):
        try:
            ctypes.CDLL(path)
        except OSError as exc:
            return str(exc)
        return ""

    def test_the_built_module_needs_nothing_missing(self):
        needed, _runpath = native.elf_dependencies(native.module_file())
        self.assertIn("libglpk.so.40", needed)
        self.assertIn("libnlopt.so.0", needed)
        self.assertIsNone(native.missing_library(native.module_file()))

    def test_a_library_absent_from_the_system(self):
        path = self.copy(native.module_file(), "m.so", ["--add-needed", "libwiresculpt-absent.so.9"])
        self.assertIn("libwiresculpt-absent.so.9: cannot open shared object file", self.loader_says(path))
        self.assertEqual(native.missing_library(path), "libwiresculpt-absent.so.9")
        text = native.explain_load_error(ImportError("x"), ["3.11"], python="3.11", missing=native.missing_library(path))
        self.assertIn("the library libwiresculpt-absent.so.9 is missing. The packaged zip carries it in libs/", text)

    def test_a_bundled_library_s_own_need(self):
        """The module finds libwsdep.so.1 in $ORIGIN/libs (as the zip bundles them); that one needs
        a library nowhere to be found: that is the one named, as the loader does."""
        dependency = ctypes.util.find_library("serialport") or ctypes.util.find_library("glpk")
        system = next(os.path.join(d, dependency) for d in ("/usr/lib/x86_64-linux-gnu", "/lib/x86_64-linux-gnu")
                      if os.path.exists(os.path.join(d, dependency)))
        self.copy(system, "libs/libwsdep.so.1", ["--set-soname", "libwsdep.so.1"],
                  ["--add-needed", "libwiresculpt-deeper.so.2"])
        path = self.copy(native.module_file(), "m.so", ["--add-needed", "libwsdep.so.1"],
                         ["--set-rpath", "$ORIGIN/libs"])
        self.assertEqual(native.elf_dependencies(path)[1], ["$ORIGIN/libs"])
        self.assertIn("libwiresculpt-deeper.so.2: cannot open shared object file", self.loader_says(path))
        self.assertEqual(native.missing_library(path), "libwiresculpt-deeper.so.2")

    def test_not_an_elf_file(self):
        path = os.path.join(self.folder, "short.so")
        with open(path, "wb") as f:
            f.write(b"\x7fEL")
        self.assertIsNone(native.elf_dependencies(path))
        self.assertIsNone(native.missing_library(path))


if __name__ == "__main__":
    unittest.main()
