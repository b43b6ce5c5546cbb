"""Builds two zips in dist/, each with the compiled module inside:

- wiresculpt-addon-<version>-linux-x86_64.zip: the add-on folder, for Preferences > Add-ons >
  Install (Blender 3.4 to 4.1, and 4.2+ as a legacy add-on);
- wiresculpt-extension-<version>-linux-x64.zip: the extension (Blender 4.2+, Install from Disk or
  `blender --command extension install-file`): blender_manifest.toml and the package's files at
  the top of the zip, as Blender's own `extension build` lays them out.

The wrong zip explains itself: Blender's legacy Add-ons > Install extracts a zip into
scripts/addons/ as it is and lists as new add-ons the top-level .py files and folders whose code
has a `bl_info` (never a top-level __init__.py). The extension zip's files are at its top, so only
WRONG_ZIP_MODULE, a top-level module the extension itself never imports, is listed: its bl_info
says in the add-on list which zip to use, and enabling it fails with that sentence, naming what the
zip put into the add-ons folder, and does nothing else.

Both zips carry the module for every Python the machine has (package_pythons.py: each CPython 3.x
from 3.10 with its development headers; the default build's module, scripts/build with
/usr/bin/python3.11, plus one build per further Python), so one zip loads in each Blender whose
Python is among them: Python picks the file whose ABI tag (_wiresculpt.cpython-310-...so) is its
own.

Both zips carry their own solver: every shared library the module needs (GLPK, NLopt,
libserialport and what they need in turn: GMP, zlib, SuiteSparse, libltdl, the C++ runtime) is
copied into libs/ beside the modules (one folder they share) (wiresculpt/libs/ in the add-on zip, libs/ at the top of the
extension zip) and every copy, and each module, gets an `$ORIGIN` run path (patchelf), so the only
outside needs left are glibc and the Python that loads the module. The package is refused
when a NEEDED entry of any bundled file is neither bundled nor part of glibc.

The version is declared in three places Blender and CMake each read; this refuses to package
when they disagree.
"""
import ast
import os
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile

import package_pythons

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ADDON = os.path.join(ROOT, "addon", "wiresculpt")


def versions():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        cmake = re.search(r"project\(wiresculpt VERSION ([0-9.]+)", f.read()).group(1)
    with open(os.path.join(ADDON, "blender_manifest.toml"), encoding="utf-8") as f:
        manifest = re.search(r'^version = "([0-9.]+)"', f.read(), re.M).group(1)
    with open(os.path.join(ADDON, "__init__.py"), encoding="utf-8") as f:
        tree = ast.parse(f.read())
    bl_info = next(ast.literal_eval(n.value) for n in tree.body
                   if isinstance(n, ast.Assign) and getattr(n.targets[0], "id", "") == "bl_info")
    return {"CMakeLists.txt": cmake, "blender_manifest.toml": manifest,
            "bl_info": ".".join(str(x) for x in bl_info["version"])}


# Part of glibc (and the kernel's vDSO): every Linux system has them, and a copy must never be
# loaded beside the system's own.
GLIBC = {"linux-vdso.so.1", "ld-linux-x86-64.so.2", "libc.so.6", "libm.so.6", "libpthread.so.0",
         "libdl.so.2", "librt.so.1", "libutil.so.1", "libresolv.so.2", "libmvec.so.1"}
LIBS = "libs"  # the folder inside the add-on holding the bundled libraries
WRONG_ZIP_MODULE = "wiresculpt_extension_zip.py"  # the extension zip's explanation to a legacy install


def zip_names(version):
    """(add-on zip name, extension zip name): the kind in the name, and each platform as its
    installer spells it (the extension's as blender_manifest.toml's platforms, linux-x64)."""
    return f"wiresculpt-addon-{version}-linux-x86_64.zip", f"wiresculpt-extension-{version}-linux-x64.zip"


def wrong_zip_module(version, sprayed):
    """The source of WRONG_ZIP_MODULE for this version; `sprayed`: the zip's other top-level names
    (what a legacy install puts into scripts/addons/)."""
    addon_zip, _extension_zip = zip_names(version)
    message = (f"This is the wiresculpt extension zip, for Blender 4.2 and later (Preferences > Get Extensions > "
               f"Install from Disk). On Blender 3.4 to 4.1 install {addon_zip} through Preferences > Add-ons > "
               f"Install instead. Installing this zip as a legacy add-on put these into the add-ons folder, "
               f"which can be deleted: {', '.join(sprayed)}, {WRONG_ZIP_MODULE}")
    major, minor, patch = (int(x) for x in version.split("."))
    return f'''# SPDX-License-Identifier: GPL-3.0-or-later
"""Written by scripts/package.py into the wiresculpt extension zip only: the extension never
imports it. Installed as a legacy add-on (Blender 3.4 to 4.1, or 4.2+'s Install legacy Add-on),
the zip's files land in scripts/addons/ and this is the one add-on Blender lists: it says which zip
to use, and enabling it does nothing but fail with that sentence."""

MESSAGE = {message!r}

bl_info = {{
    "name": "wiresculpt: wrong zip (the Blender 4.2+ extension)",
    "author": "wiresculpt developers",
    "version": ({major}, {minor}, {patch}),
    "blender": (2, 80, 0),
    "location": "Preferences > Add-ons > Install: use {addon_zip}",
    "description": "This is the Blender 4.2+ extension zip; on Blender 3.4 to 4.1 install {addon_zip}",
    "warning": "Wrong zip for a legacy install: use {addon_zip}",
    "doc_url": "",
    "category": "Object",
}}


def register():
    print("wiresculpt:", MESSAGE)
    raise RuntimeError(MESSAGE)


def unregister():
    pass
'''


