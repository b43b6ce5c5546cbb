"""The layering binding from Python: results by hand on great circles, errors and cancellation."""
import unittest

import numpy as np
from helpers import circle

from wiresculpt import native
from wiresculpt.core.design import MECHANISM, SEARCH_INCOMPLETE, STABLE_CAUSE


def wire(name, normal, **kw):
    return {"name": name, "origin": [0, 0, 0], "normal": normal, "points": circle(normal, **kw), "closed": True}


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class LayeringBinding(unittest.TestCase):
    def test_three_great_circles(self):
        r = native.module.layering([wire("X", [1, 0, 0]), wire("Y", [0, 1, 0]), wire("Z", [0, 0, 1])])
        crossings = r["network"]["crossings"]
        self.assertEqual(len(crossings), 6)
        self.assertTrue(r["stable"])
        self.assertEqual(sorted(r["assembly_order"]), [0, 1, 2])
        self.assertEqual(len(r["steps"][0]), 2)  # the first step is a pair
        for c in crossings:
            # on the common line of the two planes, on the circle
            n0 = np.eye(3)[c["wires"][0]]
            n1 = np.eye(3)[c["wires"][1]]
            p = np.asarray(c["point"])
            self.assertAlmostEqual(float(p @ n0), 0.0, places=12)
            self.assertAlmostEqual(float(p @ n1), 0.0, places=12)
            self.assertAlmostEqual(float(np.linalg.norm(p)), 0.1, places=12)

    def test_two_circles_need_a_third(self):
        # Two wires are held under forces only; the verdict for the pair is stable (Sec. 4.2).
        r = native.module.layering([wire("X", [1, 0, 0]), wire("Y", [0, 1, 0])])
        self.assertTrue(r["stable"])
        self.assertEqual(len(r["network"]["crossings"]), 2)

    def test_bad_input_names_the_wire_or_key(self):
        with self.assertRaises(ValueError) as ctx:
            native.module.layering([wire("X", [1, 0, 0]), wire("Y", [0, 1, 0])], {"frictoin": 0.3})
        self.assertIn("frictoin", str(ctx.exception))
        same = [wire("A", [0, 0, 1]), wire("B", [0, 0, 1], radius=0.1)]
        with self.assertRaises(ValueError) as ctx:
            native.module.layering(same)
        self.assertIn("A", str(ctx.exception))
        self.assertIn("B", str(ctx.exception))

    def test_wrong_types_are_value_errors_naming_the_key(self):
        cases = [({"tolerance": "abc"}, "settings['tolerance']: expected a number, got str"),
                 ({"max_nodes": 1.5}, "settings['max_nodes']: expected an integer, got float"),
                 ({"friction": float("nan")}, "settings['friction']: expected a finite number, got nan"),
                 ({"two_wire_steps": "yes"}, "settings['two_wire_steps']: expected True or False, got str")]
        for bad, message in cases:
            with self.assertRaises(ValueError) as ctx:
                native.module.layering([wire("X", [1, 0, 0]), wire("Y", [0, 1, 0])], bad)
            self.assertEqual(str(ctx.exception), message)
        flat = dict(wire("Y", [0, 1, 0]), points=circle([0, 1, 0])[:, :2])
        with self.assertRaises(ValueError) as ctx:
            native.module.layering([wire("X", [1, 0, 0]), flat])
        self.assertEqual(str(ctx.exception),
                         "wires[1]['points']: expected an (n, 3) array of numbers, got shape (64, 2)")
        with self.assertRaises(ValueError) as ctx:
            native.module.check_assembly([wire("X", [1, 0, 0]), wire("Y", [0, 1, 0])], [1, -1], [[0, "1"]])
        self.assertEqual(str(ctx.exception), "steps[0][1]: expected an integer, got str")

    def test_forbidden_hooks(self):
        wires = [wire("X", [1, 0, 0]), wire("Y", [0, 1, 0]), wire("Z", [0, 0, 1])]
        free = native.layering(wires)
        # Forbid every hook the free search chose: each such crossing gets the other hook or null.
        chosen = [[c, h] for c, h in enumerate(free["hook"]) if h != 0]
        r = native.layering(wires, {"forbidden_hooks": chosen})
        for (c, h) in chosen:
            self.assertNotEqual(r["hook"][c], h, f"crossing {c}")
        # Both hooks of every crossing forbidden: nothing can hold anything, and the reason says why.
        r = native.layering(wires, {"forbidden_hooks": [[c, h] for c in range(6) for h in (-1, 1)]})
        self.assertFalse(r["stable"])
        self.assertEqual(r["hook"], [0] * 6)
        self.assertIn("12 hooks forbidden", r["reason"])
        # as codes: not even both hooks at every crossing hold (none is allowed), over 6 x 2 hooks left out
        self.assertEqual((r["cause"], r["forbidden_hooks"]), (MECHANISM, 12))
        bad = [([[6, 1]], "settings['forbidden_hooks'][0]: crossing 6 does not exist (the network has 6 crossings)"),
               ([[0, 0]], "settings['forbidden_hooks'][0]: the hook must be -1 or 1 (null is always allowed), got 0"),
               ([[0, 1, 2]], "settings['forbidden_hooks'][0]: expected [crossing id, hook]")]
        for pairs, message in bad:
            with self.assertRaises(ValueError) as ctx:
                native.layering(wires, {"forbidden_hooks": pairs})
            self.assertEqual(str(ctx.exception), message)
        with self.assertRaises(ValueError) as ctx:
            native.check_assembly(wires, free["hook"], free["steps"], {"forbidden_hooks": chosen})
        self.assertIn("only layering() takes forbidden hooks", str(ctx.exception))

    def test_contour_arrays_and_forbid_too_close(self):
        wires = [wire("X", [1, 0, 0]), wire("Y", [0, 1, 0]), wire("Z", [0, 0, 1])]
        lists = native.layering(wires)
        arrays = native.layering(wires, {"contour_arrays": True})
        for a, b in zip(lists["network"]["wires"], arrays["network"]["wires"]):
            self.assertIsInstance(a["contour"], list)
            self.assertEqual(b["contour"].dtype, np.float64)
            self.assertEqual(b["contour"].shape, (len(a["contour"]), 3))
            np.testing.assert_array_equal(b["contour"], np.asarray(a["contour"]))
        self.assertEqual(lists["hook"], arrays["hook"])
        self.assertNotIn("arrays", lists)  # only on request
        too = native.layering(wires, {"arrays_too": True})
        self.assertEqual(len(too["arrays"]), len(too["network"]["wires"]))
        for a, b in zip(too["network"]["wires"], too["arrays"]):
            self.assertIsInstance(a["contour"], list)
            self.assertEqual(b.dtype, np.float64)
            np.testing.assert_array_equal(b, np.asarray(a["contour"]))
        # Great circles of radius 0.1 m cross pi/2 x 0.1 = 157 mm apart along each wire: nothing is too
        # close for min_segment 15 mm or 75 mm (a free point needs 150 mm).
        for lmin in (0.015, 0.075):
            free = native.layering(wires, {"forbid_too_close": True, "min_segment": lmin})
            self.assertEqual(free["hook"], lists["hook"])
            self.assertNotIn("forbidden", free["reason"])
        # With min_segment 0.1 m every piece is one fixed straight chord (141 mm, longer than 0.1 m).
        # At crossing (0.1, 0, 0) of Z (z = 0) and Y (y = 0) both of Z's chords run to (0, +-0.1, 0),
        # 45 deg from -x and 135 deg from +x, so only the hook that opens Z's kink towards -x is
        # within the 60 deg cone; that hook opens Y's kink towards +x (contact.hpp), and Y's chords run
        # to (0, 0, +-0.1), 135 deg from +x. So no hook is realisable anywhere: all 12 forbidden.
        near = native.layering(wires, {"forbid_too_close": True, "min_segment": 0.1})
        self.assertFalse(near["stable"])
        self.assertIn("12 hooks forbidden", near["reason"])
        self.assertEqual(sorted(map(tuple, near["too_close_forbidden"])), [(c, h) for c in range(6) for h in (-1, 1)])
        self.assertEqual(free["too_close_forbidden"], [])
        self.assertEqual(lists["too_close_forbidden"], [])
        with self.assertRaises(ValueError) as ctx:
            native.layering(wires, {"forbid_too_close": True, "too_close_angle_tolerance": -0.01})
        self.assertIn("too_close_angle_tolerance must be a finite angle >= 0", str(ctx.exception))
        for bad, message in ((({"contour_arrays": 1}), "settings['contour_arrays']: expected True or False, got int"),
                             (({"arrays_too": 0}), "settings['arrays_too']: expected True or False, got int"),
                             (({"forbid_too_close": "yes"}), "settings['forbid_too_close']: expected True or False, got str")):
            with self.assertRaises(ValueError) as ctx:
                native.layering(wires, bad)
            self.assertEqual(str(ctx.exception), message)
        with self.assertRaises(ValueError) as ctx:
            native.check_assembly(wires, lists["hook"], lists["steps"], {"contour_arrays": True})
        self.assertIn("only layering() returns contours", str(ctx.exception))

    def test_max_nodes_reached_is_search_incomplete(self):
        wires = [wire("X", [1, 0, 0]), wire("Y", [0, 1, 0]), wire("Z", [0, 0, 1])]
        r = native.layering(wires, {"max_nodes": 1})
        self.assertFalse(r["complete_search"])
        self.assertFalse(r["stable"])
        self.assertTrue(r["reason"].startswith("search incomplete"), r["reason"])
        self.assertNotIn("no stable", r["reason"])
        self.assertEqual((r["cause"], r["forbidden_hooks"]), (SEARCH_INCOMPLETE, 0))
        self.assertTrue(native.layering(wires, {"max_nodes": 0})["stable"])  # 0: no limit
        self.assertEqual(native.layering(wires, {"max_nodes": 0})["cause"], STABLE_CAUSE)

    def test_check_assembly_cancel(self):
        wires = [wire("X", [1, 0, 0]), wire("Y", [0, 1, 0]), wire("Z", [0, 0, 1])]
        r = native.module.layering(wires)
        stages = []
        verdict = native.module.check_assembly(wires, r["hook"], r["steps"], {},
                                               lambda stage, fraction: stages.append(stage))
        self.assertTrue(verdict["stable"])
        self.assertIn("check_assembly", stages)
        self.assertIn("network", stages)
        with self.assertRaises(native.module.Cancelled):
            native.module.check_assembly(wires, r["hook"], r["steps"], {},
                                         lambda stage, fraction: stage != "check_assembly")

    def test_cancel(self):
        wires = [wire("X", [1, 0, 0]), wire("Y", [0, 1, 0]), wire("Z", [0, 0, 1])]
        with self.assertRaises(native.module.Cancelled):
            native.module.layering(wires, {}, lambda stage, fraction: False)
        with self.assertRaises(RuntimeError):  # Cancelled is a RuntimeError for callers that don't know it
            native.module.layering(wires, {}, lambda stage, fraction: False)


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class ProgressCallbacks(unittest.TestCase):
    """One adapter serves every binding: None continues, False cancels, an exception in the
    callback is re-raised as itself."""

    def calls(self, progress):
        wires = [wire("X", [1, 0, 0]), wire("Y", [0, 1, 0]), wire("Z", [0, 0, 1])]
        line = np.stack([np.linspace(0, 0.3, 40), np.zeros(40)], axis=1)
        yield lambda: native.module.layering(wires, {}, progress)
        yield lambda: native.module.optimize_target_shape(line, False, [], {}, progress)

    def test_none_continues(self):
        seen = []
        for call in self.calls(lambda stage, fraction: seen.append(stage)):
            call()
        self.assertIn("layering", seen)
        self.assertTrue(len(set(seen)) >= 2, seen)

    def test_false_cancels(self):
        for call in self.calls(lambda stage, fraction: False):
            with self.assertRaises(native.module.Cancelled):
                call()

    def test_exception_is_reraised(self):
        class Boom(Exception):
            pass

        def explode(stage, fraction):
            raise Boom(stage)

        for call in self.calls(explode):
            with self.assertRaises(Boom):
                call()


if __name__ == "__main__":
    unittest.main()
