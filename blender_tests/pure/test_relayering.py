"""The re-layering loop (pipeline.relayer, issue 20) on a network built so that the first layering's
hooks cannot be bent and the opposite ones can.

The network (three circles on a sphere of radius R = 0.2 m): A on the plane z = 0 (the equator),
B on x = a, C on y = a, with a = R cos 47.5 deg. A crosses B at (a, +-y0, 0) (+-47.5 deg along
the equator) and C at (+-y0, a, 0) (42.5 deg and 137.5 deg), so two of A's crossings, P (with B)
and Q (with C), are 5 deg apart: 17.5 mm along the wire, more than min_segment (15 mm) but less
than the 30 mm a free bending point between them needs. The target shape must join them by one
straight piece, the chord from P to Q, which makes 45 deg with -y and 135 deg with +y at P (by
symmetry, likewise with -x and +x at Q). A kink's edges must lie within contact_angle / 2 =
60 deg of the direction it opens to, so at P A can open towards -y only, at Q towards -x only.

The layering's cost (Eq. 2, docs/method-layering.md section 3: e = sum over the two wires of
1 - h . h_input) prefers the other side: at P, A's input bends inwards, h_input = -(cos 47.5,
sin 47.5, 0), and B's (a circle about (a, 0, 0)) towards -y; a hook makes the two wires open to
opposite sides of d = +-y. A to +y, B to -y costs (1 + 0.737) + 0 = 1.74; A to -y, B to +y costs
(1 - 0.737) + 2 = 2.26; B and C cross at 2.0 whatever the hook. So the layering first picks A to
+y at P (and likewise A to +x at Q), which the straight piece rules out. Without P
and Q, A hangs on two crossings and can turn about the line through them: the old path (re-check
the same hooks) ends unstable. With those hooks forbidden, the layering picks the opposite ones
(B and C then open outwards, where they have room to bend) and the design is stable; the
independent re-check (recheck.py, numpy/scipy only) confirms it.
"""
import math
import unittest

import numpy as np

from wiresculpt import native, pipeline
from wiresculpt.core.design import new_design, wire_entry
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.settings import defaults
from wiresculpt.stages import target_shape

from recheck import recheck

R = 0.2
ANGLE = 47.5  # degrees along the equator from the x axis to P (Q is at 90 - ANGLE)
A_OFF = R * math.cos(math.radians(ANGLE))


