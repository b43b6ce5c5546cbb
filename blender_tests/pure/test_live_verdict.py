"""The words of Live's verdict line (core/live_verdict): a long reason is shown up to the end of its
first clause, where the solver puts the deciding figure, instead of being cut after a fixed number
of words; setup problems and errors are said with their own kinds, never "not stable"."""
import unittest

from wiresculpt.core import live_verdict as lv

# A Live solve of the bundled globe with Max Bend 30° (hook_patterns=1), its reason as the pipeline
# writes it (only its first two clauses here, the others repeat them for crossings 2-5; before
# stages/target_shape.crossing_words each crossing was named twice, "…Equator/0: crossing 0 on wire
# Equator/0 needs…").
GLOBE_BEND_30 = (
    "the target shape cannot realise crossing 0 on wire Equator/0: it needs a bend of at least 60° "
    "(contact angle 120° minus twice the friction angle) but the machine bends at most 30°; crossing 1 "
    "on wire Equator/0: it needs a bend of at least 60° (contact angle 120° minus twice the friction "
    "angle) but the machine bends at most 30°; without them the assembly is no longer stable when adding "
    "Equator/0 and Meridian0/0")
# Hand-written in the solver's form of a too-close clause: its ";" inside brackets is not the end.
TOO_CLOSE = (
    "the target shape cannot realise crossings 2, 3 and 4, too close to their neighbours along the wires "
    "for a free bending point between them (the closest: crossings 0 and 6 on wire Y1/0 are 16.5 mm apart "
    "along the wire; a free bending point between them needs 30 mm: scale the model up by 1.81x, to at "
    "least 0.538 m); crossing 5 on wire Y1/0: its kink cannot be made within the machine's limits: next "
    "to it, at point 12, the wire bends 128°, more than 120°; without them the assembly is no longer "
    "stable when adding X1/0 and Z1/0; layering again without the 6 hooks the target shape cannot "
    "realise finds no stable assembly (stages.relayering)")


class ShownReason(unittest.TestCase):
    def test_first_clause_whole_with_its_deciding_number(self):
        shown = lv.shown_reason(GLOBE_BEND_30)
        self.assertEqual(shown, GLOBE_BEND_30.split(";")[0] + "…")
        self.assertTrue(shown.endswith("but the machine bends at most 30°…"), shown)
        self.assertGreater(len(shown.split()), 30)  # 30 words ended before "the machine bends at most 30°"
        self.assertNotIn("crossing 1", shown)

    def test_semicolon_inside_brackets_does_not_end_the_clause(self):
        shown = lv.shown_reason(TOO_CLOSE)
        self.assertTrue(shown.endswith("scale the model up by 1.81x, to at least 0.538 m)…"), shown)
        self.assertNotIn("crossing 5", shown)
        self.assertLessEqual(len(shown.split()), lv.CLAUSE_WORDS)

    def test_short_reason_whole(self):
        reason = ("no hook configuration can make the finished sculpture stable: even with both hook directions "
                  "allowed at every crossing, wire 'Z2/0' is held only at crossings 6 and 7, which lie on one "
                  "line, so it can turn about that line like a hinge; add a plane whose wire crosses it away "
                  "from that line")  # 54 words: the advice after the ";" is kept
        self.assertEqual(lv.shown_reason(reason), reason)
        self.assertFalse(lv.shortened(reason))
        self.assertEqual(lv.shown_reason("crossing 3 pulls  wires A/0\nand B/0 apart"),
                         "crossing 3 pulls wires A/0 and B/0 apart")

    def test_sentence_end_but_not_a_decimal_point(self):
        first = "the wire " + "bends 0.126 mm more at stages.relayering " * 4 + "than 15.000 mm."
        text = first + " " + "Then another sentence follows with many words in it " * 5
        self.assertEqual(lv.clause_end(text), len(first))
        self.assertEqual(lv.shown_reason(text), first[:-1] + "…")

    def test_one_long_clause_is_cut_at_clause_words(self):
        text = " ".join(f"w{i}" for i in range(lv.CLAUSE_WORDS + 20)) + "; the rest"
        shown = lv.shown_reason(text)
        self.assertEqual(shown, " ".join(f"w{i}" for i in range(lv.CLAUSE_WORDS)) + "…")
        self.assertTrue(lv.shortened(text))

    def test_one_clause_a_little_over_reason_words_is_whole(self):
        text = " ".join(f"w{i}" for i in range(lv.REASON_WORDS + 5))  # no clause end at all
        self.assertEqual(lv.shown_reason(text), text)  # nothing left out: no "…"
        self.assertFalse(lv.shortened(text))


