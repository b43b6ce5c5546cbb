"""Why no nearby placement exists (plane_faults.py, plane_search.nearby's account:
with nearby, every scene ends stable or says why no nearby placement exists), on scenes whose answers
are known by hand:

- hand-made crossing networks: a wire crossing nothing ("alone"), two groups with no crossing
  between them ("apart"), a wire with its two crossings on the common line of two planes
  ("hinge"), the closest two crossings along a wire;
- a sphere (radius R) cut by A: z = 0.5 R, B: z = -0.5 R and C: x = 0. A and B cross only C, each
  at two points on one line (a hinge each), and no nearby change makes A and B cross: their planes
  stay within 15 + 15 deg of parallel, and the nearest the two can come inside the sphere is where a
  15 deg tilt meets an offset or another tilt, at |x| or |y - x| >= R / (2 tan 15 deg) = 1.87 R >
  sqrt2 R, outside it. C still crosses A and B whatever one or two changes do (A's circle at
  z = 0.9 R has radius 0.436 R > 0.4 R, C's largest offset). So every candidate fails with the same
  fault, a hinge of A/0 and of B/0 on C/0, and the search screens all of its candidates: the given
  planes, 25 one-plane changes of each plane (6 offsets and 3 tilts about 2 axes, each both ways,
  and the other contour rule) and 25 x 25 two-plane changes of each of the 3 pairs of planes:
  1 + 3 x 25 + 3 x 625 = 1951."""
import copy
import math
import re
import unittest

import numpy as np

from wiresculpt import native, pipeline, plane_search
from wiresculpt.core import plane_faults
from wiresculpt.core.design import TOO_CLOSE
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.scene import PlaneSpec

from helpers import settings, sphere

R = 0.125
CANDIDATES = 1 + 3 * 25 + 3 * 25 * 25
HINGES = ("hinge", ("A/0", "B/0"), ("C/0", "C/0"))


def P(name, origin, normal):
    return PlaneSpec(name, tuple(R * c for c in origin), normal)


PARALLEL = [P("A", (0, 0, 0.5), (0, 0, 1)), P("B", (0, 0, -0.5), (0, 0, 1)), P("C", (0, 0, 0), (1, 0, 0))]


def network(names, crossings):
    """A layered design by hand: wires by name (a straight two-point contour each, unused here),
    crossings as (wire a, wire b, point)."""
    return {"wires": [{"name": n, "contour": [[0, 0, 0], [1, 0, 0]], "closed": False} for n in names],
            "crossings": [{"id": k, "wires": [a, b], "point": list(p), "contour_vertices": [0, 0]}
                          for k, (a, b, p) in enumerate(crossings)],
            "reason": "not stable"}


