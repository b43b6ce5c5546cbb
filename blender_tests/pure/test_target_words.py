"""How the target shape names a crossing it could not realise and decides what to forbid
(stages/target_shape.crossing_words, unrealised_summary, whatever_the_hook): by the design's id,
once, with the solver's `words` after it; the decisions follow the solver's `cause` code, never its
sentence (native/src/target_shape_messages.cpp makes both from the code)."""
import unittest

from wiresculpt import native
from wiresculpt.stages import target_shape
from wiresculpt.stages.target_shape import crossing_words, unrealised_summary, whatever_the_hook


def failure(words, crossing=7, wire="Slice A/0", status="infeasible", message="(the solver's whole sentence)"):
    return {"crossing": crossing, "wire": wire, "status": status, "hook": 1, "scale": 1.0, "message": message,
            "words": words}


class CrossingWords(unittest.TestCase):
    def test_a_predicate_follows_the_name_once_as_its_own_sentence(self):
        # TargetShapeProblem's statuses: "crossing k on wire W needs a bend of at least …", words "it needs …"
        words = crossing_words(failure("it needs a bend of at least 60° (contact angle 120° minus twice the friction "
                                       "angle) but the machine bends at most 30°"))
        self.assertEqual(words, "crossing 7 on wire Slice A/0: it needs a bend of at least 60° (contact angle 120° minus "
                                "twice the friction angle) but the machine bends at most 30°")

    def test_a_colon_message_keeps_its_colon(self):
        # optimize_target_shape's checks: "crossing k on wire W: its kink cannot be made …: next to it, …"
        words = crossing_words(failure("its kink cannot be made within the machine's limits: next to it, at point 5, "
                                       "the wire bends 61°, more than 60°"))
        self.assertEqual(words, "crossing 7 on wire Slice A/0: its kink cannot be made within the machine's limits: "
                                "next to it, at point 5, the wire bends 61°, more than 60°")

    def test_the_message_is_not_read(self):
        # A message worded otherwise (or naming another wire) changes nothing: the words are the solver's.
        for message in ("crossing 1 on wire Slice A/01 needs a bend", "", "anything at all"):
            self.assertEqual(crossing_words(failure("it needs a bend", message=message)),
                             "crossing 7 on wire Slice A/0: it needs a bend")

    def test_the_summary_names_each_crossing_once(self):
        text = unrealised_summary([failure("it needs a bend of at least 60°", 3, "Equator/0"),
                                   failure("it needs a bend of at least 60°", 5, "Equator/0")], 0.25)
        self.assertEqual(text, "the target shape cannot realise crossing 3 on wire Equator/0: it needs a bend of at "
                               "least 60°; crossing 5 on wire Equator/0: it needs a bend of at least 60°")
        self.assertEqual(text.count("on wire"), 2)


class WhateverTheHook(unittest.TestCase):
    """The causes no hook cures, worked out from the geometry each names: a straight piece under
    min_segment is there with either hook, an open end has no kink, and a contact angle ruled out by
    friction or by the bend limit is the crossing's whichever way the kink opens; a fixed piece
    outside this hook's cone, or a kink the solver did not open, may hold with the other hook."""

    def test_each_cause(self):
        every = {"short_piece", "open_end", "contact_vs_friction", "min_bend"}
        one = {"fixed_edge", "cone_missed", "neighbour_bend", "neighbour_segment", "none"}
        for cause in every:
            self.assertTrue(whatever_the_hook(cause), cause)
        for cause in one:
            self.assertFalse(whatever_the_hook(cause), cause)

    def test_the_forbidden_hooks_follow_the_cause_whatever_the_message_says(self):
        def forbidden(cause, message):
            nulled = [{"crossing": 4, "hook": -1, "status": "too_close", "message": message, "cause": cause,
                       "whatever_the_hook": whatever_the_hook(cause)}]
            return target_shape.unrealisable({"stages": {"target_shape": {"nulled_crossings": nulled}}})

        # the same verdicts with a message reworded, or worded as the other cause's
        short = "(the straight piece is shorter than the minimum segment)"
        for message in ("reworded", short, "crossing 4 asks for contact angle 10°"):
            self.assertEqual(forbidden("short_piece", message), {(4, 1), (4, -1)})
            self.assertEqual(forbidden("fixed_edge", message), {(4, -1)})


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class TheSolverGivesCauseAndWords(unittest.TestCase):
    """The native's statuses: a cause for every failed crossing and words that read, after the
    crossing's name, as its message does."""

    def solve(self, crossings):
        line = [(0.3 * k / 300, 0.0) for k in range(301)]
        return native.require().optimize_target_shape(line, False, crossings, {"wire_name": "W"})["crossings"]

    def test_a_predicate_and_a_pair(self):
        # 30° of contact: not wider than twice atan(0.32) = 35.5°; crossings 9 mm apart: a 9 mm piece < 15 mm
        friction, = self.solve([{"vertex": 150, "bisector": (0.0, 1.0), "contact_angle": 0.5236}])
        self.assertEqual((friction["status"], friction["cause"]), ("infeasible", "contact_vs_friction"))
        self.assertEqual(friction["message"], "crossing 0 on wire W " + friction["words"][len("it "):])
        self.assertTrue(friction["words"].startswith("it asks for contact angle 30°"))
        a, b = self.solve([{"vertex": 100, "bisector": (0.0, 1.0)}, {"vertex": 109, "bisector": (0.0, -1.0)}])
        for s in (a, b):
            self.assertEqual((s["status"], s["cause"]), ("too_close", "short_piece"))
            self.assertEqual(s["words"], s["message"])
        ok, = self.solve([{"vertex": 150, "bisector": (0.0, 1.0)}])
        self.assertEqual((ok["status"], ok["cause"], ok["words"], ok["message"]), ("ok", "none", "", ""))


if __name__ == "__main__":
    unittest.main()