def needed(path):
    """The NEEDED entries of an ELF file, read with readelf."""
    out = subprocess.run(["readelf", "-d", path], capture_output=True, text=True, check=True).stdout
    return re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out)


def dependencies(module):
    """{soname: path} of every library the module loads (the whole closure, from ldd) that is not
    glibc; SystemExit naming a library the loader cannot find."""
    out = subprocess.run(["ldd", module], capture_output=True, text=True, check=True).stdout
    found = {}
    for line in out.splitlines():
        m = re.match(r"\s*(\S+)\s+=>\s+(\S+)", line)
        if not m or m.group(1) in GLIBC or os.path.basename(m.group(1)) in GLIBC:
            continue
        if m.group(2) == "not":
            raise SystemExit(f"wiresculpt: {module} needs {m.group(1)}, which the loader cannot find")
        found[m.group(1)] = os.path.realpath(m.group(2))
    return found


def bundle(module, stage):
    """Copies `module` and its libraries into `stage` (module at the top, libraries in libs/) with
    $ORIGIN run paths; returns the staged files. SystemExit when a NEEDED entry stays unresolved."""
    libs = os.path.join(stage, LIBS)
    os.makedirs(libs, exist_ok=True)
    staged_module = os.path.join(stage, os.path.basename(module))
    shutil.copy2(module, staged_module)
    staged = [staged_module]
    for soname, path in sorted(dependencies(module).items()):
        target = os.path.join(libs, soname)
        shutil.copy2(path, target)
        os.chmod(target, 0o755)
        subprocess.run(["patchelf", "--set-rpath", "$ORIGIN", target], check=True)
        staged.append(target)
    subprocess.run(["patchelf", "--set-rpath", "$ORIGIN/" + LIBS, staged_module], check=True)
    bundled = set(os.listdir(libs))
    for path in staged:
        missing = [n for n in needed(path) if n not in bundled and n not in GLIBC]
        if missing:
            raise SystemExit(f"wiresculpt: {os.path.basename(path)} needs {', '.join(missing)}, "
                             "which is neither bundled nor part of glibc")
    return staged


def addon_files(modules, stage):
    """(path on disk, path inside the add-on folder) of every file that ships: the Python and TOML
    files, then each compiled module (a path) with its libraries as bundle() stages them in
    `stage` (one libs/ for all)."""
    files = []
    for folder, dirs, names in os.walk(ADDON):
        dirs[:] = sorted(d for d in dirs if d not in ("__pycache__", LIBS))
        for name in sorted(names):
            if name.endswith((".py", ".toml")):
                full = os.path.join(folder, name)
                files.append((full, os.path.relpath(full, ADDON)))
    staged = {}
    for module in sorted(modules):
        for full in bundle(module, stage):
            staged[full] = os.path.relpath(full, stage)  # a library every module needs ships once
    return files + sorted(staged.items(), key=lambda item: item[1])


def write_zip(path, prefix, files):
    """The zip at `path` (atomically) holding `files` under the folder `prefix` ("" for the top)."""
    tmp = path + ".tmp"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for full, rel in files:
            z.write(full, os.path.join(prefix, rel))
    os.replace(tmp, path)


def toolchain():
    """(the default build's Python, CMake, the default build folder, the folder of
    pybind11Config.cmake for the further Pythons) as scripts/lib.sh names and installs them."""
    out = subprocess.run(["bash", "-c", 'source "$1"; printf "%s\\n" "$PYTHON" "$CMAKE" "$BUILD_DIR" "$(package_pybind11)"',
                          "bash", os.path.join(ROOT, "scripts", "lib.sh")],
                         capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit("wiresculpt: scripts/lib.sh could not install pybind11 for the package: " + out.stderr)
    return out.stdout.split("\n")[:4]


def modules():
    """Every compiled module to ship: the default build's (in the add-on folder, for its Python),
    then one per further Python (package_pythons)."""
    default = [os.path.join(ADDON, n) for n in os.listdir(ADDON) if n.startswith("_wiresculpt") and n.endswith(".so")]
    if not default:
        raise SystemExit("wiresculpt: the compiled module is missing; run scripts/build first")
    python, cmake, build_dir, pybind11_dir = toolchain()
    core = os.path.join(build_dir, "native", "libwiresculpt_core.a")
    tag = re.match(r"_wiresculpt\.cpython-(\d)(\d+)", os.path.basename(default[0]))
    further = [package_pythons.build(p, v, suffix, cmake, pybind11_dir, core)
               for p, v, suffix in package_pythons.find(python, f"{tag.group(1)}.{tag.group(2)}")]
    return default + further


def package(out_dir):
    """[the add-on zip, the extension zip]."""
    found = versions()
    if len(set(found.values())) != 1:
        raise SystemExit("wiresculpt: versions disagree: " + ", ".join(f"{k} {v}" for k, v in found.items()))
    version = found["CMakeLists.txt"]
    os.makedirs(out_dir, exist_ok=True)
    addon_zip, extension_zip = (os.path.join(out_dir, name) for name in zip_names(version))
    with tempfile.TemporaryDirectory() as stage:
        files = addon_files(modules(), stage)
        write_zip(addon_zip, "wiresculpt", files)
        sprayed = sorted({rel.split(os.sep)[0] + ("/" if os.sep in rel else "") for _full, rel in files})
        explainer = os.path.join(stage, WRONG_ZIP_MODULE)
        with open(explainer, "w", encoding="utf-8") as f:
            f.write(wrong_zip_module(version, sprayed))
        write_zip(extension_zip, "", files + [(explainer, WRONG_ZIP_MODULE)])
    return [addon_zip, extension_zip]


if __name__ == "__main__":
    for path in package(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "dist")):
        print(path)
