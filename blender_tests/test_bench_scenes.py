"""The benchmark's generated scenes (scripts/bench_scenes.py) are what scripts/bench says they are:
the promised wire and crossing counts, closed meshes, the longest wire at the requested length, and
the same counts when Blender itself imports the mesh in a batch run. Correctness only: no timing."""
import json
import os
import shutil
import subprocess
import tempfile
import unittest

import numpy as np

import bench_scenes
import helpers
from helpers import BATCH, BLENDER, NO_WINDOW, ROOT, run_blender


class BenchScenesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        cls.out = cls.dir.name
        try:
            cls.cases = bench_scenes.generate(cls.out, ["teddy", "globe", "sphere-222", "length-0.5m"], say=lambda _line: None)
        except SystemExit as exc:  # the generator's own (P, C) check failed
            cls.dir.cleanup()
            raise AssertionError(str(exc)) from None

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def case(self, name):
        return next(c for c in self.cases if c["name"] == name)

    def test_manifest_lists_the_cases_with_their_counts(self):
        with open(os.path.join(self.out, "manifest.json")) as f:
            manifest = json.load(f)["cases"]
        self.assertEqual([c["name"] for c in manifest], ["teddy", "globe", "sphere-222", "length-0.5m"])
        self.assertEqual((self.case("teddy")["P"], self.case("teddy")["C"]), (4, 10))  # the paper's Teddy
        # the bundled globe: three great circles, every pair crossing twice
        self.assertEqual((self.case("globe")["P"], self.case("globe")["C"]), (3, 6))
        self.assertEqual(self.case("globe")["kind"], "example")
        self.assertEqual((self.case("sphere-222")["P"], self.case("sphere-222")["C"]), (6, 24))
        self.assertEqual((self.case("length-0.5m")["P"], self.case("length-0.5m")["C"]), (4, 10))

    def test_counts_measured_by_the_pipeline(self):
        for name in ("teddy", "globe", "sphere-222"):
            case = self.case(name)
            P, C, _lmax = bench_scenes.check(dict(case, scene=os.path.join(self.out, case["scene"])))
            self.assertEqual((P, C), (case["P"], case["C"]), name)

    def test_longest_wire_is_scaled_to_the_papers_length(self):
        self.assertAlmostEqual(self.case("teddy")["longest_wire"], 1.254, delta=0.005)
        self.assertAlmostEqual(self.case("length-0.5m")["longest_wire"], 0.5, delta=0.002)

    def test_meshes_are_closed_and_outward(self):
        for name in ("teddy", "sphere"):
            V, F = bench_scenes.read_obj(os.path.join(self.out, "meshes", f"{name}.obj"))
            edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
            _unique, counts = np.unique(edges, axis=0, return_counts=True)
            self.assertTrue(np.all(counts == 2), f"{name}: {np.sum(counts != 2)} edges not shared by two triangles")
            # divergence theorem: positive volume iff the triangles face outwards
            volume = np.einsum("ij,ij->i", V[F[:, 0]], np.cross(V[F[:, 1]], V[F[:, 2]])).sum() / 6
            self.assertGreater(volume, 0, name)

    def test_blender_batch_run_sees_the_same_design(self):
        case = self.case("teddy")
        out = os.path.join(self.out, "batch")
        r = run_blender(BATCH, os.path.join(self.out, case["scene"]), "--out", out)
        self.assertIn(r.returncode, (0, 2), r.stdout + r.stderr)
        with open(os.path.join(out, "design.json")) as f:
            design = json.load(f)
        self.assertEqual((len(design["wires"]), len(design["crossings"])), (case["P"], case["C"]))


@unittest.skipUnless(shutil.which("xvfb-run"), "xvfb-run is not installed")
class BenchLiveTest(unittest.TestCase):
    """scripts/bench_live.py on the globe in a Blender with a window: it records a verdict per move
    and round trips that contain the live job's own time (no time is asserted)."""

    def test_round_trips_are_recorded(self):
        if helpers.BPY_MODULE:
            self.skipTest(NO_WINDOW)
        with tempfile.TemporaryDirectory() as out:
            bench_scenes.generate(out, ["globe"], run_check=False, say=lambda _line: None)
            result_path = os.path.join(out, "live.json")
            cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", BLENDER, "--factory-startup",
                   "--python-exit-code", "1", "--python", os.path.join(ROOT, "scripts", "bench_live.py"), "--",
                   os.path.join(out, "manifest.json"), result_path]
            r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
            self.assertTrue(os.path.exists(result_path), r.stdout[-3000:] + r.stderr[-3000:])
            with open(result_path) as f:
                (record,) = json.load(f)["cases"]
        self.assertNotIn("error", record)
        self.assertEqual(record["name"], "globe")
        self.assertEqual(record["wires_ticked"], 3)
        # the globe stands (with Live's single hook pattern its wires bend out of their planes, so the
        # verdict may read "stable, over its limits — …", core/limits.py), and 1 mm moves keep it so
        stands = r"^Live: stable($|, over its limits — )"  # its figures move with the plane
        self.assertRegex(record["first_verdict"], stands)
        self.assertEqual(len(record["verdicts"]), 5)
        for verdict in record["verdicts"]:
            self.assertRegex(verdict, stands)
        self.assertEqual(len(record["round_trips"]), 5)
        for trip, shown, job in zip(record["round_trips"], record["verdict_set"], record["job_seconds"]):
            self.assertGreater(job, 0)
            self.assertLessEqual(job, shown)  # the verdict is shown after its job ran, which began after the move
            self.assertLessEqual(shown, trip)  # and drawn after it was set


if __name__ == "__main__":
    unittest.main()
