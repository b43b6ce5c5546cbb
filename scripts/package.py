"""Builds two zips in dist/, each with the compiled module inside:

- wiresculpt-<version>-linux-x86_64.zip: the add-on folder, for Preferences > Add-ons > Install
  (Blender 3.4 to 4.1, and 4.2+ as a legacy add-on);
- wiresculpt-<version>-linux_x64.zip: the extension (Blender 4.2+, Install from Disk or
  `blender --command extension install-file`): blender_manifest.toml and the package's files at
  the top of the zip, as Blender's own `extension build` lays them out.

The version is declared in three places Blender and CMake each read; this refuses to package
when they disagree.
"""
import ast
import os
import re
import sys
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


def addon_files():
    """(path on disk, path inside the add-on folder) of every file that ships."""
    for folder, dirs, files in os.walk(ADDON):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for name in sorted(files):
            if name.endswith((".py", ".toml", ".so")):
                full = os.path.join(folder, name)
                yield full, os.path.relpath(full, ADDON)


def write_zip(path, prefix):
    tmp = path + ".tmp"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for full, rel in addon_files():
            z.write(full, os.path.join(prefix, rel))
    os.replace(tmp, path)


def package(out_dir):
    """[the add-on zip, the extension zip]."""
    found = versions()
    if len(set(found.values())) != 1:
        raise SystemExit("wiresculpt: versions disagree: " + ", ".join(f"{k} {v}" for k, v in found.items()))
    version = found["CMakeLists.txt"]
    modules = [n for n in os.listdir(ADDON) if n.startswith("_wiresculpt") and n.endswith(".so")]
    if not modules:
        raise SystemExit("wiresculpt: the compiled module is missing; run scripts/build first")
    os.makedirs(out_dir, exist_ok=True)
    addon_zip = os.path.join(out_dir, f"wiresculpt-{version}-linux-x86_64.zip")
    write_zip(addon_zip, "wiresculpt")
    extension_zip = os.path.join(out_dir, f"wiresculpt-{version}-linux_x64.zip")
    write_zip(extension_zip, "")
    return [addon_zip, extension_zip]


if __name__ == "__main__":
    for path in package(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "dist")):
        print(path)
