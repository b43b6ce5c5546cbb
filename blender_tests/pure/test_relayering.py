"""The re-layering loop (pipeline.relayer) on a network built so that the first layering's
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
and Q, A hangs on two crossings and can turn about the line through them: the every-hook path (re-check
the same hooks) ends unstable. With those hooks forbidden, the layering picks the opposite ones
(B and C then open outwards, where they have room to bend) and the design is stable; the
independent re-check (recheck.py, numpy/scipy only) confirms it. Those two hooks are known before
any solve (the layering's too_close), so with the loop on the pipeline forbids them up front and
picks the opposite hooks in its first round; told nothing up front (every_hook), the loop learns
them from the target shape in a second round.

With P and Q 3 deg apart (10.5 mm, less than min_segment: CLOSE_ANGLE) the straight piece rules out
both hooks of both, and without P and Q nothing holds A: the layering that forbids them up front
finds no stable assembly, and the pipeline falls back to layering with every hook, so the user sees
the target shape's curves and its reason exactly as without the up-front forbidding.
"""
import contextlib
import math
import re
import unittest
from unittest import mock

import numpy as np

from wiresculpt import native, pipeline
from wiresculpt.core.design import (RELAYER_INCOMPLETE, RELAYER_NO_ASSEMBLY, TOO_CLOSE, UNREALISED, new_design,
                                    wire_entry)
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.settings import defaults
from wiresculpt.stages import layering, target_shape

from recheck import recheck

R = 0.2
ANGLE = 47.5  # degrees along the equator from the x axis to P (Q is at 90 - ANGLE)
A_OFF = R * math.cos(math.radians(ANGLE))
CLOSE_ANGLE = 46.5  # P and Q 3 deg apart: 10.5 mm along A, less than min_segment


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


def network_design(settings, angle=ANGLE):
    design = new_design(PRESETS["steel"], settings)
    a = R * math.cos(math.radians(angle))
    y0 = math.sqrt(R * R - a * a)  # A meets B at (a, +-y0, 0), C at (+-y0, a, 0)
    z0 = math.sqrt(R * R - 2 * a * a)  # B meets C at (a, a, +-z0)
    ab = [(a, y0, 0.0), (a, -y0, 0.0)]
    ac = [(y0, a, 0.0), (-y0, a, 0.0)]
    bc = [(a, a, z0), (a, a, -z0)]
    for k, (name, centre, normal, radius, through) in enumerate((
            ("A", (0.0, 0.0, 0.0), (0, 0, 1), R, ab + ac),
            ("B", (a, 0.0, 0.0), (1, 0, 0), y0, ab + bc),
            ("C", (0.0, a, 0.0), (0, 1, 0), y0, ac + bc))):
        design["wires"].append(wire_entry(k, name, centre, normal, True, ring(centre, normal, radius, through)))
    return design


def opening_of_a(design, crossing):
    """The direction wire A (id 0) opens to at `crossing` by the docs/formats.md hook convention, computed
    here from the planes: hook * d for wires[0], -hook * d for wires[1], d = n0 x n1."""
    n0, n1 = (np.asarray(design["wires"][w]["plane"]["normal"], dtype=float) for w in crossing["wires"])
    d = np.cross(n0, n1)
    d /= np.linalg.norm(d)
    return (crossing["hook"] if crossing["wires"][0] == 0 else -crossing["hook"]) * d


def find(design, other, axis):
    """The crossing of A with wire `other` whose point has a positive `axis` coordinate (P or Q)."""
    return next(c for c in design["crossings"] if sorted(c["wires"]) == [0, other] and c["point"][axis] > 0.0)


@contextlib.contextmanager
def every_hook():
    """The every-hook path, forced: relayer's layerings forbid no hook up front (too_close dropped),
    so the loop learns the too-close hooks from the target shape."""
    real = layering.run

    def run(*args, **kwargs):
        kwargs["too_close"] = None
        return real(*args, **kwargs)

    with mock.patch.object(pipeline.layering, "run", run):
        yield