class Structural(unittest.TestCase):
    # four wires as the planes z = 0 (Z/0), x = 0 (X/0), y = 0 (Y/0) and z = 1 (W/0) of a unit sphere
    # would cut them: Z, X and Y cross each other at 6 points, not on one line for any wire
    SIX = [(0, 1, (0, 1, 0)), (0, 1, (0, -1, 0)), (0, 2, (1, 0, 0)), (0, 2, (-1, 0, 0)),
           (1, 2, (0, 0, 1)), (1, 2, (0, 0, -1))]

    def test_a_wire_crossing_nothing_is_alone(self):
        d = network(["Z/0", "X/0", "Y/0", "W/0"], self.SIX)
        self.assertEqual(plane_faults.structural_fault(d), ("alone", ("W/0",), ()))

    def test_two_groups_are_apart(self):
        # W and V cross each other twice, and nothing else: the smaller part is named
        d = network(["Z/0", "X/0", "Y/0", "W/0", "V/0"],
                    self.SIX + [(3, 4, (5, 0, 0)), (3, 4, (5, 1, 1))])
        self.assertEqual(plane_faults.structural_fault(d), ("apart", ("V/0", "W/0"), ()))

    def test_a_wire_crossing_one_other_twice_hinges(self):
        # W crosses X alone, at (0, 0.5, 0.8) and (0, -0.5, 0.8): on the line x = 0, z = 0.8
        d = network(["Z/0", "X/0", "Y/0", "W/0"],
                    self.SIX + [(3, 1, (0, 0.5, 0.8)), (3, 1, (0, -0.5, 0.8))])
        self.assertEqual(plane_faults.structural_fault(d), ("hinge", ("W/0",), ("X/0",)))
        # a third crossing off that line (W crossing Y at (0.3, 0, 0.8)) holds it
        d = network(["Z/0", "X/0", "Y/0", "W/0"],
                    self.SIX + [(3, 1, (0, 0.5, 0.8)), (3, 1, (0, -0.5, 0.8)), (3, 2, (0.3, 0, 0.8))])
        self.assertEqual(plane_faults.structural_fault(d), ("mechanism", (), ("not stable",)))
        # the layering's hook-relaxed verdict: its clause naming what moves (what_moves), the words
        # the fault showed before (the reason after "… allowed at every crossing, " up to its advice)
        clause = "wire 'Z2/0' is held only at crossings 6 and 7, which lie on one line, so it can turn about that line like a hinge"
        d["reason"] = ("no hook configuration can make the finished sculpture stable: even with both hook directions "
                       f"allowed at every crossing, {clause}; add a plane whose wire crosses it away from that line")
        d["what_moves"] = clause
        self.assertEqual(plane_faults.structural_fault(d), ("mechanism", (), (clause,)))
        d["what_moves"] = "x" * 200
        self.assertEqual(plane_faults.structural_fault(d), ("mechanism", (), ("x" * 160,)))

    def test_a_screen_that_fails_is_named_by_what_decided_it(self):
        # no alone, apart or hinged wire: the layering's search stopped at max_nodes is undecided, not
        # a fault of the planes; hooks forbidden as too close that did not decide it leave a mechanism
        d = network(["Z/0", "X/0", "Y/0"], self.SIX)
        self.assertEqual(plane_faults.screen_fault(dict(d, search_incomplete=True)), ("incomplete", (), ()))
        asked = []
        mechanism = dict(d, too_close_forbidden=[[0, 1]])
        self.assertEqual(plane_faults.screen_fault(mechanism, lambda: asked.append(1) or False),
                         ("mechanism", (), ("not stable",)))
        self.assertEqual(asked, [1])  # asked whether the hooks decided it: no
        self.assertEqual(plane_faults.screen_fault(d, lambda: asked.append(2) or True), ("mechanism", (), ("not stable",)))
        self.assertEqual(asked, [1])  # nothing forbidden: not asked
        self.assertIn("max_nodes", plane_faults.describe(("incomplete", (), ())))

    def test_words_name_the_wire_and_the_counts_add_up(self):
        faults = {("hinge", ("W/0",), ("X/0",)): 41, ("hinge", ("V/0",), ("X/0+Y/0",)): 2,
                  ("alone", ("W/0",), ()): 12, ("misses", (), ("W",)): 1, ("few", (), ()): 1}
        text = plane_faults.summary(faults, 0.015, shown=2)
        self.assertTrue(text.startswith("43 hinge"), text)
        self.assertIn("wire W/0 on wire X/0 in 41", text)
        self.assertIn("wire V/0 on wire X/0 and wire Y/0 in 2", text)
        self.assertIn("12 leave a wire crossing no other wire (wire W/0)", text)
        self.assertIn("2 for 2 other reasons (misses, few)", text)  # 43 + 12 + 2 = 57 = the counts' sum
        self.assertIn("add a plane whose wire crosses wire W/0 away from its line with wire X/0",
                      plane_faults.advice([("hinge", ("W/0",), ("X/0",))]))


