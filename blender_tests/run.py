"""Runs the add-on's Python test suites and prints one closing line `LABEL: N passed, N failed`,
exiting non-zero on any failure.

Inside Blender, the suites that need it (blender_tests/test_*.py):

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py [-- PATTERN...]

With the system Python 3.11 (the one Blender embeds), the bpy-free suites (blender_tests/pure/test_*.py):

    /usr/bin/python3.11 blender_tests/run.py pure [PATTERN...]

With a Python that has the PyPI `bpy` (Blender as a module; scripts/test makes one venv per
pinned version), the same Blender suites against that Blender:

    VENV/bin/python blender_tests/run.py bpy [PATTERN...]

There the tests that start a blender process or need a window are skipped (the module has neither);
each reason is printed once with its count. The closing label is `bpy VERSION`. When that Python is
not the default build's (bpy 5.1+ is Python 3.13), WIRESCULPT_MODULE names the module built for it
(scripts/package_pythons.py, as scripts/test does), loaded as the add-on's own `_wiresculpt`.

With the system Python 3.11, the Windows suites (blender_tests/windows/test_*.py: the win_amd64
module under Wine, scripts/windows.py; `scripts/test --windows`):

    /usr/bin/python3.11 blender_tests/run.py windows [PATTERN...]

Only the modules whose names contain a PATTERN run when patterns are given.
"""
import os
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def preload_module(path):
    """Loads the compiled module at `path` as wiresculpt._wiresculpt before the add-on imports it, so
    the add-on's `from . import _wiresculpt` finds it (a module built outside the source tree for
    another Python)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("wiresculpt._wiresculpt", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    sys.modules["wiresculpt._wiresculpt"] = module


def native_missing():
    """A sentence when the compiled solver cannot load: the suites that need it would only be
    skipped, so the run counts it as a failure instead of passing quietly."""
    from wiresculpt import native

    return "" if native.available() else native.LOAD_ERROR


def bpy_module():
    """Imports the PyPI bpy (before anything else touches Blender), marks the suites' helpers
    so the tests needing the blender executable or a window skip, and returns the label."""
    try:
        import bpy
    except ImportError as exc:
        sys.exit(f"bpy: this Python ({sys.executable}) has no bpy module: {exc}")
    import helpers

    helpers.BPY_MODULE = True
    return "bpy " + ".".join(map(str, bpy.app.version))


def main():
    inside_blender = "bpy" in sys.modules
    if "--" in sys.argv:
        argv = sys.argv[sys.argv.index("--") + 1:]
    else:
        argv = [] if inside_blender else sys.argv[1:]
    mode = argv[0] if argv and argv[0] in ("pure", "bpy", "windows") else ""
    if mode:
        argv = argv[1:]
    label, folder = (mode, os.path.join(HERE, mode)) if mode in ("pure", "windows") else ("blender", HERE)
    for path in (folder, HERE, os.path.join(ROOT, "addon"), os.path.join(ROOT, "scripts")):
        if path not in sys.path:
            sys.path.insert(0, path)
    if mode == "bpy":
        label = bpy_module()
    if os.environ.get("WIRESCULPT_MODULE"):
        preload_module(os.environ["WIRESCULPT_MODULE"])
    missing = native_missing()
    if missing:
        print(f"{label}: the solver is missing: {missing}")
    loader = unittest.TestLoader()
    suite = unittest.TestSuite()
    for name in sorted(os.listdir(folder)):
        if not (name.startswith("test_") and name.endswith(".py")):
            continue
        module = name[:-3]
        if argv and not any(p in module for p in argv):
            continue
        suite.addTests(loader.loadTestsFromName(module))
    result = unittest.TextTestRunner(stream=sys.stdout, verbosity=2).run(suite)
    failed = len(result.failures) + len(result.errors) + len(result.unexpectedSuccesses) + bool(missing)
    skipped = len(result.skipped)
    reasons = {}
    for _test, reason in result.skipped:
        reasons[reason] = reasons.get(reason, 0) + 1
    if mode == "bpy":  # the per-test lines above say it too; this is the summary, once a reason
        for reason, n in sorted(reasons.items()):
            print(f"{label}: {n} skipped: {reason}")
    passed = max(0, result.testsRun - failed - skipped)  # a failed setUpClass is not a test run
    sys.stdout.flush()
    print(f"{label}: {passed} passed, {failed} failed, {skipped} skipped" if skipped
          else f"{label}: {passed} passed, {failed} failed")
    sys.stdout.flush()
    code = 1 if failed or result.testsRun == 0 else 0
    if mode == "bpy":
        # The PyPI bpy (4.2 and later) crashes while Python shuts down once a scene PropertyGroup
        # has a dynamic EnumProperty (items=callback), ours or not (a 7-line script does it); the
        # results are all written, so leave without the interpreter's teardown.
        sys.stderr.flush()
        os._exit(code)
    if code:
        sys.exit(1)


main()