def without_times(value):
    """`value` (a design) without its wall-clock keys (any key `seconds`), for comparing two solves."""
    if isinstance(value, dict):
        return {k: without_times(v) for k, v in value.items() if k != "seconds"}
    if isinstance(value, list):
        return [without_times(v) for v in value]
    return value


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Relayering(unittest.TestCase):
    def solve(self, rounds, progress=None, cancel=None, angle=ANGLE, **settings):
        settings = dict(defaults(), relayer_rounds=rounds, **settings)
        return pipeline.solve(network_design(settings, angle), PRESETS["steel"], settings, progress, cancel)

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
            self.assertEqual(record["rounds"][0]["too_close"], [])  # without the loop, nothing up front
            self.assertNotIn("too_close_forbidden", old)
            # The first layering's hooks were the ones the chord rules out: A opening to +y at P
            # and to +x at Q (the nulled crossings keep the hook that failed).
            for crossing, axis in ((p, 1), (q, 0)):
                failed = dict(crossing, hook=nulled[crossing["id"]]["hook"])
                self.assertGreater(opening_of_a(old, failed)[axis], 0.9)

    def assert_opposite_hooks(self, new):
        """`new` is stable with A opening to -y at P and to -x at Q, and nothing nulled."""
        self.assertTrue(new["stable"], new["reason"])
        p, q = find(new, 1, 1), find(new, 2, 0)
        self.assertLess(opening_of_a(new, p)[1], -0.9)  # A opens to -y at P, the side the chord allows
        self.assertLess(opening_of_a(new, q)[0], -0.9)  # and to -x at Q
        # Every crossing the design hooks is realised: the target shape nulled nothing in the end.
        self.assertEqual(new["stages"]["target_shape"]["nulled_crossings"], [])
        self.assertEqual(new["pending_stages"], [])
        self.assertEqual(recheck(new), [])
        return p, q

    def test_the_first_round_forbids_the_too_close_hooks_up_front(self):
        messages, told = [], []
        real = pipeline.hooks_by_forces

        def hooks_by_forces(*args, **kwargs):  # what the other hook patterns must avoid
            told.append(set(kwargs["forbidden"]))
            return real(*args, **kwargs)

        with mock.patch.object(pipeline, "hooks_by_forces", hooks_by_forces):
            new = self.solve(8, progress=lambda stage, message: messages.append((stage, message)))
        p, q = self.assert_opposite_hooks(new)
        record = new["stages"]["relayering"]
        self.assertEqual(len(record["rounds"]), 1)  # no round spent learning them
        first = record["rounds"][0]
        self.assertEqual((first["stable"], first["verdict"], first["forbidden"], first["unrealised"]),
                         (True, "stable", [], []))
        # Forbidden up front: exactly the two hooks the chord rules out, A opening to +y at P and to +x
        # at Q (the piece is longer than min_segment, so the other hook of each stays allowed).
        too_close = {tuple(x) for x in first["too_close"]}
        self.assertEqual(too_close, {(p["id"], -p["hook"]), (q["id"], -q["hook"])})
        for crossing, axis in ((p, 1), (q, 0)):
            self.assertGreater(opening_of_a(new, dict(crossing, hook=-crossing["hook"]))[axis], 0.9)
        self.assertEqual(told, [too_close])
        self.assertEqual(record["forbidden"], [])
        self.assertNotIn("too_close_forbidden", new)  # the layering's own key never reaches a design.json
        self.assertEqual(sum(1 for s, _m in messages if s == "relayering"), 0)
        self.assertEqual(sum(1 for s, _m in messages if s == "layering"), 1)

    def test_told_nothing_up_front_the_loop_learns_the_opposite_hooks(self):
        messages = []
        with every_hook():
            new = self.solve(8, progress=lambda stage, message: messages.append((stage, message)))
        p, q = self.assert_opposite_hooks(new)
        record = new["stages"]["relayering"]
        self.assertGreaterEqual(len(record["rounds"]), 2)
        self.assertFalse(record["rounds"][0]["stable"])
        self.assertTrue(record["rounds"][-1]["stable"])
        self.assertEqual(record["rounds"][-1]["verdict"], "stable")
        forbidden = {tuple(x) for x in record["forbidden"]}
        self.assertIn((p["id"], -p["hook"]), forbidden)  # the first layering's hook at P
        self.assertEqual(set(map(tuple, record["rounds"][0]["unrealised"])), {tuple(f) for f in record["rounds"][1]["forbidden"]})
        for c in new["crossings"]:
            if c["hook"]:
                self.assertNotIn((c["id"], c["hook"]), forbidden)
        self.assertEqual(record["max_rounds"], 8)
        for r in record["rounds"]:
            self.assertGreater(r["seconds"], 0.0)
            self.assertEqual(r["too_close"], [])
        # Every round reports progress: a message per re-layering, and one layering per round.
        self.assertEqual(sum(1 for s, _m in messages if s == "relayering"), len(record["rounds"]) - 1)
        self.assertEqual(sum(1 for s, _m in messages if s == "layering"), len(record["rounds"]))

    def test_a_later_round_counts_the_too_close_hooks(self):
        # With the machine bending at most 60 deg the target shape cannot realise the kinks the
        # first layering picks on B and C either; the loop forbids them and layers again until the
        # layering finds no stable assembly. The reason counts every hook that last layering was
        # denied, the two too-close ones included, as the layering's own verdict does.
        told = []
        real = pipeline.hooks_by_forces

        def hooks_by_forces(*args, **kwargs):  # what the other hook patterns must avoid
            told.append(set(kwargs["forbidden"]))
            return real(*args, **kwargs)

        with mock.patch.object(pipeline, "hooks_by_forces", hooks_by_forces):
            new = self.solve(8, max_bend_deg=60.0)
        self.assertFalse(new["stable"])
        record = new["stages"]["relayering"]
        last = record["rounds"][-1]
        p, q = find(new, 1, 1), find(new, 2, 0)
        self.assertGreaterEqual(len(record["rounds"]), 2)
        for r in record["rounds"]:  # the same two pairs each round, never learnt
            self.assertEqual(len(r["too_close"]), 2)
            self.assertEqual({c for c, _h in r["too_close"]}, {p["id"], q["id"]})
            self.assertFalse({tuple(x) for x in r["too_close"]} & {tuple(x) for x in r["unrealised"]})
        # Every round whose layering was stable told hooks_by_forces both sets: the learnt pairs (none
        # in the first round, some in the second) and the too-close ones.
        self.assertEqual(told, [{tuple(x) for x in r["forbidden"] + r["too_close"]} for r in record["rounds"][:-1]])
        self.assertTrue(record["rounds"][1]["forbidden"])
        denied = len(last["forbidden"]) + len(last["too_close"])
        self.assertEqual(record["forbidden"], last["forbidden"])
        self.assertIn(f"with {denied} hooks forbidden", last["verdict"])  # the native layering's count
        ids = sorted((p["id"], q["id"]))
        self.assertTrue(new["reason"].endswith(f"; layering again without the {denied} hooks the target shape "
                                               f"cannot realise (2 of them at crossings {ids[0]} and {ids[1]}, too close "
                                               f"to a neighbour along a wire for a free bending point) finds no "
                                               f"stable assembly (stages.relayering)"),
                        new["reason"])
        self.assertEqual(new["reason_causes"], [TOO_CLOSE])  # the cause the note names, as its code
        # as codes: the loop ended on a layering with no stable assembly, the design is the round the
        # target shape failed
        self.assertEqual((record["end"], new["verdict_cause"]), (RELAYER_NO_ASSEMBLY, UNREALISED))

    def test_the_close_geometry(self):
        # P and Q 3 deg apart along A: 10.5 mm, shorter than min_segment, so neither hook of either
        # can be realised and the layering forbids all four up front.
        d = self.solve(0, angle=CLOSE_ANGLE)
        p, q = find(d, 1, 1), find(d, 2, 0)
        self.assertAlmostEqual(R * math.radians(2 * CLOSE_ANGLE - 90.0), 0.0105, places=4)
        self.assertLess(R * math.radians(2 * CLOSE_ANGLE - 90.0), d["machine"]["min_segment"])
        probe = network_design(dict(defaults()), CLOSE_ANGLE)
        layering.run(probe, PRESETS["steel"], dict(defaults()), too_close=target_shape.REALISED_ANGLE)
        self.assertEqual(sorted(map(tuple, probe["too_close_forbidden"])),
                         sorted((c["id"], h) for c in (p, q) for h in (-1, 1)))
        self.assertFalse(probe["stable"])  # without P and Q, A can turn about the line through the others

    def test_a_first_layering_stopped_by_max_nodes_does_not_fall_back(self):
        # A search that max_nodes stopped proved nothing: the loop stops on its verdict instead of
        # searching again, larger, with every hook. (Here the search with the too-close hooks
        # forbidden is made to stop at its node budget; on this network it would prove at once that
        # nothing holds, which is the fallback's case.)
        real = layering.run
        calls = []

        def stopped(design, *args, **kwargs):
            text = real(design, *args, **kwargs)
            calls.append(kwargs.get("too_close"))
            if kwargs.get("too_close") is not None:
                design.update(stable=False, search_incomplete=True, reason="search incomplete (stopped here)")
            return text

        messages = []
        with mock.patch.object(pipeline.layering, "run", stopped):
            d = self.solve(8, progress=lambda stage, message: messages.append((stage, message)), angle=CLOSE_ANGLE)
        self.assertEqual(calls, [target_shape.REALISED_ANGLE])  # one layering, with the hooks forbidden
        self.assertFalse(d["stable"])
        self.assertTrue(d.get("search_incomplete"))
        self.assertEqual(d["stages"]["relayering"]["end"], RELAYER_INCOMPLETE)
        rounds = d["stages"]["relayering"]["rounds"]
        self.assertEqual(len(rounds), 1)
        self.assertEqual(len(rounds[0]["too_close"]), 4)
        self.assertFalse([m for s, m in messages if s == "relayering"])
        self.assertNotIn("too_close_forbidden", d)

    def test_the_fallback_gives_the_every_hook_paths_design(self):
        # With relayer_rounds 1 too: the discarded layering is not one of the re-layerings, so the
        # every-hook path's round 1 still runs after it.
        for rounds in (1, 8):
            with self.subTest(relayer_rounds=rounds):
                messages = []
                new = self.solve(rounds, progress=lambda stage, message: messages.append((stage, message)),
                                 angle=CLOSE_ANGLE)
                with every_hook():
                    old = self.solve(rounds, angle=CLOSE_ANGLE)
                self.assertFalse(old["stable"])
                p, q = find(old, 1, 1), find(old, 2, 0)
                pq = f"crossings {min(p['id'], q['id'])} and {max(p['id'], q['id'])}, too close"
                # The every-hook path's verdict, the target shape's: P and Q too close, then nothing stable without them.
                self.assertIn(pq, old["reason"])
                self.assertNotIn("target_shape", old["pending_stages"])
                # The fallback's design is the every-hook path's, but for its record of the first layering.
                new_record, old_record = new["stages"].pop("relayering"), old["stages"].pop("relayering")
                self.assertEqual(without_times(new), without_times(old))
                self.assertEqual(len(old_record["rounds"]), 2)  # round 1 learns P and Q, then nothing holds
                self.assertEqual(without_times(new_record["rounds"][1:]), without_times(old_record["rounds"]))
                self.assertEqual((new_record["forbidden"], new_record["max_rounds"]), (old_record["forbidden"], rounds))
                first = new_record["rounds"][0]
                self.assertEqual(sorted(map(tuple, first["too_close"])),
                                 sorted((c["id"], h) for c in (p, q) for h in (-1, 1)))
                self.assertEqual((first["stable"], first["forbidden"], first["unrealised"]), (False, [], []))
                self.assertIn("with 4 hooks forbidden", first["verdict"])
                self.assertTrue(all(r["too_close"] == [] for r in new_record["rounds"][1:]))
                said = [m for s, m in messages if s == "relayering"]
                self.assertEqual(len(said), len(new_record["rounds"]) - 1)
                self.assertTrue(said[0].startswith(f"the layering finds no stable assembly without the 4 hooks at {pq} "),
                                said[0])
                self.assertIn("layering again with every hook", said[0])
                self.assertTrue(said[1].startswith("round 1: "), said[1])

    def test_cancel_reaches_a_later_round(self):
        seen = []

        def cancel():
            return any(stage == "relayering" and message.startswith("round 1:") for stage, message in seen)

        with self.assertRaises(pipeline.Cancelled):
            self.solve(8, progress=lambda stage, message: seen.append((stage, message)), cancel=cancel,
                       angle=CLOSE_ANGLE)
        self.assertTrue(cancel())