class Words(unittest.TestCase):
    def test_the_verdict_is_read_from_the_cause_s_code_not_its_words(self):
        # wires Z, X, Y of Structural.SIX with contours of their own: along Z/0 (the x axis, 0 to 1 m)
        # X/0 crosses at 0.10 m and Y/0 at 0.11 m, 10 mm apart (the closest), X/0 again at 0.60 m
        probe = {"wires": [{"name": "Z/0", "contour": [[0, 0, 0], [0.1, 0, 0], [0.11, 0, 0], [0.6, 0, 0], [1, 0, 0]],
                            "closed": False},
                           {"name": "X/0", "contour": [[0, 0, 0], [0.5, 0, 0]], "closed": False},
                           {"name": "Y/0", "contour": [[0, 0, 0], [0.5, 0, 0]], "closed": False}],
                 "crossings": [{"wires": [0, 1], "contour_vertices": [1, 0]},
                               {"wires": [0, 2], "contour_vertices": [2, 0]},
                               {"wires": [0, 1], "contour_vertices": [3, 1]}]}
        words = "crossings 1 and 2, too close to their neighbours along the wires for a free bending point between them"
        self.assertEqual(plane_faults.verdict_fault(probe, {"reason": "x; y", "reason_causes": [TOO_CLOSE]}),
                         ("close", ("Z/0",), ("X/0", "Y/0")))
        self.assertEqual(plane_faults.verdict_fault(probe, {"reason": words + "; then"}), ("unstable", (), (words,)))

    def test_one_wording_per_kind_in_every_place(self):
        # the kinds whose sentence and summary phrase had come apart read the same in both
        for fault, words in ((("unsolved", (), ()), "passed the screen, but the search ended before their full solve"),
                             (("slow", (), ()), "were stopped in the layering's search (its screening time)")):
            self.assertEqual(plane_faults.describe(fault), words)
            self.assertEqual(plane_faults.summary({fault: 3}), f"3 {words}")
        close = ("close", ("Y/0",), ("XA/0", "XB/0"))
        self.assertEqual(plane_faults.describe(close, 0.015),
                         "passed the screen, but have crossings closer than 2 x min_segment (30 mm) along wire Y/0, "
                         "where wires XA/0 and XB/0 cross it, which the target shape cannot realise")
        self.assertEqual(plane_faults.summary({close: 2}, 0.015),
                         "2 passed the screen, but have crossings closer than 2 x min_segment (30 mm) along a wire, "
                         "which the target shape cannot realise (wire Y/0, where wires XA/0 and XB/0 cross it)")
        self.assertEqual(plane_faults.KINDS[:3], ("misses", "few", "refused"))
        self.assertEqual(plane_faults.WIRE_KINDS, ("alone", "apart", "hinge"))
        self.assertEqual(plane_faults.PASSED_KINDS, ("near", "close", "unstable", "stopped", "failed", "unsolved",
                                                     "stable"))
        with self.assertRaises(ValueError):
            plane_faults.describe(("nonsense", (), ()))


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Closest(unittest.TestCase):
    @staticmethod
    def planes(d):
        """The sphere cut by y = 0, z = 0 and x = +-d: XA's and XB's crossings on the Y and Z circles
        are 2 R asin(d / R) apart, the closest gaps of the network."""
        return [plane_search.Placement("Y", (0, 0, 0), (0, 1, 0), "largest"),
                plane_search.Placement("Z", (0, 0, 0), (0, 0, 1), "largest"),
                plane_search.Placement("XA", (d, 0, 0), (1, 0, 0), "largest"),
                plane_search.Placement("XB", (-d, 0, 0), (1, 0, 0), "largest")]

    def test_two_planes_close_together_are_named(self):
        # d = 5 mm: 10 mm apart
        s = plane_search.Searcher(sphere(R), PRESETS["steel"], settings())
        d = 0.005
        _ok, _design, probe = s.screen_layered(self.planes(d))
        gap, wire, others = plane_faults.closest_gap(probe)
        self.assertAlmostEqual(gap, 2 * R * math.asin(d / R), delta=0.02 * gap)
        self.assertIn(wire, ("Y/0", "Z/0"))
        self.assertEqual(sorted(others), ["XA/0", "XB/0"])
        # a full solve that says so is counted as "close" on that wire, and the advice moves XA and XB apart
        solved = {"reason": "the target shape cannot realise crossings 1 and 2, too close to their neighbours along "
                            f"the wires for a free bending point between them (the closest: wire '{wire}': ...)",
                  "reason_causes": [TOO_CLOSE]}
        fault = plane_faults.verdict_fault(probe, solved)
        self.assertEqual(fault[:2], ("close", (wire,)))
        advice = plane_faults.advice([fault], 0.015)
        self.assertEqual(len(advice), 1)
        self.assertRegex(advice[0], rf"move planes X[AB] and X[AB] apart, so that their crossings along wire {wire} "
                                    r"are at least 30 mm apart")

    def test_a_placement_held_only_by_too_close_crossings_fails_the_screen(self):
        # The same four planes with d = 5 mm: every crossing of XA and XB (on Y and on Z) is 10 mm
        # along the wire from the other's, less than min_segment (15 mm), so the target shape can
        # realise neither (the straight piece between them is too short to bend) and XA and XB,
        # which cross nothing else, would be held by nothing. With every hook the layering finds
        # them stable; the screen, which forbids the hooks the target shape cannot realise, fails
        # them as "dropped", and the full pipeline agrees: not stable, for crossings too close.
        s = plane_search.Searcher(sphere(R), PRESETS["steel"], settings())
        ok, design, probe = s.screen_layered(self.planes(0.005))
        self.assertFalse(ok)
        self.assertEqual(len(probe["crossings"]), 10)  # Y-Z 2, each X plane 2 on Y and 2 on Z
        self.assertEqual(s.fault[0], "dropped")
        self.assertEqual(sorted(s.fault[2]), ["XA/0", "XB/0"])
        self.assertIn("(with 16 hooks forbidden", probe["reason"])  # both hooks of the 8 close crossings
        free = plane_search.Searcher._probe(design, [np.asarray(w["contour"]) for w in design["wires"]])
        from wiresculpt.stages import layering
        layering.run(free, PRESETS["steel"], s.settings_for(design))
        self.assertTrue(free["stable"], free["reason"])
        solved = s.solve(copy.deepcopy(design))
        self.assertFalse(solved["stable"])
        self.assertIn("too close to", solved["reason"])
        # the cause the reason names travels as a code, which the search counts the candidate by
        self.assertIn(TOO_CLOSE, solved["reason_causes"])
        fault = plane_faults.verdict_fault(probe, solved)
        self.assertEqual(fault[0], "close")
        self.assertEqual(sorted(fault[2]), ["XA/0", "XB/0"])
        text = plane_faults.describe(s.fault, 0.015)
        self.assertIn("closer than 2 x min_segment (30 mm)", text)
        # two crossings 2 R asin(d / R) apart for d = 12 mm: 24 mm, more than min_segment but less than
        # 2 min_segment; Y and Z run across XA and XB there (at 90 deg to the planes' common lines),
        # outside either hook's 60 deg cone, so the target shape can realise no hook there either
        ok, design, probe = s.screen_layered(self.planes(0.012))
        self.assertFalse(ok)
        self.assertEqual(s.fault[0], "dropped")
        gap, _wire, _others = plane_faults.closest_gap(probe)
        self.assertTrue(0.015 < gap < 0.030, gap)
        self.assertFalse(s.solve(copy.deepcopy(design))["stable"])
        # far apart (d = 40 mm: 80 mm) the crossings are realisable and the placement passes
        ok, _design, probe = s.screen_layered(self.planes(0.04))
        self.assertTrue(ok, probe["reason"])


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class NoNearbyPlacement(unittest.TestCase):
    def setUp(self):
        self.V, self.F = sphere(R)

    def test_every_candidate_is_counted_and_the_reason_names_the_hinges(self):
        found, s, _start = plane_search.nearby((self.V, self.F), PARALLEL, PRESETS["steel"], settings(), budget=600.0)
        self.assertEqual(found, [])
        self.assertEqual(s.screened, CANDIDATES)
        self.assertEqual(s.full_solves, 0)  # nothing passed the screen
        tally = s.tally
        self.assertEqual(tally.totals(), {HINGES: CANDIDATES})
        for name, family in tally.families.items():
            self.assertEqual(sum(family["faults"].values()), family["screened"], name)
            self.assertEqual(family["screened"], family["total"], name)
        self.assertEqual([tally.families[k]["total"] for k in ("given", "A", "B", "C", "pairs")],
                         [1, 25, 25, 25, 3 * 25 * 25])
        reason = plane_search.nearby_reason(s)
        self.assertTrue(reason.startswith("no nearby placement gives a stable design. Searched: planes A, B, C "
                                          "one at a time (75 changes: offsets up to 50 mm (20 % of the model's "
                                          "250 mm)"), reason)
        self.assertIn("tilts up to 15 deg", reason)
        self.assertIn(f"and two at a time (1875 pairs); {CANDIDATES} placements screened, 0 fully solved", reason)
        self.assertIn(f"Every one of the {CANDIDATES} candidates was screened", reason)
        self.assertIn("two-plane changes (1875 of 1875 screened): 1875 hinge", reason)
        self.assertIn("(wire A/0 on wire C/0 in 1875, wire B/0 on wire C/0 in 1875)", reason)
        self.assertIn("add a plane whose wire crosses wire A/0 away from its line with wire C/0", reason)
        self.assertIn("move or tilt planes A and B towards each other until their wires cross", reason)
        self.assertNotIn("budget", reason)

    def test_a_search_cut_short_says_how_much_was_left(self):
        found, s, _start = plane_search.nearby((self.V, self.F), PARALLEL, PRESETS["steel"], settings(), budget=0.0)
        self.assertEqual((found, s.screened), ([], 0))
        reason = plane_search.nearby_reason(s)
        self.assertIn(f"The 0 s budget ended the search after 0 of {CANDIDATES} candidates: {CANDIDATES} left "
                      "(the planes as given, 75 one-plane and 1875 two-plane changes)", reason)
        self.assertIn("give the search more time", reason)

    def test_the_reason_reaches_the_design(self):
        design, used = plane_search.run(self.V, self.F, PARALLEL, PRESETS["steel"], settings(plane_search="nearby"))
        given = pipeline.run(self.V, self.F, PARALLEL, PRESETS["steel"], settings())
        self.assertFalse(design["stable"])
        self.assertEqual(used, PARALLEL)
        self.assertTrue(design["reason"].startswith("no nearby placement gives a stable design. Searched: "))
        self.assertTrue(design["reason"].endswith(f". The planes as given: {given['reason']}"))
        self.assertIn("wire A/0 on wire C/0", design["reason"])
        # the record keeps the keys it had (the FORMATS contract's and the extra ones before), and adds only
        # not_found (how the search ended, as data beside the reason's words), what bounded the search
        # (limits, stopped_by, screens_cut) and the returned candidate's fidelity and coverage (none here)
        self.assertEqual(set(design["plane_search"]), {
            "mode", "planes_before", "planes_after", "changes", "candidates", "full_solves", "budget_seconds",
            "solves_stopped", "solves_failed", "final_solve", "seconds", "score", "measure", "not_found",
            "limits", "stopped_by", "screens_cut", "fidelity", "coverage"})
        self.assertIsNone(design["plane_search"]["fidelity"])
        self.assertEqual(design["plane_search"]["stopped_by"], "done")  # every candidate screened
        self.assertEqual(design["plane_search"]["planes_after"], [])
        screened = int(re.search(r"; (\d+) placements screened", design["reason"]).group(1))
        self.assertEqual(design["plane_search"]["candidates"], screened)
        ending = design["plane_search"]["not_found"]
        self.assertEqual((ending["screened"], ending["total"], ending["budget_ended"]), (screened, CANDIDATES, False))
        self.assertIn("To change: " + "; or ".join(ending["advice"]) + ". The planes as given: ", design["reason"])


if __name__ == "__main__":
    unittest.main()
