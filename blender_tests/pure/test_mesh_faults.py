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
