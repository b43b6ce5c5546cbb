"""Builds dist/wiresculpt-<version>-linux-x86_64.zip: the add-on folder with the compiled module,
installable through Blender's Preferences > Add-ons > Install (3.4+) and as an extension (4.2+).

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
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for folder, dirs, files in os.walk(ADDON):
            dirs[:] = sorted(d for d in dirs if d != "__pycache__")
            for name in sorted(files):
                if name.endswith((".py", ".toml", ".so")):
                    full = os.path.join(folder, name)
                    z.write(full, os.path.join("wiresculpt", os.path.relpath(full, ADDON)))
    os.replace(tmp, path)
    return path


if __name__ == "__main__":
    print(package(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "dist")))
