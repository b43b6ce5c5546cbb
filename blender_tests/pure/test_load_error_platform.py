"""The load error names the platform at fault: a zip whose modules (or wheels) are all for
another platform than this computer's says so before anything about Pythons (native.py)."""
import os
import tempfile
import unittest

from wiresculpt import native


class PlatformTest(unittest.TestCase):
    def test_file_names_give_the_platform(self):
        self.assertEqual(native.platform_of("_wiresculpt.cpython-311-x86_64-linux-gnu.so"), "Linux x86_64")
        self.assertEqual(native.platform_of("_wiresculpt.cp313-win_amd64.pyd"), "Windows x64")
        self.assertEqual(native.platform_of("wiresculpt_solver-0.1.0-cp311-cp311-win_amd64.whl"), "Windows x64")
        self.assertEqual(native.platform_of("wiresculpt_solver-0.1.0-cp313-cp313-manylinux_2_36_x86_64.whl"),
                         "Linux x86_64")
        self.assertEqual(native.platform_of("_wiresculpt.cpython-311-darwin.so"), "macOS")
        self.assertIsNone(native.platform_of("native.py"))

    def test_linux_zip_on_windows(self):
        text = native.explain_load_error(ImportError("DLL load failed"), ["3.11"], python="3.11",
                                         host="Blender 4.5.3", platforms=["Linux x86_64"], running="Windows x64")
        self.assertEqual("The wiresculpt solver did not load: this zip has the solver for Linux x86_64; Blender "
                         "4.5.3 runs on Windows x64: install the zip made for Windows x64 (scripts/package writes "
                         "one per platform), or build from source with scripts/package on that computer.", text)

    def test_the_right_platform_is_not_blamed(self):
        text = native.explain_load_error(ImportError("x"), ["3.11"], python="3.13", host="Blender 5.1.0",
                                         platforms=["Linux x86_64", "Windows x64"], running="Windows x64")
        self.assertNotIn("runs on", text)
        self.assertIn("Blender 5.1.0 uses 3.13", text)

    def test_platforms_read_from_a_folder_and_its_wheels(self):
        with tempfile.TemporaryDirectory() as folder:
            os.makedirs(os.path.join(folder, "wheels"))
            open(os.path.join(folder, "wheels", "wiresculpt_solver-0.1.0-cp311-cp311-win_amd64.whl"), "w").close()
            open(os.path.join(folder, "native.py"), "w").close()
            self.assertEqual(native.built_platforms(folder), ["Windows x64"])
            open(os.path.join(folder, "_wiresculpt.cpython-311-x86_64-linux-gnu.so"), "w").close()
            self.assertEqual(native.built_platforms(folder), ["Linux x86_64", "Windows x64"])

    def test_this_checkout(self):
        self.assertEqual(native.running_platform(), "Linux x86_64")
        self.assertIn("Linux x86_64", native.built_platforms())


if __name__ == "__main__":
    unittest.main()
