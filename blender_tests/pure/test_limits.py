"""The limits a stable design can still break (core/limits.py), said in short, and the verdicts
that must then not read plainly "stable" (core/live_verdict.of_design). Designs written by hand,
each figure just over, at, or under its limit; the expected phrases written out."""
import unittest

from wiresculpt.core import live_verdict as lv
from wiresculpt.core import limits
from wiresculpt.core.limits import DEFLECTION_LIMIT, OVER_LIMITS, broken_limits, hooks_may_help


def wire(name, length=0.5, deflection=0.0, side=0.2):
    """A closed square wire of `side` metres in the xy plane with the figures the stages write."""
    return {"name": name, "closed": True, "length": length, "out_of_plane_deflection": deflection,
            "contour": [[0, 0, 0], [side, 0, 0], [side, side, 0], [0, side, 0]]}


def design(*wires, asked=3.0, reached=3.0, weakest="-z"):
    return {"stable": True, "reason": "", "wires": list(wires),
            "load_factor": {"asked": asked, "reached": reached, "weakest": weakest}}


def codes(d):
    return [code for code, _phrase in limits.limit_records(d)]


class Limits(unittest.TestCase):
    def test_within_every_limit(self):
        self.assertEqual(broken_limits(design(wire("A/0"), wire("B/0", deflection=DEFLECTION_LIMIT, length=1.0))), [])

    def test_the_load_factor_not_reached(self):
        self.assertEqual(broken_limits(design(wire("A/0"), reached=1.8726)),
                         ["holds 1.87x its weight (-z), not the 3.00x asked"])

    def test_wires_bending_out_of_their_planes(self):
        self.assertEqual(broken_limits(design(wire("A/0", deflection=0.0025), wire("B/0"))),
                         ["wire A/0 bends 2.5 mm out of its plane (limit 2.0 mm)"])
        self.assertEqual(broken_limits(design(wire("A/0", deflection=0.0025), wire("B/0", deflection=0.07087))),
                         ["2 wires bend out of their planes, B/0 by 70.9 mm (limit 2.0 mm)"])
        # just over: the figure is written with digits enough to read over the limit
        self.assertEqual(broken_limits(design(wire("A/0", deflection=0.002001))),
                         ["wire A/0 bends 2.001 mm out of its plane (limit 2.000 mm)"])

    def test_wires_longer_than_the_stock(self):
        self.assertEqual(broken_limits(design(wire("A/0", length=1.2087), wire("B/0"))),
                         ["wire A/0 is 1209 mm long, over the 1000 mm stock"])
        self.assertEqual(broken_limits(design(wire("A/0", length=1.2087), wire("B/0", length=1.05))),
                         ["2 wires are longer than the 1000 mm stock, A/0 1209 mm"])
        self.assertEqual(broken_limits(design(wire("A/0", length=1.2)), stock_length=1.5), [])

    def test_a_model_over_the_largest_size(self):
        self.assertEqual(broken_limits(design(wire("A/0", side=2.0))), ["2.00 m across, over 1.50 m"])

    def test_most_decisive_first(self):
        said = broken_limits(design(wire("A/0", deflection=0.003, length=1.1), reached=2.0))
        self.assertEqual([s.split()[0] for s in said], ["holds", "wire", "wire"])

    def test_a_design_without_these_figures_breaks_none(self):
        self.assertEqual(broken_limits({"stable": True, "wires": [{"name": "A/0"}]}), [])
        # a hand-edited design with figures of the wrong kind is not a crash at every redraw
        self.assertEqual(broken_limits({"stable": True, "load_factor": 3, "wires": [7, {"name": "A/0"}]}), [])

    def test_a_factor_just_short_reads_short(self):
        self.assertEqual(broken_limits(design(wire("A/0"), reached=2.999)), ["holds 2.999x its weight (-z), not the 3.000x asked"])

    def test_which_limits_another_hook_pattern_may_keep(self):
        self.assertTrue(hooks_may_help(codes(design(wire("A/0"), reached=2.0))))
        self.assertTrue(hooks_may_help(codes(design(wire("A/0", deflection=0.01)))))
        self.assertFalse(hooks_may_help(codes(design(wire("A/0", length=1.5), wire("B/0", side=2.0)))))

    def test_each_phrase_has_its_code(self):
        over = design(wire("A/0", deflection=0.003, length=1.1), wire("B/0", side=2.0), reached=2.0)
        self.assertEqual(limits.limit_records(over), [
            ("load_factor", "holds 2.00x its weight (-z), not the 3.00x asked"),
            ("deflection", "wire A/0 bends 3.0 mm out of its plane (limit 2.0 mm)"),
            ("stock", "wire A/0 is 1100 mm long, over the 1000 mm stock"),
            ("size", "2.00 m across, over 1.50 m")])
        self.assertEqual(broken_limits(over), [p for _c, p in limits.limit_records(over)])


class Verdict(unittest.TestCase):
    def test_a_stable_design_over_a_limit_is_not_plainly_stable(self):
        over = design(wire("A/0", deflection=0.0025), wire("B/0"))
        self.assertEqual(lv.of_design(over), (OVER_LIMITS, "wire A/0 bends 2.5 mm out of its plane (limit 2.0 mm)"))
        line = lv.verdict(*lv.of_design(over))
        self.assertEqual(line, "stable, over its limits — wire A/0 bends 2.5 mm out of its plane (limit 2.0 mm)")
        self.assertEqual(codes(over), ["deflection"])  # the code Live keeps beside the line
        self.assertEqual(lv.of_design(design(wire("A/0"), wire("B/0"))), (lv.STABLE, ""))

    def test_a_design_not_stable_keeps_its_reason(self):
        failed = dict(design(wire("A/0", deflection=0.01), wire("B/0")), stable=False, reason="crossing 2 slips")
        self.assertEqual(lv.of_design(failed), (lv.NOT_STABLE, "crossing 2 slips"))


if __name__ == "__main__":
    unittest.main()
