"""Runs the Blender test suites inside Blender:

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py [-- PATTERN...]

Discovers blender_tests/test_*.py (or only the modules whose names contain a PATTERN), runs them
with unittest, prints a closing line `N passed, N failed` and exits non-zero on any failure.
"""
import os
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
for path in (HERE, os.path.join(ROOT, "addon"), os.path.join(ROOT, "scripts")):
    if path not in sys.path:
        sys.path.insert(0, path)


def native_missing():
    """A sentence when the compiled solver cannot load: the suites that need it would only be
    skipped, so the run counts it as a failure instead of passing quietly."""
    from wiresculpt import native

    return "" if native.available() else native.LOAD_ERROR


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    missing = native_missing()
    if missing:
        print(f"blender: the solver is missing: {missing}")
    loader = unittest.TestLoader()
    suite = unittest.TestSuite()
    for name in sorted(os.listdir(HERE)):
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
    print(f"blender: {passed} passed, {failed} failed, {skipped} skipped" if skipped
          else f"blender: {passed} passed, {failed} failed")
    sys.stdout.flush()
    if failed or result.testsRun == 0:
        sys.exit(1)


main()
