"""scripts/bench_pipeline knows a case whose process could not load the solver (it retries those:
the module may be being rebuilt) by the child's exit status, not by its error's words."""
import contextlib
import io
import os
import tempfile
import unittest
from unittest import mock

import bench_case
import bench_pipeline


def run_fake(status, line):
    """run_case on a stand-in bench_case.py that prints `line` on stderr and exits with `status`."""
    with tempfile.TemporaryDirectory() as folder:
        with open(os.path.join(folder, "bench_case.py"), "w") as f:
            f.write(f"import sys\nprint({line!r}, file=sys.stderr)\nsys.exit({status})\n")
        with mock.patch.object(bench_pipeline, "HERE", folder):
            return bench_pipeline.run_case({"scene": "x.json"}, folder, 30.0, 1.0)


class BenchRetry(unittest.TestCase):
    def test_the_case_without_the_solver_exits_with_its_status(self):
        said = io.StringIO()
        with mock.patch("wiresculpt.native.available", return_value=False), contextlib.redirect_stderr(said):
            with self.assertRaises(SystemExit) as stop:
                bench_case.main(["missing.json"])
        self.assertEqual(stop.exception.code, 3)
        self.assertTrue(said.getvalue().strip())  # its reason, for the bench's log

    def test_run_case_gives_the_cause_by_the_status(self):
        r = run_fake(3, "RuntimeError: worded any way")
        self.assertEqual((r["cause"], r["error"]), ("no_solver", "exit status 3: RuntimeError: worded any way"))
        r = run_fake(1, "RuntimeError: The wiresculpt solver (_wiresculpt) is not installed")
        self.assertNotIn("cause", r)  # the words alone decide nothing
        self.assertEqual(r["error"], "exit status 1: RuntimeError: The wiresculpt solver (_wiresculpt) is not installed")


if __name__ == "__main__":
    unittest.main()
