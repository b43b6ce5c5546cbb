"""Forces, rest shapes, cuts and load capacity in the headless batch run (docs/formats.md `force`, `rest`,
`cut`), checked on the globe example against the contract, not against the solver's own numbers."""
import json
import math
import os
import tempfile
import unittest

from helpers import BATCH, ROOT, run_blender

GLOBE = os.path.join(ROOT, "scripts", "examples", "globe", "scene.json")


def normalize(v):
    n = math.sqrt(sum(x * x for x in v))
    return [x / n for x in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


class ForcesStageTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        out = os.path.join(cls.dir.name, "out")
        cls.batch = run_blender(BATCH, GLOBE, "--out", out)
        cls.design = None
        if cls.batch.returncode == 0:
            with open(os.path.join(out, "design.json")) as f:
                cls.design = json.load(f)

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def setUp(self):
        self.assertEqual(self.batch.returncode, 0, self.batch.stdout + self.batch.stderr)
        self.d = self.design

    def test_stages_ran(self):
        d = self.d
        self.assertEqual(d["pending_stages"], [])
        for stage in ("forces", "rest_shape"):
            self.assertIn(stage, d["stages"])
            self.assertGreaterEqual(d["stages"][stage]["seconds"], 0.0)
        self.assertLess(d["stages"]["forces"]["equilibrium_residual"], 1e-9)
        self.assertTrue(d["stages"]["forces"]["torque_active"])
        # The paper's 3D bound |t_v| <= t_max (docs/method-forces.md §3): every wire's 3D torque
        # is within t_max, and the LP took its polytope's rows in more than one solve.
        self.assertEqual(d["stages"]["forces"]["torque_bound"], "3d")
        self.assertGreaterEqual(d["stages"]["forces"]["lp_rounds"], 2)
        t_max = d["stages"]["forces"]["t_max"]
        for w in d["wires"]:
            self.assertLessEqual(w["max_torque_3d"], t_max * (1 + 1e-7), w["name"])
        self.assertFalse([m for m in d.get("warnings", []) if "twist together reach" in m], d.get("warnings"))
        self.assertAlmostEqual(d["stages"]["forces"]["t_max"], d["material"]["max_torque"] * d["torque_fraction"])
        lines = [line for line in self.batch.stdout.splitlines() if line.startswith("wiresculpt:")]
        self.assertTrue(any(line.startswith("wiresculpt: forces:") for line in lines), lines)
        self.assertTrue(any(line.startswith("wiresculpt: rest_shape:") for line in lines), lines)

    def test_force_sign_per_formats(self):
        d = self.d
        loaded = 0
        for c in d["crossings"]:
            self.assertEqual(len(c["force"]), 3)
            if c["hook"] == 0:
                self.assertEqual(c["force"], [0.0, 0.0, 0.0])
                continue
            n0, n1 = (d["wires"][w]["plane"]["normal"] for w in c["wires"])
            dvec = normalize(cross(n0, n1))
            # the force on wires[0] has a -hook component along d
            self.assertLess(dot(c["force"], dvec) * c["hook"], 0.0, c)
            self.assertEqual(len(c["out_of_plane"]), 2)
            # each share is |f.n| / |f| in that wire's own plane, recomputed here
            for share, n in zip(c["out_of_plane"], (n0, n1)):
                self.assertAlmostEqual(share, abs(dot(c["force"], n)) / math.sqrt(dot(c["force"], c["force"])), 9)
            loaded += 1
        self.assertGreater(loaded, 0)
        shares = [s for c in d["crossings"] if c["hook"] != 0 for s in c["out_of_plane"]]
        self.assertAlmostEqual(d["out_of_plane"]["mean"], sum(shares) / len(shares), 9)
        largest = max(math.sqrt(dot(c["force"], c["force"])) for c in d["crossings"])
        along = [abs(dot(c["force"], d["wires"][w]["plane"]["normal"]))
                 for c in d["crossings"] if c["hook"] != 0 for w in c["wires"]]
        self.assertAlmostEqual(d["out_of_plane"]["mean_to_max_force"], sum(along) / len(along) / largest, 9)
        self.assertAlmostEqual(d["out_of_plane"]["max_to_max_force"], max(along) / largest, 9)
        for w in d["wires"]:
            self.assertGreaterEqual(w["max_torque_3d"], w["max_torque"] * (1 - 1e-12), w["name"])

    def test_equilibrium_of_every_wire(self):
        # Independent of the solver: sum the crossing forces on each wire (wires[1] gets -f).
        d = self.d
        for w in d["wires"]:
            f, m, scale = [0.0] * 3, [0.0] * 3, 0.0
            for c in d["crossings"]:
                if w["id"] not in c["wires"]:
                    continue
                k = c["wires"].index(w["id"])
                force = [x if k == 0 else -x for x in c["force"]]
                p = w["target"][c["vertices"][k]]
                f = [a + b for a, b in zip(f, force)]
                m = [a + b for a, b in zip(m, cross(p, force))]
                scale += math.sqrt(dot(force, force))
            self.assertLess(math.sqrt(dot(f, f)), 1e-8 * max(scale, 1.0), w["name"])
            self.assertLess(math.sqrt(dot(m, m)), 1e-8 * max(scale, 1.0), w["name"])

    def test_rest_and_cut(self):
        d = self.d
        for w in d["wires"]:
            n = len(w["target"])
            self.assertTrue(w["closed"])
            self.assertIsInstance(w["cut"], int)
            self.assertTrue(0 <= w["cut"] < n, w["cut"])
            crossing_vertices = {c["vertices"][c["wires"].index(w["id"])] for c in d["crossings"]
                                 if w["id"] in c["wires"]}
            self.assertNotIn(w["cut"], crossing_vertices)
            rest = w["rest"]
            self.assertEqual(len(rest), n + 1)
            for p in rest:
                self.assertEqual(len(p), 2)
            for k in range(n):
                a, b = w["target"][(w["cut"] + k) % n], w["target"][(w["cut"] + k + 1) % n]
                self.assertAlmostEqual(math.dist(rest[k], rest[k + 1]), math.dist(a, b), delta=1e-12)
            self.assertAlmostEqual(w["closure_gap"], math.dist(rest[0], rest[-1]), delta=1e-12)
            self.assertEqual(len(w["rest_angles"]), n + 1)

    def test_load_capacity(self):
        lc = self.d["load_capacity"]
        # three great circles of radius 0.125 m, 3 mm steel wire
        length = sum(sum(math.dist(w["target"][i], w["target"][(i + 1) % len(w["target"])])
                         for i in range(len(w["target"]))) for w in self.d["wires"])
        weight = length * math.pi * 0.0015 ** 2 * 7850.0 * 9.81
        self.assertAlmostEqual(lc["weight_N"], weight, delta=1e-9)
        for axis in ("+x", "-x", "+y", "-y", "+z", "-z"):
            self.assertIn(axis, lc)
            self.assertTrue(lc[axis] is None or lc[axis] >= 0.0)


if __name__ == "__main__":
    unittest.main()
