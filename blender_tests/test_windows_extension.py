"""The Windows extension zip (scripts/wheels.py: the add-on's Python files and one win_amd64 wheel
per Python in wheels/) through Blender's own manifest validator, strict as the extensions platform
checks it, and through Install from Disk on this Linux Blender, which must refuse it for its
platform (the manifest says windows-x64 only). Blender 4.2+ with the bpy module; the Windows
modules come from the cache scripts/test_windows fills (skipped, saying so, when this tree's are
not there: nothing is cross-built inside a Blender suite)."""
import os
import subprocess
import sys
import tempfile
import tomllib
import unittest
import zipfile

from helpers import ROOT

sys.path.insert(0, os.path.join(ROOT, "scripts"))


class WindowsExtensionTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        import bpy

        from test_package import extensions_api

        reason = extensions_api()
        if reason:
            raise unittest.SkipTest(reason)
        if bpy.app.binary_path:
            raise unittest.SkipTest("runs with the bpy module (a fresh `python` with bpy per check)")
        import package
        import wheels
        import windows

        modules = [windows.cached_module(m) for m in wheels.PYTHONS]
        if None in modules:
            raise unittest.SkipTest("no Windows module of this source tree in the cache: scripts/test_windows "
                                    "(a stage of scripts/test, before this one) builds them")
        cls.tmp = tempfile.TemporaryDirectory()
        version = package.versions()["CMakeLists.txt"]
        made = [wheels.write_wheel(cls.tmp.name, version, "cp" + m.replace(".", ""), "win_amd64",
                                   [(path, os.path.basename(path))]) for m, path in zip(wheels.PYTHONS, modules)]
        cls.wheels = [os.path.basename(w) for w in made]
        cls.zip = wheels.extension_zip(cls.tmp.name, version, "windows-x64", made)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def run_python(self, *args):
        env = {**os.environ, "BLENDER_USER_RESOURCES": os.path.join(self.tmp.name, "user"), "PYTHONPATH": ""}
        return subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=self.tmp.name, env=env,
                              timeout=600)

    def test_manifest_lists_its_wheels_and_platform(self):
        with zipfile.ZipFile(self.zip) as z:
            manifest = tomllib.loads(z.read("blender_manifest.toml").decode())
            names = set(z.namelist())
        self.assertEqual(manifest["platforms"], ["windows-x64"])
        self.assertEqual(manifest["wheels"], [f"./wheels/{w}" for w in self.wheels])
        self.assertEqual(sorted(self.wheels), ["wiresculpt_solver-%s-cp311-cp311-win_amd64.whl" % manifest["version"],
                                               "wiresculpt_solver-%s-cp313-cp313-win_amd64.whl" % manifest["version"]])
        for w in self.wheels:
            self.assertIn("wheels/" + w, names)
        self.assertIn("native.py", names)
        self.assertFalse([n for n in names if n.endswith((".so", ".pyd"))], "the module is in the wheels only")
        for w in self.wheels:
            with zipfile.ZipFile(os.path.join(self.tmp.name, w)) as whl:
                inside = whl.namelist()
            tag = w.split("-")[2]
            self.assertIn(f"wiresculpt_solver/_wiresculpt.{tag}-win_amd64.pyd", inside)
            self.assertIn("wiresculpt_solver-%s.dist-info/RECORD" % manifest["version"], inside)

    def test_blender_validates_the_manifest(self):
        import bpy

        cli = os.path.join(bpy.utils.system_resource('SCRIPTS'), "addons_core", "bl_pkg", "cli", "blender_ext.py")
        r = self.run_python(cli, "validate", self.zip)
        self.assertEqual(r.returncode, 0, f"Blender rejects the manifest: {r.stdout}{r.stderr}")

    def test_linux_blender_refuses_it(self):
        script = os.path.join(self.tmp.name, "install.py")
        with open(script, "w") as f:
            f.write("import os, sys, bpy\n"
                    "repo = bpy.context.preferences.extensions.repos.new(name='wstest', module='wstest', "
                    "custom_directory=sys.argv[2], source='USER')\n"
                    "try:\n"
                    "    print('result', sorted(bpy.ops.extensions.package_install_files(filepath=sys.argv[1], "
                    "repo='wstest', enable_on_install=True)))\n"
                    "except RuntimeError as exc:\n"
                    "    print('refused:', exc)\n"
                    "print('enabled', 'bl_ext.wstest.wiresculpt' in bpy.context.preferences.addons)\n"
                    "sys.stdout.flush()\n"
                    "os._exit(0)\n")
        r = self.run_python(script, self.zip, os.path.join(self.tmp.name, "repo"))
        out = r.stdout + r.stderr
        self.assertIn("This platform (linux-x64) isn't one of (windows-x64)", out)
        self.assertIn("enabled False", r.stdout, out)


if __name__ == "__main__":
    unittest.main()
