"""The target shape's memory between coupling rounds (Sec. 4.3; stages/target_shape.Memo): a wire's
optimum is reused under a lower bend limit only where a cold solve reaches the same answer, and
crossings nulled in one round stay nulled in the next."""
import copy
import math
import unittest

import numpy as np

from wiresculpt import native, pipeline
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.polylines import ContourArrays, point_array
from wiresculpt.core.settings import defaults
from wiresculpt.stages import layering, target_shape

from helpers import PLANES, sphere


def result(max_bend=1.0, feasible=True, nlopt="NLOPT_FTOL_REACHED", status="ok"):
    return {"feasible": feasible, "nlopt_result": nlopt, "crossings": [{"status": "inactive"}, {"status": status}],
            "max_bend": max_bend}


class Reusable(unittest.TestCase):
    """Memo.reusable on results written by hand (radians)."""

    def memo_with(self, r, limit=2.0):
        memo = target_shape.Memo()
        memo.remember("key", limit, r)
        return memo

    def test_an_optimum_within_the_lower_limit_is_reused(self):
        r = result(max_bend=1.0)
        memo = self.memo_with(r)
        self.assertIs(memo.reusable("key", 1.5), r)
        self.assertIs(memo.reusable("key", 1.0), r)  # the limit reached exactly still holds
        self.assertEqual(memo.reused, 2)

    def test_what_is_not_reused(self):
        self.assertIsNone(self.memo_with(result(max_bend=1.0)).reusable("key", 0.99))  # bends over the new limit
        self.assertIsNone(self.memo_with(result(max_bend=1.0)).reusable("key", 2.5))  # a looser limit
        self.assertIsNone(self.memo_with(result(max_bend=1.0)).reusable("other", 1.5))  # another problem
        self.assertIsNone(self.memo_with(result(feasible=False)).reusable("key", 1.5))
        self.assertIsNone(self.memo_with(result(nlopt="NLOPT_ROUNDOFF_LIMITED")).reusable("key", 1.5))
        self.assertIsNone(self.memo_with(result(nlopt="NLOPT_MAXEVAL_REACHED")).reusable("key", 1.5))
        self.assertIsNone(self.memo_with(result(status="infeasible")).reusable("key", 1.5))
        self.assertIsNone(target_shape.Memo().reusable("key", 1.5))

    def test_the_same_problem_is_reused_across_memos_whatever_its_result(self):
        same = {}
        r = result(feasible=False, nlopt="NLOPT_ROUNDOFF_LIMITED")  # never reused under another limit
        target_shape.Memo(same).remember("key", 2.0, r)
        other = target_shape.Memo(same)
        self.assertIs(other.reusable("key", 2.0), r)  # exactly the same problem: the same answer
        self.assertEqual(other.reused, 1)
        self.assertIsNone(other.reusable("key", 1.5))
        self.assertIsNone(target_shape.Memo().reusable("key", 2.0))  # a memo of its own shares nothing

    def test_the_key_sees_every_input_but_the_bend_limit(self):
        contour = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
        specs = [{"vertex": 1, "bisector": (0.0, 1.0), "contact_angle": 2.0, "active": True}]
        options = {"min_segment": 0.015, "max_bend": 2.0}
        key = target_shape.Memo.key(contour, True, specs, options)
        self.assertEqual(key, target_shape.Memo.key(contour.copy(), True, specs, {**options, "max_bend": 1.0}))
        self.assertNotEqual(key, target_shape.Memo.key(contour, False, specs, options))
        self.assertNotEqual(key, target_shape.Memo.key(contour + 1e-9, True, specs, options))
        self.assertNotEqual(key, target_shape.Memo.key(contour, True, [{**specs[0], "active": False}], options))
        self.assertNotEqual(key, target_shape.Memo.key(contour, True, specs, {**options, "min_segment": 0.02}))


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class AgainstColdSolves(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.settings = defaults()
        cls.material = PRESETS["steel"]
        V, F = sphere()
        cls.design = pipeline.slice_and_pick(V, F, PLANES, cls.material, cls.settings)
        layering.run(cls.design, cls.material, cls.settings)
        cls.size = target_shape.model_size(cls.design)

    def solve(self, wire, limit_deg, memo=None):
        settings = {**self.settings, "max_bend_deg": limit_deg}
        return target_shape.solve_wire(self.design, wire, self.material, settings, self.size, None, memo)[0]

    def test_a_reused_optimum_is_what_a_cold_solve_finds(self):
        machine = self.settings["max_bend_deg"]
        for wire in self.design["wires"]:
            memo = target_shape.Memo()
            first = self.solve(wire, machine, memo)
            bend = math.degrees(first["max_bend"])
            self.assertLess(bend, machine - 1.0, wire["name"])  # room for a lower limit that fits
            lower = (bend + machine) / 2
            again = self.solve(wire, lower, memo)
            self.assertIs(again, first)
            self.assertEqual(memo.reused, 1)
            cold = self.solve(wire, lower)
            self.assertLess(np.max(np.linalg.norm(np.asarray(cold["points"]) - np.asarray(again["points"]), axis=1)),
                            1e-5, wire["name"])
            self.assertAlmostEqual(cold["energy"] / again["energy"], 1.0, delta=1e-8)
            # Below the optimum's largest bend the wire is solved again and keeps the new limit.
            tight = self.solve(wire, bend - 1.0, memo)
            self.assertEqual(memo.reused, 1)
            self.assertLessEqual(math.degrees(tight["max_bend"]), bend - 1.0 + 1e-4)

    def test_a_second_round_reuses_every_fitting_wire_and_keeps_the_nulled_crossings(self):
        machine = self.settings["max_bend_deg"]
        memo = target_shape.Memo()
        first = copy.deepcopy(self.design)
        target_shape.run(first, self.material, self.settings, None, memo)
        self.assertEqual(first["stages"]["target_shape"]["reused_wires"], 0)
        bends = [math.degrees(w["max_bend"]) for _k, (_l, w) in memo.solves.items()]
        # Pretend the first round could not realise crossing 0: the next round starts without it.
        memo.nulled = [{"crossing": 0, "wire": "A/0", "status": "infeasible", "scale": 1.0, "message": "by hand",
                        "cause": "cone_missed", "words": "by hand"}]
        second = copy.deepcopy(self.design)
        self.assertNotEqual(second["crossings"][0]["hook"], 0)
        target_shape.run(second, self.material, {**self.settings, "max_bend_deg": (max(bends) + machine) / 2},
                         None, memo)
        stage = second["stages"]["target_shape"]
        self.assertEqual(second["crossings"][0]["hook"], 0)
        self.assertEqual([n["message"] for n in stage["nulled_crossings"]], ["by hand"])
        through = {w for w in second["crossings"][0]["wires"]}
        # The wires through the nulled crossing are new problems; every other one is reused as is.
        self.assertEqual(stage["wire_solves"], len(through))
        self.assertEqual(stage["reused_wires"], len(second["wires"]) - len(through))
        for w1, w2 in zip(first["wires"], second["wires"]):
            if w1["id"] not in through:
                self.assertEqual(w1["target"], w2["target"])


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Derived(unittest.TestCase):
    """What a memo keeps of the contours and planes between rounds (Memo.frame, bisector_2d,
    model_size) is what the stage computes without it, and is computed again when they change."""

    @classmethod
    def setUpClass(cls):
        settings, material = defaults(), PRESETS["steel"]
        V, F = sphere()
        cls.design = pipeline.slice_and_pick(V, F, PLANES, material, settings)
        layering.run(cls.design, material, settings)

    def test_the_same_as_without_a_memo(self):
        memo = target_shape.Memo()
        for _ in range(2):  # computed, then kept
            for wire in self.design["wires"]:
                u, v, contour = memo.frame(wire)
                _n, u0, v0 = target_shape.plane_frame(wire["plane"]["normal"])
                np.testing.assert_array_equal(contour, target_shape.to_2d(wire["contour"], wire["plane"]["origin"], u0, v0))
                np.testing.assert_array_equal(u, u0)
                np.testing.assert_array_equal(v, v0)
            for c in self.design["crossings"]:
                for k in (0, 1):
                    h = target_shape.desired_bisector(self.design, c, k)
                    u, v, _contour = memo.frame(self.design["wires"][c["wires"][k]])
                    self.assertEqual(memo.bisector_2d(self.design, c, k), (float(h @ u), float(h @ v)))
            self.assertEqual(memo.model_size(self.design), target_shape.model_size(self.design))

    def test_a_new_contour_plane_or_hook_is_computed_again(self):
        design = copy.deepcopy(self.design)
        memo = target_shape.Memo()
        wire = design["wires"][0]
        first = memo.frame(wire)[2]
        wire["contour"] = [[x + 0.01, y, z] for x, y, z in wire["contour"]]  # another list
        moved = memo.frame(wire)[2]
        self.assertFalse(np.array_equal(first, moved))
        wire["plane"]["origin"] = [o + 0.02 for o in wire["plane"]["origin"]]
        self.assertFalse(np.array_equal(moved, memo.frame(wire)[2]))
        size = memo.model_size(design)
        wire["contour"] = [[3 * x, 3 * y, 3 * z] for x, y, z in wire["contour"]]
        self.assertGreater(memo.model_size(design), size)
        c = next(c for c in design["crossings"] if c["hook"] != 0)
        h = memo.bisector_2d(design, c, 0)
        c["hook"] = -c["hook"]
        self.assertEqual(memo.bisector_2d(design, c, 0), (-h[0], -h[1]))
        other = design["wires"][c["wires"][1]]
        other["plane"]["normal"] = [-x for x in other["plane"]["normal"]]  # d = n0 x n1 turns over
        self.assertEqual(memo.bisector_2d(design, c, 0), h)

    def test_the_sides_of_each_wire_are_those_a_scan_finds(self):
        sides = target_shape.sides_by_wire(self.design)
        for wire in self.design["wires"]:
            scan = [(c["id"], c["wires"].index(wire["id"])) for c in self.design["crossings"] if wire["id"] in c["wires"]]
            self.assertEqual([(c["id"], k) for c, k in sides.get(wire["id"], [])], scan)
        self.assertEqual(sum(map(len, sides.values())), 2 * len(self.design["crossings"]))

    def test_contour_arrays_are_converted_once_per_list(self):
        contours = ContourArrays()
        wire = self.design["wires"][0]
        first = contours.get(wire["contour"])
        np.testing.assert_array_equal(first, np.asarray(wire["contour"], dtype=np.float64))
        self.assertIs(contours.get(wire["contour"]), first)
        other = [list(p) for p in wire["contour"]]  # equal, but another list
        self.assertIsNot(contours.get(other), first)
        given = np.zeros((3, 3))
        contours.remember(other, given)  # what the layering hands over is what is read
        self.assertIs(contours.get(other), given)
        self.assertIs(target_shape.Memo(contour_cache=contours).array({"name": "x", "contour": other}), given)

    def test_the_layering_hands_over_its_contours_as_the_same_floats(self):
        design = copy.deepcopy(self.design)
        contours = ContourArrays()
        layering.run(design, PRESETS["steel"], defaults(), contour_cache=contours)
        for wire in design["wires"]:
            self.assertIn(id(wire["contour"]), contours._by_id)  # handed over, not converted
            got = contours.get(wire["contour"])
            self.assertEqual(got.dtype, np.float64)
            np.testing.assert_array_equal(got, np.asarray(wire["contour"], dtype=np.float64))


class PointArray(unittest.TestCase):
    """core.polylines.point_array, the memo's conversion of a contour: the numbers np.asarray gives."""

    def test_the_same_floats_as_numpy(self):
        rng = np.random.default_rng(7)
        contour = (rng.normal(size=(500, 3)) * 10.0 ** rng.integers(-12, 3, size=(500, 1))).tolist()
        contour[3] = [1, 2, 3]  # ints too
        got = point_array(contour)
        want = np.asarray(contour, dtype=np.float64)
        self.assertEqual(got.dtype, np.float64)
        self.assertEqual(got.shape, (500, 3))
        self.assertTrue(np.array_equal(got, want))  # bit for bit (no NaN here)

    def test_what_is_not_a_list_of_points_fails_as_numpy_does(self):
        for bad in ([[1.0, 2.0, 3.0], [4.0, 5.0]], [[1.0, 2.0], [3.0, 4.0, 5.0, 6.0]], [[1.0, 2.0, "x"]]):
            with self.assertRaises(ValueError, msg=bad):
                point_array(bad)
        self.assertEqual(point_array(np.zeros((2, 3))).shape, (2, 3))
        self.assertEqual(point_array([]).shape, (0,))


if __name__ == "__main__":
    unittest.main()
