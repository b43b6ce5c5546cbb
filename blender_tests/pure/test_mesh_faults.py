"""Mesh diagnostics (core/mesh_faults.py): separate parts and holes found with their figures, on
meshes whose answer is known by construction (boxes: their parts, faces and edges counted by hand)."""
import unittest

import numpy as np

from wiresculpt.core import mesh_faults

# a unit cube's corners and its 12 outward triangles, two per side
CORNERS = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
SIDES = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]


def box(offset=(0.0, 0.0, 0.0), scale=1.0, drop_side=None):
    faces = [t for k, (a, b, c, d) in enumerate(SIDES) if k != drop_side for t in ((a, b, c), (a, c, d))]
    return CORNERS * scale + np.asarray(offset), np.asarray(faces)


def joined(*meshes):
    V, F, n = [], [], 0
    for v, f in meshes:
        V.append(v)
        F.append(f + n)
        n += len(v)
    return np.concatenate(V), np.concatenate(F)


def soup(V, F):
    """Every triangle with its own three vertices (as an STL file gives them)."""
    return V[F].reshape(-1, 3), np.arange(3 * len(F)).reshape(-1, 3)


class MeshFaultsTest(unittest.TestCase):
    def setUp(self):
        mesh_faults._memo.clear()

    def test_one_closed_box_is_fine_also_as_a_triangle_soup(self):
        self.assertEqual(mesh_faults.check(*box()), [])
        self.assertEqual(mesh_faults.check(*soup(*box())), [])

    def test_two_separate_boxes_are_two_parts_with_a_remesh_that_joins_them(self):
        gap = 0.1
        V, F = joined(box(), box(offset=(1 + gap, 0, 0), scale=1.0))
        faults = mesh_faults.check(V, F)
        self.assertEqual([f["cause"] for f in faults], [mesh_faults.SHELLS])
        fault = faults[0]
        self.assertEqual(fault["shells"], 2)
        self.assertAlmostEqual(fault["largest_share"], 0.5, places=12)  # equal boxes: half the area each
        size = 2 + gap  # the model's largest side
        rungs = [r * size for r in mesh_faults.VOXEL_LADDER]
        # the smallest rung that fuses points `gap` apart (within a voxel: at most the first rung >= gap,
        # at least half the gap: points two cells apart never fuse)
        self.assertIn(fault["voxel"], rungs)
        self.assertLessEqual(fault["voxel"], min(r for r in rungs if r >= gap) + 1e-12)
        self.assertGreaterEqual(fault["voxel"], gap / 2)
        text = mesh_faults.sentence(fault)
        self.assertIn("the mesh has 2 separate parts", text)
        self.assertIn(f"about {fault['voxel'] * 1000:.0f} mm", text)
        # the same as a triangle soup, and a third box far away: no rung of the ladder joins it
        self.assertEqual(mesh_faults.check(*soup(V, F))[0]["shells"], 2)
        far = mesh_faults.check(*joined(box(), box(offset=(1 + gap, 0, 0)), box(offset=(40, 0, 0))))[0]
        self.assertEqual((far["shells"], far["voxel"]), (3, None))
        self.assertAlmostEqual(far["largest_share"], 1 / 3, places=12)

    def test_a_box_with_a_hole_has_its_four_boundary_edges_in_one_hole(self):
        faults = mesh_faults.check(*box(scale=0.2, drop_side=1))
        self.assertEqual([f["cause"] for f in faults], [mesh_faults.OPEN])
        self.assertEqual((faults[0]["edges"], faults[0]["holes"]), (4, 1))
        self.assertAlmostEqual(faults[0]["voxel"], mesh_faults.VOXEL_SHARE * 0.2, places=12)
        V, F = box()
        tube = mesh_faults.check(V, F[4:])  # the sides x = 0 and x = 1 gone: a square tube, two square holes
        self.assertEqual((tube[0]["edges"], tube[0]["holes"]), (8, 2))
        corner = mesh_faults.check(V, np.concatenate([F[2:10]]))  # x = 0 and z = 1 gone: one hole of 6 edges
        self.assertEqual((corner[0]["edges"], corner[0]["holes"]), (6, 1))
        self.assertIn("4 boundary edges in 1 hole", mesh_faults.sentence(faults[0]))

    def test_explain_puts_the_mesh_first_in_a_failed_verdict_only(self):
        faults = mesh_faults.check(*joined(box(), box(offset=(1.1, 0, 0))))
        failed = {"stable": False, "reason": "wire B/0 ... not connected", "mesh_faults": faults}
        self.assertTrue(mesh_faults.explain(failed))
        self.assertEqual(failed["reason"], mesh_faults.words(faults) + " (the solver: wire B/0 ... not connected)")
        self.assertEqual(failed["reason_causes"], [mesh_faults.SHELLS])
        stable = {"stable": True, "reason": "", "mesh_faults": faults}
        self.assertFalse(mesh_faults.explain(stable))
        self.assertEqual(stable["reason"], "")
        clean = {"stable": False, "reason": "r", "mesh_faults": []}
        self.assertFalse(mesh_faults.explain(clean))


