"""The packaged zips: the add-on zip installs into a clean user scripts folder and loads its
compiled module (the Blender executable); both zips carry their own solver libraries and a module
for each Python the machine has, each of which imports with its own interpreter; a failed load
says what is wrong; the extension zip passes Blender's own manifest check, installs into a
temporary extension repository through Blender's extension API, enables and Optimizes the bundled
globe (Blender 4.2+, e.g. the PyPI bpy)."""
import glob
import json
import os
import re
import shutil
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
    model = objects[0]
    model.scale = (float(radius),) * 3
    bpy.context.view_layer.update()
    bpy.context.scene.wiresculpt.model = model
    for rotation in ((0, 0, 0), (0, math.pi / 2, 0), (math.pi / 2, 0, 0)):
        assert bpy.ops.wiresculpt.add_plane() == {'FINISHED'}
        bpy.context.view_layer.objects.active.rotation_euler = rotation
    assert bpy.ops.wiresculpt.slice() == {'FINISHED'}
    assert bpy.ops.wiresculpt.optimize() == {'FINISHED'}
    design = results.stored_design()
    assert design is not None and design["stable"], design and design["reason"]
    with open("/proc/self/maps") as f:  # the solver's libraries come from the extension's libs/
        mapped = {line.split()[-1] for line in f if "/" in line.split()[-1]}
    solver = [p for p in mapped if os.path.basename(p).startswith(("libglpk", "libnlopt", "libserialport"))]
    outside = [p for p in solver if not os.path.realpath(p).startswith(os.path.realpath(repo_dir))]
    assert solver and not outside, f"solver libraries loaded from outside the extension: {outside or 'none loaded'}"
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
    bpy.context.scene.wiresculpt.model = objects[0]
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

# The extension zip put through the legacy Add-ons > Install (Blender 3.4): which add-ons Blender
# lists as new, what they say, and what enabling them does.
WRONG_ZIP = textwrap.dedent("""
    import json, sys, addon_utils, bpy
    zip_path, user = sys.argv[sys.argv.index("--") + 1:]
    before = {m.__name__ for m in addon_utils.modules()}
    result = bpy.ops.preferences.addon_install(filepath=zip_path)
    new = sorted({m.__name__ for m in addon_utils.modules(refresh=False)} - before)
    infos = {m.__name__: addon_utils.module_bl_info(m) for m in addon_utils.modules(refresh=False) if m.__name__ in new}
    errors = []
    for name in new:
        addon_utils.enable(name, default_set=True, handle_error=lambda ex: errors.append(str(ex)))
    enabled = sorted(a.module for a in bpy.context.preferences.addons if a.module in new)
    print("WRONG-ZIP", json.dumps({"install": sorted(result), "new": new, "enabled": enabled, "errors": errors,
                                   "infos": {k: {f: v.get(f, "") for f in ("name", "description", "warning")}
                                             for k, v in infos.items()},
                                   "panel": hasattr(bpy.types, "VIEW3D_PT_wiresculpt")}))
""")

GLIBC = {"ld-linux-x86-64.so.2", "libc.so.6", "libm.so.6", "libpthread.so.0", "libdl.so.2", "librt.so.1"}


