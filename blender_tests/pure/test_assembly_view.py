"""What the assembly slider shows (core/assembly_view), on steps written by hand."""
import unittest

from wiresculpt.core import assembly_view

STEPS = [[2, 0], [3], [1]]  # a two-wire start, then one wire a step


class AssemblyViewTest(unittest.TestCase):
    def test_visible_wires_by_step(self):
        ids = [0, 1, 2, 3]
        self.assertEqual(assembly_view.visible(ids, STEPS, 0), {0, 1, 2, 3})
        self.assertEqual(assembly_view.visible(ids, STEPS, 1), {0, 2})
        self.assertEqual(assembly_view.visible(ids, STEPS, 2), {0, 2, 3})
        self.assertEqual(assembly_view.visible(ids, STEPS, 9), {0, 1, 2, 3})
        self.assertEqual(assembly_view.visible(ids, [], 2), {0, 1, 2, 3})  # no order (not stable): all

    def test_shown_lines_keep_the_entries_of_visible_wires_in_order(self):
        preview = ["w1", "w3", "w0", "w2"]
        ids = [1, 3, 0, 2]
        self.assertEqual(assembly_view.shown_lines(preview, ids, STEPS, 1), ["w0", "w2"])
        self.assertEqual(assembly_view.shown_lines(preview, ids, STEPS, 2), ["w3", "w0", "w2"])
        self.assertEqual(assembly_view.shown_lines(preview, ids, STEPS, 0), preview)
        self.assertEqual(assembly_view.shown_lines(preview, [], STEPS, 1), preview)  # no ids: all, as before


if __name__ == "__main__":
    unittest.main()
