"""The packaged zips: the add-on zip installs into a clean user scripts folder and loads its
compiled module (the Blender executable); the extension zip passes Blender's own manifest check,
installs into a temporary extension repository through Blender's extension API, enables and
Optimizes the bundled globe (Blender 4.2+, e.g. the PyPI bpy)."""
import os
import subprocess
import sys
import tempfile
import textwrap
import unittest

from helpers import GLOBE_OBJ, GLOBE_RADIUS, ROOT, run_blender


def package(out_dir):
    """(add-on zip, extension zip) written by scripts/package.py into out_dir."""
    made = subprocess.run(["/usr/bin/python3.11", os.path.join(ROOT, "scripts", "package.py"), out_dir],
                          capture_output=True, text=True)
    if made.returncode != 0:
        raise AssertionError("scripts/package.py failed: " + made.stderr)
    addon_zip, extension_zip = made.stdout.split()
    return addon_zip, extension_zip


def extensions_api():
    """A sentence when this Blender has no extension API to install through, else ""."""
    import bpy

    if not hasattr(bpy.context.preferences, "extensions") or \
            "package_install_files" not in dir(bpy.ops.extensions):
        return f"Blender {bpy.app.version_string} has no extensions (4.2+)"
    return ""


REPO = "wiresculpt_test"
INSTALL = textwrap.dedent("""
    import importlib, math, os, sys
    import bpy
    zip_path, repo_dir, globe_obj, radius = sys.argv[sys.argv.index("--") + 1:]
    repo = bpy.context.preferences.extensions.repos.new(
        name="wiresculpt test", module="%(repo)s", custom_directory=repo_dir, source='USER')
    result = bpy.ops.extensions.package_install_files(filepath=zip_path, repo=repo.module,
                                                      enable_on_install=True)
    assert result == {'FINISHED'}, f"the install returned {result}"
    name = "bl_ext.%(repo)s.wiresculpt"
    assert name in bpy.context.preferences.addons, f"{name} is not enabled after the install"
    native = importlib.import_module(name + ".native")
    assert native.module is not None, native.LOAD_ERROR
    assert native.__file__.startswith(os.path.realpath(repo_dir)) or native.__file__.startswith(repo_dir), native.__file__
    assert "wiresculpt" not in sys.modules, "the source tree's package was imported"
    mesh = importlib.import_module(name + ".blend.mesh")
    results = importlib.import_module(name + ".blend.results")
    _V, _F, objects = mesh.import_mesh(globe_obj)
    target = objects[0]
    target.scale = (float(radius),) * 3
    bpy.context.view_layer.update()
    bpy.context.scene.wiresculpt.target = target
    for rotation in ((0, 0, 0), (0, math.pi / 2, 0), (math.pi / 2, 0, 0)):
        assert bpy.ops.wiresculpt.add_plane() == {'FINISHED'}
        bpy.context.view_layer.objects.active.rotation_euler = rotation
    assert bpy.ops.wiresculpt.slice() == {'FINISHED'}
    assert bpy.ops.wiresculpt.optimize() == {'FINISHED'}
    design = results.stored_design()
    assert design is not None and design["stable"], design and design["reason"]
    print("EXTENSION-OK", len(design["wires"]), "wires", flush=True)
    os._exit(0)  # the bpy module crashes in Python's teardown with a dynamic enum registered (run.py)
""") % {"repo": REPO}

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
            zip_path, _extension = package(tmp)
            self.assertRegex(os.path.basename(zip_path), r"^wiresculpt-\d+\.\d+\.\d+-linux-x86_64\.zip$")
            user = os.path.join(tmp, "user")
            script = os.path.join(tmp, "check.py")
            with open(script, "w") as f:
                f.write(CHECK)
            r = run_blender(script, zip_path, user, env={"BLENDER_USER_SCRIPTS": user})
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            self.assertIn("PACKAGE-OK", r.stdout)



class ExtensionTest(unittest.TestCase):
    """The extension zip through Blender's own tools: the manifest validator of the extension
    CLI (strict, as the extensions platform checks it) and the Install from Disk operator into a
    temporary repository, in a fresh Python with this bpy and its own user folder."""

    @classmethod
    def setUpClass(cls):
        import bpy

        reason = extensions_api()
        if reason:
            raise unittest.SkipTest(reason)
        if bpy.app.binary_path:
            raise unittest.SkipTest("runs with the bpy module (a fresh `python` with bpy per "
                                    "check); the Blender executable has its own CLI for this")
        cls.tmp = tempfile.TemporaryDirectory()
        cls.addon_zip, cls.zip = package(cls.tmp.name)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def run_python(self, *args, cwd=None):
        user = os.path.join(self.tmp.name, "user")
        env = {**os.environ, "BLENDER_USER_RESOURCES": user, "PYTHONPATH": ""}
        return subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=cwd or self.tmp.name,
                              env=env, timeout=600)

    def test_blender_validates_the_manifest(self):
        import bpy

        cli = os.path.join(bpy.utils.system_resource('SCRIPTS'), "addons_core", "bl_pkg", "cli",
                           "blender_ext.py")
        self.assertTrue(os.path.isfile(cli), f"Blender's extension CLI is not at {cli}")
        r = self.run_python(cli, "validate", self.zip)
        self.assertEqual(r.returncode, 0, f"Blender rejects the manifest: {r.stdout}{r.stderr}")

    def test_installs_enables_and_optimizes_the_globe(self):
        script = os.path.join(self.tmp.name, "install.py")
        with open(script, "w") as f:
            f.write(INSTALL)
        repo = os.path.join(self.tmp.name, "repo")
        r = self.run_python(script, "--", self.zip, repo, GLOBE_OBJ, str(GLOBE_RADIUS))
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn("EXTENSION-OK 3 wires", r.stdout)
        warned = [line for line in (r.stdout + r.stderr).splitlines()
                  if "deprecat" in line.lower()]
        self.assertEqual(warned, [], "deprecation warnings while the add-on installs and runs")


if __name__ == "__main__":
    unittest.main()
