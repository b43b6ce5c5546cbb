"""The packaged zip installs into a clean user scripts folder and loads its compiled module; it
carries its own solver libraries, and a failed load says what is wrong."""
import os
import re
import shutil
import subprocess
import tempfile
import textwrap
import unittest

from helpers import BLENDER, ROOT, run_blender

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


# The globe example through the installed add-on, with a check of where every solver library
# was loaded from (/proc/self/maps: the mapped files of this process).
OPTIMIZE = textwrap.dedent("""
    import math, os, sys, addon_utils, bpy
    zip_path, user, globe_obj = sys.argv[sys.argv.index("--") + 1:]
    bpy.ops.preferences.addon_install(filepath=zip_path)
    assert addon_utils.enable("wiresculpt", default_set=True) is not None, "the add-on did not enable"
    import wiresculpt, wiresculpt.native as native
    assert wiresculpt.__file__.startswith(user), wiresculpt.__file__
    assert native.available(), native.LOAD_ERROR
    from wiresculpt.blend.mesh import import_mesh
    _V, _F, objects = import_mesh(globe_obj)
    objects[0].scale = (0.125,) * 3
    bpy.context.view_layer.update()
    bpy.context.scene.wiresculpt.target = objects[0]
    for rotation in ((0, 0, 0), (0, math.pi / 2, 0), (math.pi / 2, 0, 0)):
        bpy.ops.wiresculpt.add_plane()
        bpy.context.view_layer.objects.active.rotation_euler = rotation
    assert bpy.ops.wiresculpt.slice() == {'FINISHED'}
    assert bpy.ops.wiresculpt.optimize() == {'FINISHED'}
    wires = [o for o in bpy.context.scene.objects if o.type == 'CURVE']
    with open("/proc/self/maps") as f:
        mapped = sorted({line.split()[-1] for line in f if "/" in line.split()[-1]})
    solver = [p for p in mapped if os.path.basename(p).startswith(("libglpk", "libnlopt", "libserialport", "_wiresculpt"))]
    print("LOADED", *solver)
    print("WIRES", len(wires))
""")

GLIBC = {"ld-linux-x86-64.so.2", "libc.so.6", "libm.so.6", "libpthread.so.0", "libdl.so.2", "librt.so.1"}


def readelf(path):
    """(NEEDED entries, RUNPATH/RPATH) of an ELF file, parsed from readelf -d."""
    out = subprocess.run(["readelf", "-d", path], capture_output=True, text=True, check=True).stdout
    return (re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out),
            re.findall(r"\((?:RUNPATH|RPATH)\)\s+Library (?:runpath|rpath): \[([^\]]+)\]", out))


def make_zip(folder):
    made = subprocess.run(["/usr/bin/python3.11", os.path.join(ROOT, "scripts", "package.py"), folder],
                          capture_output=True, text=True)
    if made.returncode != 0:
        raise AssertionError(made.stderr)
    return made.stdout.strip()


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

    def test_zip_carries_its_solver(self):
        """Every NEEDED entry of every ELF file in the zip is in the zip or glibc; installed into a
        fresh user folder and run with LD_LIBRARY_PATH cleared, the add-on loads GLPK, NLopt and
        libserialport from its own folder (not the system's) and optimizes the globe."""
        with tempfile.TemporaryDirectory() as tmp:
            zip_path = make_zip(tmp)
            unpacked = os.path.join(tmp, "unpacked")
            shutil.unpack_archive(zip_path, unpacked)
            libs = os.path.join(unpacked, "wiresculpt", "libs")
            bundled = set(os.listdir(libs))
            for name in ("libglpk", "libnlopt", "libserialport"):
                self.assertTrue(any(b.startswith(name + ".so") or b.startswith(name + "_cxx.so") for b in bundled),
                                f"{name} is not bundled: {sorted(bundled)}")
            elves = [os.path.join(d, n) for d, _s, files in os.walk(unpacked) for n in files if ".so" in n]
            self.assertGreater(len(elves), 3)
            for path in elves:
                entries, runpaths = readelf(path)
                outside = [n for n in entries if n not in bundled and n not in GLIBC]
                self.assertEqual(outside, [], f"{os.path.relpath(path, unpacked)} needs libraries outside the zip")
                self.assertTrue(runpaths and runpaths[0].startswith("$ORIGIN"), f"{path}: run path {runpaths}")
            user = os.path.join(tmp, "user")
            script = os.path.join(tmp, "optimize.py")
            with open(script, "w") as f:
                f.write(OPTIMIZE)
            env = {k: v for k, v in os.environ.items() if k != "LD_LIBRARY_PATH"}
            env["BLENDER_USER_SCRIPTS"] = user
            cmd = [BLENDER, "--background",
                   "--factory-startup", "--python-exit-code", "1", "--python", script, "--", zip_path, user,
                   os.path.join(ROOT, "scripts", "examples", "globe", "globe.obj")]
            r = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=env)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            loaded = next(line for line in r.stdout.splitlines() if line.startswith("LOADED")).split()[1:]
            for name in ("libglpk", "libnlopt", "libserialport", "_wiresculpt"):
                paths = [p for p in loaded if os.path.basename(p).startswith(name)]
                self.assertTrue(paths, f"{name} was not loaded: {loaded}")
                for p in paths:
                    self.assertTrue(p.startswith(user), f"{name} came from {p}, not from the installed add-on")
            wires = int(next(line for line in r.stdout.splitlines() if line.startswith("WIRES")).split()[1])
            self.assertGreaterEqual(wires, 3)


class LoadErrorTest(unittest.TestCase):
    """A real failed import, made in a copy of the zip, turned into the sentence the panel shows."""

    def load_error(self, folder):
        code = "import wiresculpt.native as n; print(n.LOAD_ERROR)"
        r = subprocess.run(["/usr/bin/python3.11", "-c", code], capture_output=True, text=True,
                           env={**os.environ, "PYTHONPATH": folder}, cwd=folder)
        self.assertEqual(r.returncode, 0, r.stderr)
        return r.stdout.strip()

    def test_other_python_and_missing_library(self):
        with tempfile.TemporaryDirectory() as tmp:
            zip_path = make_zip(tmp)
            folder = os.path.join(tmp, "unpacked")
            shutil.unpack_archive(zip_path, folder)
            package = os.path.join(folder, "wiresculpt")
            module = next(n for n in os.listdir(package) if n.startswith("_wiresculpt"))
            self.assertEqual(self.load_error(folder), "")
            # the module's NEEDED entry for GLPK renamed to a library that exists nowhere
            glpk = next(n for n in readelf(os.path.join(package, module))[0] if n.startswith("libglpk"))
            subprocess.run(["patchelf", "--replace-needed", glpk, "libglpk_gone.so.40", os.path.join(package, module)],
                           check=True)
            message = self.load_error(folder)
            self.assertIn("libglpk_gone.so.40 is missing", message)
            self.assertIn("install the zip again", message)
            # the same module named for Python 3.10: Python 3.11 does not import it
            os.rename(os.path.join(package, module), os.path.join(package, "_wiresculpt.cpython-310-x86_64-linux-gnu.so"))
            message = self.load_error(folder)
            self.assertIn("this build is for Python 3.10; this Python uses 3.11", message)
            self.assertIn("build from source with scripts/package", message)


if __name__ == "__main__":
    unittest.main()
