"""The sentence a failed load of the solver gives (native.explain_load_error), for the cases a
real import cannot make on this machine: another Blender's Python."""
import unittest

from wiresculpt import native


class LoadErrorTest(unittest.TestCase):
    def test_older_blender(self):
        text = native.explain_load_error(ImportError("No module named 'wiresculpt._wiresculpt'"), ["3.11"],
                                         python="3.10", host="Blender 4.0.2")
        self.assertIn("this build is for Python 3.11; Blender 4.0.2 uses 3.10: use Blender 4.1+ "
                      "or build from source with scripts/package", text)

    def test_newer_python(self):
        text = native.explain_load_error(ImportError("x"), ["3.11"], python="3.13", host="Blender 5.1.0")
        self.assertIn("Blender 5.1.0 uses 3.13: use a Blender whose Python is 3.11", text)

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
