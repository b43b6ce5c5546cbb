"""Builds dist/wiresculpt-<version>-linux-x86_64.zip: the add-on folder with the compiled module,
installable through Blender's Preferences > Add-ons > Install (3.4+) and as an extension (4.2+).

The zip carries its own solver: every shared library the module needs (GLPK, NLopt, libserialport
and what they need in turn: GMP, zlib, SuiteSparse, libltdl, the C++ runtime) is copied into
wiresculpt/libs/ and every copy, and the module, gets an `$ORIGIN` run path (patchelf), so the
only outside needs left are glibc and the Python that loads the module. The package is refused
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


def package(out_dir):
    found = versions()
    if len(set(found.values())) != 1:
        raise SystemExit("wiresculpt: versions disagree: " + ", ".join(f"{k} {v}" for k, v in found.items()))
    version = found["CMakeLists.txt"]
    modules = [n for n in os.listdir(ADDON) if n.startswith("_wiresculpt") and n.endswith(".so")]
    if not modules:
        raise SystemExit("wiresculpt: the compiled module is missing; run scripts/build first")
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, f"wiresculpt-{version}-linux-x86_64.zip")
    tmp = path + ".tmp"
    with tempfile.TemporaryDirectory() as stage, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for folder, dirs, files in os.walk(ADDON):
            dirs[:] = sorted(d for d in dirs if d not in ("__pycache__", LIBS))
            for name in sorted(files):
                if name.endswith((".py", ".toml")):
                    full = os.path.join(folder, name)
                    z.write(full, os.path.join("wiresculpt", os.path.relpath(full, ADDON)))
        for name in sorted(modules):
            for full in bundle(os.path.join(ADDON, name), stage):
                z.write(full, os.path.join("wiresculpt", os.path.relpath(full, stage)))
    os.replace(tmp, path)
    return path


if __name__ == "__main__":
    print(package(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "dist")))