def ring(centre, normal, radius, through, n=120):
    """A circle of `n` points about `centre` in the plane of `normal`, with the points `through` (on
    the circle: the crossings, as a slicer's contours share them) inserted in their places."""
    normal = np.asarray(normal, dtype=float)
    u = np.cross(normal, [0.0, 0.0, 1.0] if abs(normal[2]) < 0.9 else [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    offsets = [np.subtract(p, centre) for p in through]
    for o in offsets:
        assert abs(np.linalg.norm(o) - radius) < 1e-12 and abs(o @ normal) < 1e-12
    t = np.concatenate([np.linspace(0.0, 2.0 * math.pi, n, endpoint=False) + 0.01,
                        [math.atan2(o @ v, o @ u) % (2.0 * math.pi) for o in offsets]])
    t = np.sort(t)
    return np.asarray(centre) + radius * (np.outer(np.cos(t), u) + np.outer(np.sin(t), v))


def network_design(settings):
    design = new_design(PRESETS["steel"], settings)
    y0 = math.sqrt(R * R - A_OFF * A_OFF)  # A meets B at (a, +-y0, 0), C at (+-y0, a, 0)
    z0 = math.sqrt(R * R - 2 * A_OFF * A_OFF)  # B meets C at (a, a, +-z0)
    ab = [(A_OFF, y0, 0.0), (A_OFF, -y0, 0.0)]
    ac = [(y0, A_OFF, 0.0), (-y0, A_OFF, 0.0)]
    bc = [(A_OFF, A_OFF, z0), (A_OFF, A_OFF, -z0)]
    for k, (name, centre, normal, radius, through) in enumerate((
            ("A", (0.0, 0.0, 0.0), (0, 0, 1), R, ab + ac),
            ("B", (A_OFF, 0.0, 0.0), (1, 0, 0), y0, ab + bc),
            ("C", (0.0, A_OFF, 0.0), (0, 1, 0), y0, ac + bc))):
        design["wires"].append(wire_entry(k, name, centre, normal, True, ring(centre, normal, radius, through)))
    return design


def opening_of_a(design, crossing):
    """The direction wire A (id 0) opens to at `crossing` by the FORMATS hook convention, computed
    here from the planes: hook * d for wires[0], -hook * d for wires[1], d = n0 x n1."""
    n0, n1 = (np.asarray(design["wires"][w]["plane"]["normal"], dtype=float) for w in crossing["wires"])
    d = np.cross(n0, n1)
    d /= np.linalg.norm(d)
    return (crossing["hook"] if crossing["wires"][0] == 0 else -crossing["hook"]) * d


def find(design, other, axis):
    """The crossing of A with wire `other` whose point has a positive `axis` coordinate (P or Q)."""
    return next(c for c in design["crossings"] if sorted(c["wires"]) == [0, other] and c["point"][axis] > 0.0)


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Relayering(unittest.TestCase):
    def solve(self, rounds, progress=None, cancel=None):
        settings = dict(defaults(), relayer_rounds=rounds)
        return pipeline.solve(network_design(settings), PRESETS["steel"], settings, progress, cancel)

    def test_the_geometry_is_as_described(self):
        # P and Q 17.5 mm apart along A (between min_segment and twice it), the chord at 45 deg.
        d = self.solve(0)
        p, q = find(d, 1, 1), find(d, 2, 0)
        np.testing.assert_allclose(p["point"], [A_OFF, R * math.sin(math.radians(ANGLE)), 0], atol=1e-9)
        np.testing.assert_allclose(q["point"], [R * math.cos(math.radians(90 - ANGLE)), A_OFF, 0], atol=1e-9)
        chord = np.subtract(q["point"], p["point"])
        self.assertAlmostEqual(float(np.linalg.norm(chord)), 2 * R * math.sin(math.radians(ANGLE - 45.0)), places=9)
        self.assertLess(R * math.radians(2 * ANGLE - 90.0), 2 * d["machine"]["min_segment"])  # no free point
        self.assertGreater(np.linalg.norm(chord), d["machine"]["min_segment"])
        self.assertAlmostEqual(math.degrees(math.acos(-chord[1] / np.linalg.norm(chord))), 45.0, places=6)

    def test_the_old_path_ends_unstable(self):
        for rounds in (0,):
            old = self.solve(rounds)
            self.assertFalse(old["stable"])
            nulled = {n["crossing"]: n for n in old["stages"]["target_shape"]["nulled_crossings"]}
            p, q = find(old, 1, 1), find(old, 2, 0)
            self.assertIn(p["id"], nulled)
            self.assertIn(q["id"], nulled)
            self.assertIn("no longer stable", old["reason"])
            record = old["stages"]["relayering"]
            self.assertEqual(len(record["rounds"]), 1)
            self.assertEqual(record["forbidden"], [])
            # The first layering's hooks were the ones the chord rules out: A opening to +y at P
            # and to +x at Q (the nulled crossings keep the hook that failed).
            for crossing, axis in ((p, 1), (q, 0)):
                failed = dict(crossing, hook=nulled[crossing["id"]]["hook"])
                self.assertGreater(opening_of_a(old, failed)[axis], 0.9)

    def test_relayering_finds_the_opposite_hooks(self):
        messages = []
        new = self.solve(8, progress=lambda stage, message: messages.append((stage, message)))
        self.assertTrue(new["stable"], new["reason"])
        p, q = find(new, 1, 1), find(new, 2, 0)
        self.assertLess(opening_of_a(new, p)[1], -0.9)  # A opens to -y at P, the side the chord allows
        self.assertLess(opening_of_a(new, q)[0], -0.9)  # and to -x at Q
        record = new["stages"]["relayering"]
        self.assertGreaterEqual(len(record["rounds"]), 2)
        self.assertFalse(record["rounds"][0]["stable"])
        self.assertTrue(record["rounds"][-1]["stable"])
        self.assertEqual(record["rounds"][-1]["verdict"], "stable")
        forbidden = {tuple(x) for x in record["forbidden"]}
        self.assertIn((p["id"], -p["hook"]), forbidden)  # the first layering's hook at P
        self.assertEqual(set(map(tuple, record["rounds"][0]["unrealised"])), {tuple(f) for f in record["rounds"][1]["forbidden"]})
        # Every crossing the design hooks is realised: the target shape nulled nothing in the end.
        self.assertEqual(new["stages"]["target_shape"]["nulled_crossings"], [])
        for c in new["crossings"]:
            if c["hook"]:
                self.assertNotIn((c["id"], c["hook"]), forbidden)
        self.assertEqual(record["max_rounds"], 8)
        for r in record["rounds"]:
            self.assertGreater(r["seconds"], 0.0)
        # Every round reports progress: a message per re-layering, and one layering per round.
        self.assertEqual(sum(1 for s, _m in messages if s == "relayering"), len(record["rounds"]) - 1)
        self.assertEqual(sum(1 for s, _m in messages if s == "layering"), len(record["rounds"]))
        self.assertEqual(new["pending_stages"], [])
        self.assertEqual(recheck(new), [])

    def test_cancel_reaches_the_second_round(self):
        seen = []

        def cancel():
            return any(stage == "relayering" for stage, _m in seen)

        with self.assertRaises(pipeline.Cancelled):
            self.solve(8, progress=lambda stage, message: seen.append((stage, message)), cancel=cancel)
        self.assertTrue(any(stage == "relayering" for stage, _m in seen))


class Unrealisable(unittest.TestCase):
    """Which (crossing, hook) pairs a failed target shape forbids: the failed hook, or both when the
    solver's verdict on either wire says no hook cures it (the reviewer's case: a crossing 25 mm
    along the wire from its neighbour, whose fixed piece lies outside this hook's kink, must keep
    its other hook however close another crossing is in space)."""

    GAP = ("crossings 0 and 1 on wire A/0 are 25.0 mm apart along the wire; a free bending point between "
           "them needs 30.0 mm: scale the model up by 1.2x")

    def forbidden(self, *failures):
        nulled = [{"crossing": c, "hook": h, "status": status, "message": message,
                   "whatever_the_hook": target_shape.whatever_the_hook(status, message)}
                  for c, h, status, message in failures]
        return target_shape.unrealisable({"stages": {"target_shape": {"nulled_crossings": nulled}}})

    def test_the_failed_hook_or_both(self):
        self.assertEqual(self.forbidden((0, 1, "too_close", self.GAP)), {(0, 1)})
        short = self.GAP + " (the straight piece is shorter than the minimum segment)"
        self.assertEqual(self.forbidden((0, 1, "too_close", short)), {(0, 1), (0, -1)})
        self.assertEqual(self.forbidden((3, -1, "open_end", "crossing 3 is at an end of the open wire")),
                         {(3, 1), (3, -1)})
        cone = "crossing 2 on wire B/0 misses its contact cone by 3.1 deg"
        self.assertEqual(self.forbidden((2, -1, "infeasible", cone)), {(2, -1)})
        rule = ("crossing 2 needs a bend of at least 130 deg (contact angle 60 deg minus twice the friction angle) "
                "but the machine bends at most 120 deg")
        self.assertEqual(self.forbidden((2, -1, "infeasible", rule)), {(2, 1), (2, -1)})
        self.assertEqual(target_shape.unrealisable({"stages": {}}), set())


if __name__ == "__main__":
    unittest.main()
