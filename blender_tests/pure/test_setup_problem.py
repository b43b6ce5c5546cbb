"""The pipeline's setup problems as codes (core/design.setup_problem): fewer than two wires is a
scene to set up, known by `reason_causes`, and by the design's own facts for a design stored before
that key (a .blend's); the words stay the pipeline's."""
import unittest

from wiresculpt import pipeline
from wiresculpt.core import design as vocabulary
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.settings import defaults

# The words users read, written out here (not taken from the module): they must not change.
NO_WIRES_WORDS = "no plane cuts the mesh: move the planes through the mesh"
ONE_WIRE_WORDS = "a sculpture needs at least two wires: add a plane or pick more contours"


def solved(wires):
    design = vocabulary.new_design(PRESETS["steel"], defaults())
    design["wires"] = [{"id": i, "name": f"A/{i}"} for i in range(wires)]
    return pipeline.solve(design, PRESETS["steel"], defaults())


class SetupProblem(unittest.TestCase):
    def test_the_pipeline_writes_the_code_and_the_same_words(self):
        none, one = solved(0), solved(1)
        self.assertEqual((none["stable"], none["reason"], none["reason_causes"]),
                         (False, NO_WIRES_WORDS, ["no_wires"]))
        self.assertEqual((one["stable"], one["reason"], one["reason_causes"]),
                         (False, ONE_WIRE_WORDS, ["one_wire"]))
        self.assertTrue(vocabulary.setup_problem(none))
        self.assertTrue(vocabulary.setup_problem(one))

    def test_it_is_decided_by_the_code_not_the_words(self):
        reworded = {"stable": False, "reason": "reworded", "reason_causes": ["one_wire"], "wires": [{}],
                    "pending_stages": ["layering"]}
        self.assertTrue(vocabulary.setup_problem(reworded))
        other = {"stable": False, "reason": ONE_WIRE_WORDS, "reason_causes": ["too_close"], "wires": [{}],
                 "pending_stages": ["layering"]}
        self.assertFalse(vocabulary.setup_problem(other))
        self.assertFalse(vocabulary.setup_problem(dict(reworded, stable=True)))

    def test_a_design_stored_before_the_code(self):
        """No `reason_causes`: fewer than two wires with the layering still pending is a setup problem;
        an unstable design the layering judged is not, nor a design not solved yet."""
        old = {"stable": False, "reason": ONE_WIRE_WORDS, "wires": [{"name": "A/0"}],
               "pending_stages": ["layering", "target_shape", "forces", "rest_shape"]}
        self.assertTrue(vocabulary.setup_problem(old))
        self.assertTrue(vocabulary.setup_problem(dict(old, reason=NO_WIRES_WORDS, wires=[])))
        judged = {"stable": False, "reason": "crossing 3 slips", "wires": [{"name": "A/0"}],
                  "pending_stages": ["rest_shape"]}
        self.assertFalse(vocabulary.setup_problem(judged))
        self.assertFalse(vocabulary.setup_problem(vocabulary.new_design(PRESETS["steel"], defaults())))


if __name__ == "__main__":
    unittest.main()