def readelf(path):
    """(NEEDED entries, RUNPATH/RPATH) of an ELF file, parsed from readelf -d."""
    out = subprocess.run(["readelf", "-d", path], capture_output=True, text=True, check=True).stdout
    return (re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out),
            re.findall(r"\((?:RUNPATH|RPATH)\)\s+Library (?:runpath|rpath): \[([^\]]+)\]", out))


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
            self.assertRegex(os.path.basename(zip_path), r"^wiresculpt-addon-\d+\.\d+\.\d+-linux-x86_64\.zip$")
            self.assertRegex(os.path.basename(_extension), r"^wiresculpt-extension-\d+\.\d+\.\d+-linux-x64\.zip$")
            user = os.path.join(tmp, "user")
            script = os.path.join(tmp, "check.py")
            with open(script, "w") as f:
                f.write(CHECK)
            r = run_blender(script, zip_path, user, env={"BLENDER_USER_SCRIPTS": user})
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            self.assertIn("PACKAGE-OK", r.stdout)

    def assert_carries_solver(self, zip_path, package_dir):
        """Every NEEDED entry of every ELF file in the zip is in the zip or glibc, GLPK, NLopt and
        libserialport are in `package_dir`/libs, and every ELF file has an $ORIGIN run path (the
        module's is $ORIGIN/libs). Returns (the unpacked folder, the unpacked package folder)."""
        unpacked = os.path.join(os.path.dirname(zip_path), "unpacked-" + os.path.basename(zip_path))
        shutil.unpack_archive(zip_path, unpacked)
        package_folder = os.path.join(unpacked, package_dir)
        bundled = set(os.listdir(os.path.join(package_folder, "libs")))
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
        modules = [n for n in os.listdir(package_folder) if n.startswith("_wiresculpt")]
        self.assertIn("_wiresculpt.cpython-311-x86_64-linux-gnu.so", modules)  # the default build's
        for module in modules:
            entries, runpaths = readelf(os.path.join(package_folder, module))
            self.assertEqual(runpaths, ["$ORIGIN/libs"], module)
            solver = [n for n in entries if re.match(r"lib(glpk|nlopt|serialport)", n)]
            self.assertEqual(len(solver), 3, f"{module} NEEDED: {entries}")
            self.assertEqual([n for n in solver if n not in bundled], [], f"{module} needs these outside the zip")
        return unpacked, package_folder

    def test_zip_carries_its_solver(self):
        """The add-on zip carries its solver (assert_carries_solver); installed into a fresh user
        folder and run with LD_LIBRARY_PATH cleared, the add-on loads GLPK, NLopt and libserialport
        from its own folder (not the system's) and optimizes the globe."""
        with tempfile.TemporaryDirectory() as tmp:
            zip_path, _extension = package(tmp)
            self.assert_carries_solver(zip_path, "wiresculpt")
            user = os.path.join(tmp, "user")
            script = os.path.join(tmp, "optimize.py")
            with open(script, "w") as f:
                f.write(OPTIMIZE)
            r = run_blender(script, zip_path, user, GLOBE_OBJ, timeout=600,
                            env={"LD_LIBRARY_PATH": None, "BLENDER_USER_SCRIPTS": user})
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            loaded = next(line for line in r.stdout.splitlines() if line.startswith("LOADED")).split()[1:]
            for name in ("libglpk", "libnlopt", "libserialport", "_wiresculpt"):
                paths = [p for p in loaded if os.path.basename(p).startswith(name)]
                self.assertTrue(paths, f"{name} was not loaded: {loaded}")
                for p in paths:
                    self.assertTrue(p.startswith(user), f"{name} came from {p}, not from the installed add-on")
            wires = int(next(line for line in r.stdout.splitlines() if line.startswith("WIRES")).split()[1])
            self.assertGreaterEqual(wires, 3)

    def test_the_extension_zip_explains_itself_to_a_legacy_install(self):
        """Blender 3.4's Add-ons > Install with the extension zip: Blender lists exactly
        one new add-on, whose name, description and warning say which zip to use; enabling it
        fails with the sentence naming the add-on zip, registers nothing of wiresculpt, and the
        add-on zip's name differs from the extension's by more than a platform spelling."""
        with tempfile.TemporaryDirectory() as tmp:
            addon_zip, extension_zip = package(tmp)
            addon_name = os.path.basename(addon_zip)
            self.assertIn("-addon-", addon_name)
            self.assertIn("-extension-", os.path.basename(extension_zip))
            user = os.path.join(tmp, "user")
            script = os.path.join(tmp, "wrong_zip.py")
            with open(script, "w") as f:
                f.write(WRONG_ZIP)
            r = run_blender(script, extension_zip, user, env={"BLENDER_USER_SCRIPTS": user})
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            seen = json.loads(next(line for line in r.stdout.splitlines()
                                   if line.startswith("WRONG-ZIP")).split(" ", 1)[1])
            self.assertEqual(seen["install"], ["FINISHED"])
            self.assertEqual(seen["new"], ["wiresculpt_extension_zip"], r.stdout)
            info = seen["infos"]["wiresculpt_extension_zip"]
            self.assertIn("wrong zip", info["name"])
            for field in ("description", "warning"):
                self.assertIn(addon_name, info[field])
            self.assertEqual(seen["enabled"], [])
            self.assertEqual(len(seen["errors"]), 1, seen["errors"])
            self.assertIn(addon_name, seen["errors"][0])
            self.assertIn("Blender 4.2", seen["errors"][0])
            self.assertFalse(seen["panel"])
            # what the zip put at the top of the add-ons folder is named for deleting
            for name in ("__init__.py", "core/", "libs/", "wiresculpt_extension_zip.py"):
                self.assertIn(name, seen["errors"][0])
                self.assertTrue(os.path.exists(os.path.join(user, "addons", name.rstrip("/"))), name)

    def test_extension_zip_carries_its_solver(self):
        """The extension zip, whose files sit at its top level, carries the same libraries in libs/
        with the same run paths."""
        with tempfile.TemporaryDirectory() as tmp:
            _addon, extension_zip = package(tmp)
            self.assert_carries_solver(extension_zip, "")


