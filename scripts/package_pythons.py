"""The Pythons scripts/package builds the solver module for, and that build.

Every CPython 3.x found on the machine (the system's /usr/bin/python3.*, /usr/local/bin/python3.*
and pyenv's versions) that has its development headers (Python.h in its sysconfig include
folder) and is at least MIN_PYTHON gets the module, each in a CMake build folder of its own under
build/package/ with its output kept there (the source tree keeps only the default build's module).
One interpreter per minor version: the first found wins, the default build's Python (the one the
tests use) first. Each one left out is named with the reason in one line on stderr.

WIRESCULPT_PACKAGE_PYTHONS (space-separated interpreter paths) replaces the search; set and empty,
only the default build's module is packaged.
"""
import glob
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD_ROOT = os.path.join(ROOT, "build", "package")

# The Python of the oldest Blender the add-on supports (bl_info: 3.4; Blender's own builds of 3.1
# to 4.0 embed Python 3.10). No older Python can load the add-on, so none is built for.
MIN_PYTHON = (3, 10)

# Printed by each candidate interpreter about itself.
PROBE = """
import json, os, sys, sysconfig
include = sysconfig.get_paths().get("include") or ""
print(json.dumps({"implementation": sys.implementation.name, "version": list(sys.version_info[:2]),
                  "include": include, "headers": os.path.isfile(os.path.join(include, "Python.h")),
                  "ext_suffix": sysconfig.get_config_var("EXT_SUFFIX") or ""}))
"""


def say(text):
    print("wiresculpt: " + text, file=sys.stderr, flush=True)


def candidates():
    """Interpreter paths to look at, in order, without duplicates of the same file."""
    listed = os.environ.get("WIRESCULPT_PACKAGE_PYTHONS")
    if listed is not None:
        paths = listed.split()
    else:
        pyenv = os.environ.get("PYENV_ROOT") or os.path.expanduser("~/.pyenv")
        paths = (sorted(glob.glob("/usr/bin/python3.[0-9]*")) + sorted(glob.glob("/usr/local/bin/python3.[0-9]*"))
                 + sorted(glob.glob(os.path.join(pyenv, "versions", "*", "bin", "python3"))))
    seen, out = set(), []
    for path in paths:
        if path.endswith("-config") or not os.access(path, os.X_OK):
            continue
        real = os.path.realpath(path)
        if real not in seen:
            seen.add(real)
            out.append(path)
    return out


def probe(python):
    """What `python` says about itself (PROBE), or a sentence saying why it could not be asked."""
    try:
        r = subprocess.run([python, "-I", "-c", PROBE], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return f"does not run ({exc})"
    if r.returncode != 0:
        return "does not run (" + (r.stderr.strip().splitlines() or ["exit %d" % r.returncode])[-1] + ")"
    return json.loads(r.stdout)


def find(default_python, default_version):
    """[(interpreter, "3.10", its extension suffix)] to build for, the default build's Python
    (default_version, e.g. "3.11") left out as already built; one line on stderr per interpreter
    skipped."""
    built = {default_version: default_python}
    found = []
    for python in candidates():
        if os.path.realpath(python) == os.path.realpath(default_python):
            continue
        info = probe(python)
        if isinstance(info, str):
            say(f"{python} {info}; skipped")
            continue
        version = "%d.%d" % tuple(info["version"])
        what = f"Python {version} at {python}"
        if info["implementation"] != "cpython":
            say(f"{what} is {info['implementation']}, not CPython; skipped")
        elif tuple(info["version"]) < MIN_PYTHON:
            say(f"{what} is older than {'.'.join(map(str, MIN_PYTHON))}, the Python of the oldest Blender "
                "the add-on supports; skipped")
        elif version in built:
            say(f"{what}: the module for {version} comes from {built[version]}; skipped")
        elif not info["headers"]:
            say(f"{what} has no development headers (no Python.h in {info['include'] or 'its include folder'}); skipped")
        else:
            built[version] = python
            found.append((python, version, info["ext_suffix"]))
    return found


def build(python, version, ext_suffix, cmake, pybind11_dir, core, jobs=2):
    """The module for `python`, built in build/package/py<version>/ with `pybind11_dir`'s pybind11
    against `core` (the default build's libwiresculpt_core.a: only the bindings are compiled per
    Python), rebuilt only when a source or the core changed; SystemExit naming the Python and the
    log when configure or build fails."""
    if not os.path.isfile(core):
        raise SystemExit(f"wiresculpt: {core} is missing; run scripts/build first")
    folder = os.path.join(BUILD_ROOT, "py" + version.replace(".", ""))
    out = os.path.join(folder, "module")
    os.makedirs(folder, exist_ok=True)
    log = os.path.join(folder, "build.log")
    with open(log, "w") as f:
        # configured every time (a second or two): the settings below always hold, even in a folder
        # an older checkout configured
        steps = [[cmake, "-S", ROOT, "-B", folder, "-DCMAKE_BUILD_TYPE=Release",
                  f"-DPython_EXECUTABLE={python}", f"-DWIRESCULPT_PYTHON_VERSION={version}",
                  f"-Dpybind11_DIR={pybind11_dir}", f"-DWIRESCULPT_MODULE_DIR={out}",
                  f"-DWIRESCULPT_CORE_LIBRARY={core}", "-DWIRESCULPT_BUILD_TESTS=OFF"],
                 [cmake, "--build", folder, "--target", "_wiresculpt", f"-j{jobs}"]]
        for step in steps:
            if subprocess.run(step, stdout=f, stderr=subprocess.STDOUT).returncode != 0:
                with open(log, errors="replace") as r:
                    sys.stderr.write("".join(r.readlines()[-30:]))
                raise SystemExit(f"wiresculpt: building the module for Python {version} ({python}) failed "
                                 f"(log: {log})")
    module = os.path.join(out, "_wiresculpt" + ext_suffix)
    if not os.path.isfile(module):
        raise SystemExit(f"wiresculpt: the build for Python {version} ({python}) made no {os.path.basename(module)}")
    return module


if __name__ == "__main__":
    # scripts/test: the module for one further Python (the bpy suites on a Blender whose Python is
    # not the default build's), printed as its path:
    #   package_pythons.py PYTHON CMAKE PYBIND11_DIR CORE
    python, cmake, pybind11_dir, core = sys.argv[1:5]
    info = probe(python)
    if isinstance(info, str):
        raise SystemExit(f"wiresculpt: {python} {info}")
    if not info["headers"]:
        raise SystemExit(f"wiresculpt: {python} has no development headers (no Python.h in {info['include']})")
    print(build(python, "%d.%d" % tuple(info["version"]), info["ext_suffix"], cmake, pybind11_dir, core))
