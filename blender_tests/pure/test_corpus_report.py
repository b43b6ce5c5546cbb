"""scripts/corpus.py's report groups the unstable runs by their verdict's codes, never by the
reason's words: cause_kind on codes whose kind is known by hand, run_codes on a design, and every
run stored in docs/corpus.json carrying its codes with a named kind."""
import json
import os
import sys
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import corpus  # noqa: E402

from wiresculpt.core import design as codes  # noqa: E402

VERDICTS = codes.LAYERING_CAUSES + (codes.UNREALISED, codes.NOT_BUILDABLE) + codes.SETUP_CAUSES


def run(cause, end=codes.RELAYER_NOTHING_NEW, hooks=0):
    return {"verdict_cause": cause, "relayering_end": end, "forbidden_hooks": hooks}


class CauseKind(unittest.TestCase):
    def test_the_kinds_by_hand(self):
        kinds = corpus.CAUSE_KINDS
        self.assertEqual(corpus.cause_kind(run(codes.MECHANISM)), kinds[codes.MECHANISM])
        self.assertEqual(corpus.cause_kind(run(codes.ALONE)), kinds[codes.ALONE])
        self.assertEqual(corpus.cause_kind(run(codes.UNREALISED, codes.RELAYER_ROUNDS)), kinds[codes.UNREALISED])
        self.assertEqual(corpus.cause_kind(run(codes.NOT_BUILDABLE)), kinds[codes.NOT_BUILDABLE])
        # the loop ended on a layering without a stable assembly: whatever the returned round's verdict
        self.assertEqual(corpus.cause_kind(run(codes.UNREALISED, codes.RELAYER_NO_ASSEMBLY)), corpus.NO_ASSEMBLY_KIND)
        # a layering verdict over the allowed hooks only; a later stage's verdict is not one
        self.assertEqual(corpus.cause_kind(run(codes.MECHANISM, hooks=1)), corpus.NO_ASSEMBLY_KIND)
        self.assertEqual(corpus.cause_kind(run(codes.NO_ASSEMBLY_ORDER, hooks=4)), corpus.NO_ASSEMBLY_KIND)
        self.assertEqual(corpus.cause_kind(run(codes.UNREALISED, hooks=4)), kinds[codes.UNREALISED])
        self.assertEqual(corpus.cause_kind(run(codes.ALONE, hooks=4)), kinds[codes.ALONE])
        # a stopped search proves nothing, forbidden hooks or not
        self.assertEqual(corpus.cause_kind(run(codes.SEARCH_INCOMPLETE, codes.RELAYER_INCOMPLETE, 6)),
                         kinds[codes.SEARCH_INCOMPLETE])
        self.assertEqual(corpus.cause_kind(run("a_new_code")), "a_new_code")  # no kind yet: the code itself

    def test_every_unstable_verdict_has_a_kind(self):
        self.assertEqual([c for c in VERDICTS if c != codes.STABLE_CAUSE and c not in corpus.CAUSE_KINDS], [])

    def test_run_codes_reads_the_design(self):
        design = {"stable": False, "reason": "words", "verdict_cause": codes.UNREALISED,
                  "stages": {"layering": {"forbidden_hooks": 3}, "relayering": {"end": codes.RELAYER_NO_ASSEMBLY}}}
        self.assertEqual(corpus.run_codes(design), run(codes.UNREALISED, codes.RELAYER_NO_ASSEMBLY, 3))
        self.assertEqual(corpus.run_codes({"stages": {}}), run(None, None, 0))


class Standing(unittest.TestCase):
    def test_the_3d_figures_by_hand(self):
        design = {"stands_3d": {"cause": "slips", "max_sag": 0.00123456, "slipping": [3, 7]},
                  "stages": {"forces": {"carried_3d": True}}, "out_of_plane": {"mean_to_max_force": 0.051234},
                  "load_capacity": {"+x": 2.5, "-x": None, "+y": 1.25, "-y": 3.0, "+z": None, "-z": 4.0}}
        row = corpus.standing_figures(design)
        self.assertEqual(row, {"stands_3d": "slips", "sag_mm": 1.23, "slipping": 2, "carried": True,
                               "out_of_plane": 0.0512, "load": 1.25})
        self.assertEqual(corpus.standing_cell(row), "slips 2 (1.23)")
        self.assertEqual(corpus.standing_figures({"stable": False}), {})
        self.assertEqual(corpus.standing_cell({}), "—")


class StoredRuns(unittest.TestCase):
    def test_every_stored_run_carries_its_codes(self):
        with open(os.path.join(ROOT, "docs", "corpus.json")) as f:
            runs = json.load(f)["runs"]
        named = set(corpus.CAUSE_KINDS.values()) | {corpus.NO_ASSEMBLY_KIND}
        for r in runs:
            with self.subTest(r["name"]):
                if r["stable"] is None:  # no design: a failure or a timeout
                    continue
                self.assertIn(r["verdict_cause"], VERDICTS)
                self.assertIn(r["relayering_end"], codes.RELAYER_ENDS)
                self.assertEqual(r["verdict_cause"] == codes.STABLE_CAUSE, r["stable"])
                self.assertEqual(r["relayering_end"] == codes.RELAYER_STABLE, r["stable"])
                if not r["stable"]:
                    self.assertIn(corpus.cause_kind(r), named)


if __name__ == "__main__":
    unittest.main()