class Unrealisable(unittest.TestCase):
    """Which (crossing, hook) pairs a failed target shape forbids: the failed hook, or both when the
    solver's verdict on either wire says no hook cures it (the reviewer's case: a crossing 25 mm
    along the wire from its neighbour, whose fixed piece lies outside this hook's kink, must keep
    its other hook however close another crossing is in space)."""

    GAP = ("crossings 0 and 1 on wire A/0 are 25.0 mm apart along the wire; a free bending point between "
           "them needs 30.0 mm: scale the model up by 1.2x")

    def forbidden(self, *failures):
        nulled = [{"crossing": c, "hook": h, "status": status, "message": message, "cause": cause,
                   "whatever_the_hook": target_shape.whatever_the_hook(cause)}
                  for c, h, status, cause, message in failures]
        return target_shape.unrealisable({"stages": {"target_shape": {"nulled_crossings": nulled}}})

    def test_the_failed_hook_or_both(self):
        self.assertEqual(self.forbidden((0, 1, "too_close", "fixed_edge", self.GAP)), {(0, 1)})
        short = self.GAP + " (the straight piece is shorter than the minimum segment)"
        self.assertEqual(self.forbidden((0, 1, "too_close", "short_piece", short)), {(0, 1), (0, -1)})
        self.assertEqual(self.forbidden((3, -1, "open_end", "open_end", "crossing 3 is at an end of the open wire")),
                         {(3, 1), (3, -1)})
        cone = "crossing 2 on wire B/0 misses its contact cone by 3.1 deg"
        self.assertEqual(self.forbidden((2, -1, "infeasible", "cone_missed", cone)), {(2, -1)})
        rule = ("crossing 2 needs a bend of at least 130 deg (contact angle 60 deg minus twice the friction angle) "
                "but the machine bends at most 120 deg")
        self.assertEqual(self.forbidden((2, -1, "infeasible", "min_bend", rule)), {(2, 1), (2, -1)})
        self.assertEqual(target_shape.unrealisable({"stages": {}}), set())


if __name__ == "__main__":
    unittest.main()