if __name__ == "__main__":
    unittest.main()


class NonManifold(unittest.TestCase):
    def setUp(self):
        mesh_faults._memo.clear()

    def test_a_fin_on_a_box_edge_is_one_non_manifold_edge(self):
        V, F = box()
        # a third triangle on the edge (0, 1) of the box (x = 0, y = 0, z from 0 to 1), standing out
        V = np.concatenate([V, [[-1.0, -1.0, 0.5]]])
        F = np.concatenate([F, [[0, 1, 8]]])
        faults = {f["cause"]: f for f in mesh_faults.check(V, F)}
        self.assertEqual(faults[mesh_faults.NONMANIFOLD]["edges"], 1)
        self.assertEqual(faults[mesh_faults.OPEN]["edges"], 2)  # the fin's own two free edges
        self.assertIn("1 non-manifold edge (", mesh_faults.sentence(faults[mesh_faults.NONMANIFOLD]))


class Closing(unittest.TestCase):
    """The closing's rule, record and words (the remesh itself: blender_tests/test_mesh_closing.py)."""

    def test_the_voxel_rule_by_hand(self):
        cases = [  # (size m, min_segment m, voxel m): the smaller of 1 % and l_min / 4, at least size / 256
            (0.5, 0.015, 0.00375), (0.3, 0.015, 0.003), (0.1, 0.015, 0.001), (2.0, 0.015, 2.0 / 256),
            (0.5, 0.004, 0.5 / 256), (0.75, 0.015, 0.00375)]
        for size, segment, voxel in cases:
            with self.subTest(size=size, segment=segment):
                self.assertAlmostEqual(mesh_faults.closing_voxel(size, segment), voxel, places=6)
        self.assertEqual(mesh_faults.closing_voxel(0.5, float(np.float32(0.015))), 0.00375)  # the panel's float32

    def test_the_record_and_its_words_carry_the_figures(self):
        before = mesh_faults.check(*joined(box(drop_side=1), box(offset=(0.5, 0.2, 0.2))))
        record = mesh_faults.closing(before, [], 0.00375, 1234)
        self.assertEqual((record["boundary_edges"], record["holes"], record["shells"], record["shells_after"],
                          record["nonmanifold_edges"]), (4, 1, 2, 1, 0))
        self.assertEqual(mesh_faults.closing_sentence(record),
                         "closed 4 boundary edges (1 hole) and joined 2 parts into one by a 4 mm voxel remesh "
                         "for slicing (1234 triangles; the mesh object itself is unchanged)")
        apart = mesh_faults.closing(before, [{"cause": mesh_faults.SHELLS, "shells": 2}], 0.003, 10)
        self.assertEqual(mesh_faults.closing_sentence(apart),
                         "closed 4 boundary edges (1 hole) by a 3 mm voxel remesh for slicing (10 triangles; the mesh "
                         "object itself is unchanged); its 2 parts stay apart (too far for the remesh to join)")

    def test_specks_are_left_out_and_counted(self):
        V, F = joined(box(), box(offset=(3, 0, 0), scale=0.01), box(offset=(5, 0, 0), scale=0.5))
        kept, dropped = mesh_faults.drop_specks(V, F)
        # areas 6, 0.0006 and 1.5: the 0.01 box is under 0.1 % of 7.5006, the 0.5 box is not
        self.assertEqual(dropped, 1)
        self.assertEqual(len(kept), 24)
        self.assertFalse(np.isin(np.arange(8, 16), kept).any())

    def test_a_closed_mesh_remembers_its_closing_for_the_pipeline(self):
        V, F = box()
        record = mesh_faults.closing(mesh_faults.check(*box(drop_side=2)), [], 0.01, len(F))
        mesh_faults.remember(V, F, record)
        self.assertEqual(mesh_faults.closing_of(V, F), record)
        self.assertEqual(mesh_faults.closing_of(V.copy(), F.copy()), record)  # the same numbers
        self.assertIsNone(mesh_faults.closing_of(V + 1.0, F))

    def test_a_lost_part_leads_the_reason_of_a_failed_design_with_where_it_was(self):
        record = mesh_faults.closing([], [], 0.00375, 10, lost=0.12, lost_at=(0.1, 0.2, 0.3))
        design = {"stable": False, "reason": "wire X1/0 crosses no other wire", "mesh_faults": [],
                  "mesh_closing": record}
        self.assertTrue(mesh_faults.explain(design))
        self.assertEqual(design["reason_causes"], [mesh_faults.THIN_LOST])
        self.assertTrue(design["reason"].startswith(
            "parts of the model thinner than the 4 mm voxel (12 % of its vertices around (100, 200, 300) mm"))
        self.assertTrue(design["reason"].endswith("(the solver: wire X1/0 crosses no other wire)"))
        kept = {"stable": False, "reason": "r", "mesh_faults": [],
                "mesh_closing": mesh_faults.closing([], [], 0.00375, 10, lost=mesh_faults.LOST_SHARE)}
        self.assertFalse(mesh_faults.explain(kept))  # at the threshold nothing is said
