"""The sentence a failed load of the solver gives (native.explain_load_error), for the cases a
real import cannot make on this machine: another Blender's Python."""
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
        text = native.explain_load_error(exc, ["3.10", "3.11", "3.13"], python="3.13", host="Blender 5.1.0")
        self.assertNotIn("this zip has the solver for", text)
        self.assertIn("the library libglpk.so.40 is missing", text)

    def test_missing_library_named(self):
        exc = ImportError("libnlopt_cxx.so.0: cannot open shared object file: No such file or directory")
        text = native.explain_load_error(exc, ["3.11"], python="3.11", host="Blender 4.2.0")
        self.assertIn("the library libnlopt_cxx.so.0 is missing", text)

    def test_not_built(self):
        text = native.explain_load_error(ImportError("No module named 'wiresculpt._wiresculpt'"), [], python="3.11")
        self.assertIn("not built", text)
        self.assertIn("scripts/setup", text)

    def test_builds_read_from_file_names(self):
        # the running checkout: whatever modules are there name their Python in the file name
        for version in native.built_for():
            self.assertRegex(version, r"^3\.\d+$")


if __name__ == "__main__":
    unittest.main()
