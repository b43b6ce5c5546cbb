"""Runs the add-on's Python test suites and prints one closing line `LABEL: N passed, N failed`,
exiting non-zero on any failure.

Inside Blender, the suites that need it (blender_tests/test_*.py):

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py [-- PATTERN...]

With the system Python 3.11 (the one Blender embeds), the bpy-free suites (blender_tests/pure/test_*.py):

    /usr/bin/python3.11 blender_tests/run.py pure [PATTERN...]

Only the modules whose names contain a PATTERN run when patterns are given.
"""
import os
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def native_missing():
    """A sentence when the compiled solver cannot load: the suites that need it would only be
    skipped, so the run counts it as a failure instead of passing quietly."""
    from wiresculpt import native

    return "" if native.available() else native.LOAD_ERROR


def main():
    inside_blender = "bpy" in sys.modules
    if "--" in sys.argv:
        argv = sys.argv[sys.argv.index("--") + 1:]
    else:
        argv = [] if inside_blender else sys.argv[1:]
    pure = bool(argv) and argv[0] == "pure"
    if pure:
        argv = argv[1:]
    label, folder = ("pure", os.path.join(HERE, "pure")) if pure else ("blender", HERE)
    for path in (folder, HERE, os.path.join(ROOT, "addon"), os.path.join(ROOT, "scripts")):
        if path not in sys.path:
            sys.path.insert(0, path)
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
    passed = max(0, result.testsRun - failed - skipped)  # a failed setUpClass is not a test run
    sys.stdout.flush()
    print(f"{label}: {passed} passed, {failed} failed, {skipped} skipped" if skipped
          else f"{label}: {passed} passed, {failed} failed")
    sys.stdout.flush()
    if failed or result.testsRun == 0:
        sys.exit(1)


main()
