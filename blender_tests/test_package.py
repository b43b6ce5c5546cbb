"""The packaged zip installs into a clean user scripts folder and loads its compiled module."""
import os
import subprocess
import tempfile
import textwrap
import unittest

from helpers import ROOT, run_blender

CHECK = textwrap.dedent("""
    import sys, addon_utils, bpy
    zip_path, user = sys.argv[sys.argv.index("--") + 1:]
    bpy.ops.preferences.addon_install(filepath=zip_path)
    mod = addon_utils.enable("wiresculpt", default_set=True)
    assert mod is not None, "the add-on did not enable"
    import wiresculpt, wiresculpt.native as native
    assert wiresculpt.__file__.startswith(user), wiresculpt.__file__
    assert native.available(), native.LOAD_ERROR
    assert hasattr(bpy.types, "VIEW3D_PT_wiresculpt"), "the sidebar panel is not registered"
    assert hasattr(bpy.types.Scene, "wiresculpt"), "the settings are not registered"
    print("PACKAGE-OK", native.module.__version__)
""")


class PackageTest(unittest.TestCase):
    def test_manifest_for_blender_4_2(self):
        import tomllib

        import wiresculpt

        with open(os.path.join(ROOT, "addon", "wiresculpt", "blender_manifest.toml"), "rb") as f:
            manifest = tomllib.load(f)
        for key in ("schema_version", "id", "version", "name", "tagline", "maintainer", "type",
                    "blender_version_min", "license"):
            self.assertIn(key, manifest)
        self.assertEqual(manifest["id"], "wiresculpt")
        self.assertEqual(manifest["type"], "add-on")
        self.assertEqual(manifest["version"], ".".join(map(str, wiresculpt.bl_info["version"])))
        self.assertFalse(manifest["tagline"].endswith("."), "Blender refuses a tagline ending in a period")
        self.assertLessEqual(len(manifest["tagline"]), 64)

    def test_zip_installs_and_loads(self):
        with tempfile.TemporaryDirectory() as tmp:
            made = subprocess.run(["/usr/bin/python3.11", os.path.join(ROOT, "scripts", "package.py"), tmp],
                                  capture_output=True, text=True)
            self.assertEqual(made.returncode, 0, made.stderr)
            zip_path = made.stdout.strip()
            self.assertRegex(os.path.basename(zip_path), r"^wiresculpt-\d+\.\d+\.\d+-linux-x86_64\.zip$")
            user = os.path.join(tmp, "user")
            script = os.path.join(tmp, "check.py")
            with open(script, "w") as f:
                f.write(CHECK)
            r = run_blender(script, zip_path, user, env={"BLENDER_USER_SCRIPTS": user})
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            self.assertIn("PACKAGE-OK", r.stdout)


if __name__ == "__main__":
    unittest.main()
