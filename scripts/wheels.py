"""The solver as Python wheels, and one Blender extension zip per platform made of them.

    wheels.py [OUT]     (scripts/package runs it after package.py; OUT defaults to dist/)

writes, for each (platform, Python) it can build here:

- wheels/wiresculpt_solver-<version>-cp3XX-cp3XX-<platform>.whl: the package `wiresculpt_solver`
  holding `_wiresculpt` (the add-on's native.py imports it from there when the module is not beside
  it, as in an extension zip made of wheels, which Blender installs into the extension's own
  site-packages);
  * linux x86_64, cp311 and cp313: the modules scripts/package builds (the default build's, and
    package_pythons.py's for 3.13), with GLPK, NLopt, libserialport and what they need copied into
    wiresculpt_solver/libs/ with $ORIGIN run paths (package.bundle). The platform tag is
    manylinux_2_<N>_x86_64 with N the newest glibc symbol version any file of the wheel needs
    (read with readelf), so pip and Blender refuse it on an older glibc; `auditwheel show` (PyPI's
    auditwheel, AUDITWHEEL, in a venv under ~/.cache/wiresculpt) must find the wheel consistent with
    that very tag, or no wheel is written (WIRESCULPT_AUDITWHEEL=0 skips the check). Built on
    Debian 12 the tag is manylinux_2_36: the bundled libstdc++ (GCC 12) needs arc4random@GLIBC_2.36,
    the module hypot@GLIBC_2.35 and glibc 2.34's pthread symbols; a lower tag needs an older glibc
    to build on;
  * win_amd64, cp311 and cp313: scripts/windows.py's cross-built .pyd files (everything static;
    windows.module refuses one that imports a DLL other than Windows' own and pythonXY.dll);
- wiresculpt-extension-<version>-windows-x64.zip: the extension for Blender 4.2+ on Windows, the
  add-on's Python files with the wheels in wheels/, its blender_manifest.toml listing them under
  `wheels` and `platforms = ["windows-x64"]` (the Linux extension zip stays package.py's, with
  the modules beside the add-on's files).

- macOS arm64 and x86_64 (macosx_11_0), cp311 and cp313, UNTESTED: scripts/macos.py's modules,
  cross-built with zig (nothing of them has run on a Mac), and wiresculpt-extension-<version>-
  macos-arm64.zip / -macos-x64.zip made of them.

WIRESCULPT_WINDOWS=0 leaves Windows out (no Wine, MinGW or downloads needed then), WIRESCULPT_MACOS=0
macOS (no zig).
"""
import base64
import csv
import hashlib
import io
import os
import re
import subprocess
import sys
import tempfile
import zipfile

import package
import windows

ROOT = package.ROOT
PACKAGE = "wiresculpt_solver"
PYTHONS = ("3.11", "3.13")
AUDITWHEEL = "6.8.2"  # PyPI's auditwheel, in its own venv under the cache (auditwheel_tool)


def auditwheel_tool():
    """The auditwheel command, installed once into ~/.cache/wiresculpt/auditwheel-<version>/."""
    venv = os.path.join(os.path.dirname(windows.CACHE), f"auditwheel-{AUDITWHEEL}")
    tool = os.path.join(venv, "bin", "auditwheel")
    if not os.path.isfile(os.path.join(venv, ".complete")):
        import shutil
        shutil.rmtree(venv, ignore_errors=True)
        subprocess.run([windows.HOST_PYTHON, "-m", "venv", venv], check=True)
        subprocess.run([os.path.join(venv, "bin", "python"), "-m", "pip", "install", "-q", "--disable-pip-version-check",
                        f"auditwheel=={AUDITWHEEL}"], check=True)
        open(os.path.join(venv, ".complete"), "w").close()
    return tool


def audited_tag(wheel):
    """(the platform tag `auditwheel show` finds the wheel consistent with, or None; its whole
    output). auditwheel reads every ELF file's needed libraries and versioned symbols against the
    manylinux policies, independently of glibc_floor."""
    r = subprocess.run([auditwheel_tool(), "show", wheel], capture_output=True, text=True)
    text = " ".join((r.stdout + r.stderr).split())  # it wraps its lines
    m = re.search(r'consistent with the following platform tag: "([^"]+)"', text)
    return (m.group(1) if m and r.returncode == 0 else None), r.stdout + r.stderr


def glibc_floor(paths):
    """The newest GLIBC_2.N symbol version the ELF files need, as (2, N)."""
    newest = (2, 17)
    for path in paths:
        out = subprocess.run(["readelf", "-V", "-W", path], capture_output=True, text=True, check=True).stdout
        for major, minor in re.findall(r"Name: GLIBC_(\d+)\.(\d+)", out):
            newest = max(newest, (int(major), int(minor)))
    return newest


