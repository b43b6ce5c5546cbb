"""The plane assistant's corpus table (scripts/plane_search_corpus.py) written into a planes section
by a nearby-only run (--counts ""): the given-planes and nearby cells are the run's, the auto
columns and what the header said of their run are kept as they were, the hand-written notes too,
and a second such run changes nothing. A section whose table has no auto columns is refused with a
message that says to run with --counts."""
import argparse
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                                "scripts"))
import plane_search_corpus as corpus  # noqa: E402

BEFORE = """# Performance

<!-- planes:begin -->
## Plane assistant on the real-mesh corpus

`scripts/bench planes --size 0.5 --counts 4,5 --section docs/performance.md` (2026-11-30, commit abc1234; `scripts/plane_search_corpus.py`, in-process with the system Python 3.11 and the built module, no Blender): every `zzxxy5` scene of the corpus at 0.5 m, solved with the planes as given, then with `plane_search: "nearby"` (budget 8 s), and every mesh with `"auto"` (budget 6 s per plane, then at most 20 s for the comparison of hook patterns on the returned design). Load average (1 min) of the 2-core machine, shared: 3.3 at the start, 2.9 at the end. Every stable design is re-checked by `blender_tests/pure/recheck.py`: 5 stable, 0 refused by it.

Auto: stable on 2, 1 of 2 meshes for N = 4, 5. Nearby: 0 of the 2 unstable scenes made stable.

| mesh | given planes | nearby | nearby s (screened / solved) | auto N=4 (s, screened / solved) | auto N=5 (s, screened / solved) |
|---|---|---|---|---|---|
| ant | not stable | not stable: budget ended after 7 of 90 candidates; *move it* | 8.1 (7 / 1) | stable (1.0, 3 / 3) | stable (2.0, 4 / 3) |
| bee | not stable | not stable: budget ended after 9 of 90 candidates; *move it* | 8.2 (9 / 2) | stable (3.0, 5 / 3) | not stable (4.0, 6 / 3) |

<!-- planes:notes -->
Notes by hand.
<!-- planes:end -->

The rest of the page.
"""


def row(mesh, stable, changes, seconds, screened, solved):
    return {"mesh": mesh, "off": {"stable": False, "reason": "a hinge"},
            "nearby": {"stable": stable, "reason": "", "seconds": seconds, "changes": changes, "candidates": screened,
                       "full_solves": solved}}


class NearbyOnlySection(unittest.TestCase):
    def write(self, text, rows):
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "performance.md")
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)
            corpus.section(path, rows, [], argparse.Namespace(size="0.5", counts=""), [1.5, 1.8], "def5678")
            with open(path, encoding="utf-8") as f:
                return f.read()

    def test_the_auto_columns_and_the_notes_are_kept(self):
        rows = [row("ant", True, ["move plane X1 +x 10 mm"], 1.2, 12, 3), row("bee", True, [], 0.4, 1, 2)]
        after = self.write(BEFORE, rows)
        lines = after.splitlines()
        self.assertIn("| ant | not stable | stable: move plane X1 +x 10 mm | 1.2 (12 / 3) | stable (1.0, 3 / 3) | "
                      "stable (2.0, 4 / 3) |", lines)
        self.assertIn("| bee | not stable | stable: kept as given | 0.4 (1 / 2) | stable (3.0, 5 / 3) | "
                      "not stable (4.0, 6 / 3) |", lines)
        self.assertIn("| mesh | given planes | nearby | nearby s (screened / solved) | auto N=4 (s, screened / solved) "
                      "| auto N=5 (s, screened / solved) |", lines)
        self.assertIn("|---|---|---|---|---|---|", lines)
        self.assertIn("--counts \"\" --section", after)
        self.assertIn("commit def5678", after)
        self.assertIn("The auto columns are kept from the run before (2026-11-30, commit abc1234, load 3.3 at the "
                      "start and 2.9 at the end; budget 6 s per plane", after)
        self.assertIn("Auto (the run before): stable on 2, 1 of 2 meshes for N = 4, 5. Nearby: 2 of the 2 unstable "
                      "scenes made stable.", after)
        self.assertIn("<!-- planes:notes -->\nNotes by hand.\n<!-- planes:end -->\n\nThe rest of the page.", after)
        self.assertEqual(self.write(after, rows), after)  # a second nearby-only run keeps the same auto part

    def test_a_section_without_auto_columns_is_refused(self):
        rows = [row("ant", True, [], 0.4, 1, 2)]
        bare = "\n".join(line for line in BEFORE.splitlines() if not line.startswith("|"))
        with self.assertRaises(SystemExit) as cm:
            self.write(bare, rows)
        self.assertIn("run with --counts", str(cm.exception))