# Run by each Python the zip has a module for, in a subprocess with no LD_LIBRARY_PATH: imports the
# module from the unpacked add-on folder, strips a G-code text (the rule by hand: ';' to the end of
# the line and '(...)' are comments, blank lines go) and lists the solver libraries it mapped.
IMPORT = textwrap.dedent("""
    import json, os, sys
    folder = sys.argv[1]
    sys.path.insert(0, folder)
    import _wiresculpt as m
    lines = m.stream_lines("G21 ; millimetres\\n(pin down)\\n\\n  G1 X10 F300 (feed)\\n")
    with open("/proc/self/maps") as f:
        mapped = sorted({line.split()[-1] for line in f if "/" in line.split()[-1]})
    solver = [p for p in mapped if os.path.basename(p).startswith(("libglpk", "libnlopt", "libserialport"))]
    print(json.dumps({"file": m.__file__, "python": "%d.%d" % sys.version_info[:2], "lines": lines,
                      "solver": solver}))
""")


def interpreters(version):
    """The interpreters for Python `version` ("3.10") on this machine: the system's and pyenv's
    (a clean machine has /usr/bin/python3.11 and maybe no pyenv)."""
    pyenv = os.environ.get("PYENV_ROOT") or os.path.expanduser("~/.pyenv")
    found = [f"/usr/bin/python{version}", f"/usr/local/bin/python{version}"] + \
        sorted(glob.glob(os.path.join(pyenv, "versions", version + ".*", "bin", "python" + version)))
    return [p for p in found if os.access(p, os.X_OK)]


def has_headers(python):
    """Whether `python` has its development headers (Python.h in its sysconfig include folder)."""
    code = "import os, sysconfig; print(os.path.isfile(os.path.join(sysconfig.get_paths()['include'], 'Python.h')))"
    r = subprocess.run([python, "-I", "-c", code], capture_output=True, text=True)
    return r.stdout.strip() == "True"


