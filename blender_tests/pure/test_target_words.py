"""How the target shape names a crossing it could not realise (stages/target_shape.crossing_words,
unrealised_summary): by the design's id, once, with the solver's words after it (the solver's
messages, native/src/target_shape.cpp, open with its own per-wire number)."""
import unittest

from wiresculpt.stages.target_shape import crossing_words, unrealised_summary


def failure(message, crossing=7, wire="Slice A/0", status="infeasible"):
    return {"crossing": crossing, "wire": wire, "status": status, "hook": 1, "scale": 1.0, "message": message}


class CrossingWords(unittest.TestCase):
    def test_a_predicate_follows_the_name_once_as_its_own_sentence(self):
        # TargetShapeProblem's statuses: "crossing k on wire W needs a bend of at least …"
        words = crossing_words(failure("crossing 0 on wire Slice A/0 needs a bend of at least 60° (contact angle "
                                       "120° minus twice the friction angle) but the machine bends at most 30°"))
        self.assertEqual(words, "crossing 7 on wire Slice A/0: it needs a bend of at least 60° (contact angle 120° minus "
                                "twice the friction angle) but the machine bends at most 30°")

    def test_a_colon_message_keeps_its_colon(self):
        # optimize_target_shape's checks: "crossing k on wire W: its kink cannot be made …: next to it, …"
        words = crossing_words(failure("crossing 2 on wire Slice A/0: its kink cannot be made within the machine's "
                                       "limits: next to it, at point 5, the wire bends 61°, more than 60°"))
        self.assertEqual(words, "crossing 7 on wire Slice A/0: its kink cannot be made within the machine's limits: "
                                "next to it, at point 5, the wire bends 61°, more than 60°")

    def test_another_wire_s_name_or_other_words_are_kept_whole(self):
        # A wire whose name starts like another's ("Slice A/0" and "Slice A/01") is not cut short.
        self.assertEqual(crossing_words(failure("crossing 1 on wire Slice A/01 needs a bend", wire="Slice A/0")),
                         "crossing 7 on wire Slice A/0: crossing 1 on wire Slice A/01 needs a bend")
        self.assertEqual(crossing_words(failure("the kink could not be opened")),
                         "crossing 7 on wire Slice A/0: the kink could not be opened")

    def test_the_summary_names_each_crossing_once(self):
        text = unrealised_summary([failure("crossing 0 on wire Equator/0 needs a bend of at least 60°", 3, "Equator/0"),
                                   failure("crossing 1 on wire Equator/0 needs a bend of at least 60°", 5, "Equator/0")],
                                  0.25)
        self.assertEqual(text, "the target shape cannot realise crossing 3 on wire Equator/0: it needs a bend of at "
                               "least 60°; crossing 5 on wire Equator/0: it needs a bend of at least 60°")
        self.assertEqual(text.count("on wire"), 2)


if __name__ == "__main__":
    unittest.main()