def record_line(arcname, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return [arcname, f"sha256={digest}", str(len(data))]


def write_wheel(out_dir, version, python_tag, platform_tag, files):
    """The wheel holding `files` [(path on disk, path inside wiresculpt_solver/)]; returns its path."""
    name = f"{PACKAGE}-{version}-{python_tag}-{python_tag}-{platform_tag}.whl"
    path = os.path.join(out_dir, name)
    info = f"{PACKAGE}-{version}.dist-info"
    entries = [(f"{PACKAGE}/__init__.py",
                b'"""The wiresculpt solver (_wiresculpt), as the wiresculpt Blender extension installs it."""\n')]
    for full, rel in files:
        with open(full, "rb") as f:
            entries.append((f"{PACKAGE}/{rel}", f.read()))
    entries.append((f"{info}/METADATA", (
        f"Metadata-Version: 2.1\nName: {PACKAGE}\nVersion: {version}\n"
        "Summary: The compiled solver of the wiresculpt Blender add-on (GLPK, NLopt inside)\n"
        "License: GPL-3.0-or-later\n"
        f"Requires-Python: =={python_tag[2]}.{python_tag[3:]}.*\n").encode()))
    entries.append((f"{info}/WHEEL", (
        "Wheel-Version: 1.0\nGenerator: wiresculpt scripts/wheels.py\nRoot-Is-Purelib: false\n"
        f"Tag: {python_tag}-{python_tag}-{platform_tag}\n").encode()))
    rows = [record_line(arc, data) for arc, data in entries] + [[f"{info}/RECORD", "", ""]]
    text = io.StringIO()
    csv.writer(text, lineterminator="\n").writerows(rows)
    entries.append((f"{info}/RECORD", text.getvalue().encode()))
    tmp = path + ".tmp"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for arc, data in entries:
            info_entry = zipfile.ZipInfo(arc, date_time=(2026, 1, 1, 0, 0, 0))
            info_entry.external_attr = (0o755 if arc.endswith((".so", ".pyd")) or ".so." in arc else 0o644) << 16
            info_entry.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info_entry, data)
    os.replace(tmp, path)
    return path


def linux_wheels(out_dir, version):
    made = []
    for module in package.modules():
        m = re.match(r"_wiresculpt\.cpython-(\d)(\d+)", os.path.basename(module))
        minor = f"{m.group(1)}.{m.group(2)}"
        if minor not in PYTHONS:
            continue
        with tempfile.TemporaryDirectory() as stage:
            staged = package.bundle(module, stage)
            floor = glibc_floor(staged)
            files = [(p, os.path.relpath(p, stage)) for p in staged]
            tag = f"manylinux_{floor[0]}_{floor[1]}_x86_64"
            wheel = write_wheel(out_dir, version, f"cp{m.group(1)}{m.group(2)}", tag, files)
        if os.environ.get("WIRESCULPT_AUDITWHEEL", "1") != "0":
            found, text = audited_tag(wheel)
            if found != tag:
                os.remove(wheel)
                raise SystemExit(f"wiresculpt: auditwheel finds {os.path.basename(wheel)} consistent with "
                                 f"{found or 'no manylinux tag'}, not {tag}:\n{text}")
        made.append(wheel)
    return made


def windows_wheels(out_dir, version):
    made = []
    for minor in PYTHONS:
        pyd = windows.module(minor)
        made.append(write_wheel(out_dir, version, "cp" + minor.replace(".", ""), "win_amd64",
                                [(pyd, os.path.basename(pyd))]))
    return made


def macos_wheels(out_dir, version):
    """UNTESTED (nothing of it has run on a Mac): the macOS wheels scripts/macos.py cross-builds."""
    import macos

    made = {}
    for arch in macos.ARCHS:
        made[arch] = []
        for minor in PYTHONS:
            so = macos.module(arch, minor)
            made[arch].append(write_wheel(out_dir, version, "cp" + minor.replace(".", ""), macos.WHEEL_TAG[arch],
                                          [(so, os.path.basename(so))]))
    return made


def manifest_for(platform, wheels):
    """The add-on's blender_manifest.toml for one platform's extension zip made of `wheels`."""
    with open(os.path.join(package.ADDON, "blender_manifest.toml"), encoding="utf-8") as f:
        text = f.read()
    listed = ", ".join(f'"./wheels/{os.path.basename(w)}"' for w in wheels)
    text, n = re.subn(r"^platforms = .*$", f'platforms = ["{platform}"]\nwheels = [{listed}]', text, flags=re.M)
    if n != 1:
        raise SystemExit("wiresculpt: blender_manifest.toml has no platforms line to replace")
    return text


def extension_zip(out_dir, version, platform, wheels):
    """The extension zip of `platform` ("windows-x64"): the add-on's Python files (no module) with
    `wheels` in wheels/ and a manifest listing them."""
    path = os.path.join(out_dir, f"wiresculpt-extension-{version}-{platform}.zip")
    with tempfile.TemporaryDirectory() as stage:
        files = [(full, rel) for full, rel in package.addon_files([], stage) if rel != "blender_manifest.toml"]
        manifest = os.path.join(stage, "blender_manifest.toml")
        with open(manifest, "w", encoding="utf-8") as f:
            f.write(manifest_for(platform, wheels))
        files.append((manifest, "blender_manifest.toml"))
        files += [(w, "wheels/" + os.path.basename(w)) for w in wheels]
        package.write_zip(path, "", files)
    return path


def main(out_dir):
    found = package.versions()
    if len(set(found.values())) != 1:
        raise SystemExit("wiresculpt: versions disagree: " + ", ".join(f"{k} {v}" for k, v in found.items()))
    version = found["CMakeLists.txt"]
    wheel_dir = os.path.join(out_dir, "wheels")
    os.makedirs(wheel_dir, exist_ok=True)
    written = linux_wheels(wheel_dir, version)
    if os.environ.get("WIRESCULPT_WINDOWS", "1") != "0":
        win = windows_wheels(wheel_dir, version)
        written += win + [extension_zip(out_dir, version, "windows-x64", win)]
    if os.environ.get("WIRESCULPT_MACOS", "1") != "0":
        for arch, made in macos_wheels(wheel_dir, version).items():
            platform = {"aarch64": "macos-arm64", "x86_64": "macos-x64"}[arch]
            written += made + [extension_zip(out_dir, version, platform, made)]
    return written


if __name__ == "__main__":
    for p in main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "dist")):
        print(p)