if __name__ == "__main__":
    unittest.main()


def cell_from_words(reason):
    """The nearby cell as the table made it from the reason's words before the search recorded how
    it ended (the reference the record must reproduce)."""
    import re
    if not reason.startswith("no nearby placement"):
        first = reason.split("; no nearby placement")[0]
        return f"*{first[:100]}{'…' if len(first) > 100 else ''}*" + (" (budget reached)" if "budget" in reason else "")
    cut = re.search(r"budget ended the search after (\d+) of (\d+) candidates", reason)
    every = re.search(r"Every one of the (\d+) candidates was screened", reason)
    todo = re.search(r"To change: (.*?)(?:\. The planes as given: |$)", reason, re.S)
    todo = todo.group(1) if todo else ""
    head = (f"budget ended after {cut.group(1)} of {cut.group(2)} candidates" if cut else
            f"all {every.group(1)} candidates screened" if every else "")
    return f"{head}; *{todo[:160]}{'…' if len(todo) > 160 else ''}*"


class NearbyCell(unittest.TestCase):
    """The cell of a nearby search that found nothing, made from its `not_found` record, reads as the
    one made from the reason's words did, for a search the budget ended, one that screened every
    candidate, and one that stopped with candidates left otherwise."""

    def tally(self, screened_pairs, out_of_time):
        import types
        from wiresculpt.core.plane_faults import Tally
        base = [types.SimpleNamespace(name=n) for n in ("X1", "Y1")]
        singles = {0: ["a", "b"], 1: ["c"]}
        t = Tally(base, singles, 2)
        t.screened("given")
        t.fault("given", ("hinge", ("X1/0",), ("Y1/0+Z1/0",)))
        for change, family in (("a", "X1"), ("b", "X1"), ("c", "Y1")):
            t.screened(family)
            t.fault(family, ("alone", ("Y1/0",), ()), [(0, change)])
        for _ in range(screened_pairs):
            t.screened("pairs")
            t.fault("pairs", ("apart", ("X1/0",), ()), [(0, "a"), (1, "c")])
        t.out_of_time, t.seconds = out_of_time, 3.5
        return t

    def test_the_record_gives_the_cell_the_words_gave(self):
        for pairs, out_of_time, head in ((0, True, "budget ended after 4 of 6 candidates"),
                                         (2, True, "all 6 candidates screened"),
                                         (1, False, "")):
            t = self.tally(pairs, out_of_time)
            reason = t.report(25.0, 500.0, 10.0, 8.0, 0.015) + ". The planes as given: wire X1/0 turns like a hinge"
            record = {"stable": False, "reason": reason, "not_found": t.ending(0.015)}
            cell = corpus.nearby_cell(record)
            self.assertEqual(cell, cell_from_words(reason))
            self.assertTrue(cell.startswith(head + "; *"), cell)
            self.assertGreater(len(cell), len(head) + 5)  # the advice is there
        error = {"stable": False, "reason": "error: the solver refused the planes"}
        self.assertEqual(corpus.nearby_cell(error), "*error: the solver refused the planes*")