class ModulePerPythonTest(unittest.TestCase):
    """The add-on zip has a module for each Python from 3.10 that has its headers on this machine
    (the system's 3.11 always; pyenv's 3.10, 3.12, 3.13 where they are installed, skipped with a
    message where not), and each module imports with its own interpreter from the unpacked folder
    with LD_LIBRARY_PATH cleared, its solver libraries coming from the zip's libs/."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        zip_path, _extension = package(cls.tmp.name)
        shutil.unpack_archive(zip_path, os.path.join(cls.tmp.name, "unpacked"))
        cls.folder = os.path.join(cls.tmp.name, "unpacked", "wiresculpt")
        tags = (re.match(r"_wiresculpt\.cpython-(\d)(\d+)-", n) for n in os.listdir(cls.folder))
        cls.versions = sorted(f"{t.group(1)}.{t.group(2)}" for t in tags if t)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_a_module_for_every_python_with_headers(self):
        missing, absent = [], []
        for version in ("3.10", "3.11", "3.12", "3.13"):
            pythons = [p for p in interpreters(version) if has_headers(p)]
            if not pythons:
                absent.append(version)
            elif version not in self.versions:
                missing.append(f"{version} ({pythons[0]})")
        self.assertNotIn("3.11", absent, "/usr/bin/python3.11 with its headers is always there")
        self.assertEqual(missing, [], f"the zip has modules for {self.versions} only")
        if absent:
            print(f"  no Python {', '.join(absent)} with headers on this machine: not required in the zip")

    def test_each_module_imports_with_its_own_python(self):
        skipped = []
        for version in self.versions:
            pythons = interpreters(version)
            if not pythons:
                skipped.append(version)
                continue
            with self.subTest(python=pythons[0]):
                r = subprocess.run([pythons[0], "-I", "-c", IMPORT, self.folder], capture_output=True, text=True,
                                   env={"PATH": "/usr/bin:/bin"}, timeout=120)
                self.assertEqual(r.returncode, 0, r.stderr)
                got = json.loads(r.stdout)
                self.assertEqual(got["python"], version)
                self.assertEqual(os.path.dirname(got["file"]), self.folder)
                self.assertIn(f"cpython-{version.replace('.', '')}-", os.path.basename(got["file"]))
                self.assertEqual(got["lines"], ["G21", "G1 X10 F300"])
                names = sorted({re.match(r"lib(glpk|nlopt|serialport)", os.path.basename(p)).group(1)
                                for p in got["solver"]})
                self.assertEqual(names, ["glpk", "nlopt", "serialport"], got["solver"])
                for path in got["solver"]:
                    self.assertEqual(os.path.dirname(path), os.path.join(self.folder, "libs"))
        if skipped:
            print(f"  no interpreter for Python {', '.join(skipped)} on this machine: its module not imported")
        self.assertGreater(len(self.versions) - len(skipped), 0)


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
            zip_path, _extension = package(tmp)
            folder = os.path.join(tmp, "unpacked")
            shutil.unpack_archive(zip_path, folder)
            addon = os.path.join(folder, "wiresculpt")
            module = "_wiresculpt.cpython-311-x86_64-linux-gnu.so"  # the one Python 3.11 imports
            for other in os.listdir(addon):
                if other.startswith("_wiresculpt") and other != module:
                    os.remove(os.path.join(addon, other))
            self.assertEqual(self.load_error(folder), "")
            # the module's NEEDED entry for GLPK renamed to a library that exists nowhere
            glpk = next(n for n in readelf(os.path.join(addon, module))[0] if n.startswith("libglpk"))
            subprocess.run(["patchelf", "--replace-needed", glpk, "libglpk_gone.so.40", os.path.join(addon, module)],
                           check=True)
            message = self.load_error(folder)
            self.assertIn("libglpk_gone.so.40 is missing", message)
            self.assertIn("install the zip again", message)
            # the same module named for Python 3.10: Python 3.11 does not import it
            os.rename(os.path.join(addon, module), os.path.join(addon, "_wiresculpt.cpython-310-x86_64-linux-gnu.so"))
            message = self.load_error(folder)
            self.assertIn("this zip has the solver for Python 3.10; this Python uses 3.11: install it in a "
                          "Blender whose Python is 3.10 (Blender 3.4 to 4.0)", message)
            self.assertIn("build the zip from source with scripts/package", message)


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