class Kinds(unittest.TestCase):
    def test_each_kind_its_prefix(self):
        self.assertEqual(lv.verdict(lv.STABLE), "stable")
        self.assertEqual(lv.verdict(lv.NOT_STABLE, GLOBE_BEND_30), "not stable — " + lv.shown_reason(GLOBE_BEND_30))
        problem = "No contour is ticked: Slice, then tick the contours that become wires"
        self.assertEqual(lv.verdict(lv.CANNOT_SOLVE, problem), "cannot solve — " + problem)
        self.assertEqual(lv.verdict(lv.ERROR, "KeyError: 'x'"), "error — KeyError: 'x'")
        self.assertEqual(lv.verdict(lv.NOT_STABLE, ""), "not stable")

    def test_a_setup_problem_never_reads_not_stable(self):
        # (the panel keeps each verdict's kind beside its line, live/state.py: nothing reads the kind back from the words)
        self.assertNotIn("not stable", lv.verdict(lv.CANNOT_SOLVE, "the solver is not loaded"))


class SetupProblems(unittest.TestCase):
    """Fewer than two wires: the pipeline stops with stable false and a reason that says what to set
    up. Live calls that "cannot solve", as its other setup problems, not a verdict on a design."""

    def solved(self, wires):
        from wiresculpt import pipeline
        from wiresculpt.core.materials import PRESETS
        from wiresculpt.core.settings import defaults

        from helpers import PLANES, sphere

        V, F = sphere()
        design = pipeline.slice_and_pick(V, F, PLANES[:wires], PRESETS["steel"], defaults())
        self.assertEqual(len(design["wires"]), wires)  # a great circle per plane
        return pipeline.solve(design, PRESETS["steel"], defaults())

    def test_one_wire_cannot_solve(self):
        design = self.solved(1)
        # design.json as before: not stable, the pipeline's own sentence
        self.assertIs(design["stable"], False)
        self.assertEqual(design["reason"], "a sculpture needs at least two wires: add a plane or pick more contours")
        kind, text = lv.of_design(design)
        self.assertEqual(lv.verdict(kind, text),
                         "cannot solve — a sculpture needs at least two wires: add a plane or pick more contours")

    def test_no_wire_cannot_solve(self):
        design = self.solved(0)
        self.assertEqual(design["reason"], "no plane cuts the mesh: move the planes through the mesh")
        self.assertEqual(lv.verdict(*lv.of_design(design)),
                         "cannot solve — no plane cuts the mesh: move the planes through the mesh")

    def test_a_design_found_not_stable_is_not_stable(self):
        reason = "wire 'B/0' crosses no other wire, so nothing can hold it"
        self.assertEqual(lv.of_design({"stable": False, "reason": reason, "wires": [{}, {}]}), (lv.NOT_STABLE, reason))
        # the setup sentence inside a longer reason is some other verdict's words
        longer = "a sculpture needs at least two wires: add a plane or pick more contours; and more"
        self.assertEqual(lv.of_design({"stable": False, "reason": longer})[0], lv.NOT_STABLE)
        self.assertEqual(lv.of_design({"stable": True, "reason": ""}), (lv.STABLE, ""))


if __name__ == "__main__":
    unittest.main()
