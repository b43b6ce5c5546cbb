"""Thin parts (core/mesh_faults.thin): a box with a rod whose thickness is known by construction.

The rod is a prism of N = 15 sides (odd: the ray from a vertex through the axis meets the middle
of the opposite side) about the x axis, of circumradius r: a vertex of an inner ring has a radial
normal (its two side faces are symmetric about it), so its inward ray crosses the rod in
r (1 + cos(pi / N)). The box is 0.2 m about the origin; the rod, from x = 0.05 m inside it to 0.2 m,
sticks out of its +x side (two shells: thin() looks at the surfaces, not at the parts). With
min_segment 15 mm the limit is 3 / pi * 15 = 14.32 mm: a rod of r = 3 mm (5.93 mm thick) is
thin, one of r = 20 mm (39.6 mm) is not."""
import math
import unittest

import numpy as np

from wiresculpt.core import mesh_faults

from test_mesh_faults import box, joined

N = 15
RINGS = 11
MIN_SEGMENT = 0.015


def rod(r, x0=0.05, x1=0.2, rings=RINGS):
    """A closed prism of N sides and `rings` rings from x0 to x1 about the x axis, capped by fans,
    its faces wound outwards."""
    RINGS = rings  # noqa: N806
    a = 2 * math.pi * np.arange(N) / N
    rings = [np.column_stack([np.full(N, x), r * np.cos(a), r * np.sin(a)]) for x in np.linspace(x0, x1, RINGS)]
    V = np.concatenate(rings + [[[x0, 0, 0], [x1, 0, 0]]])
    F = []
    for i in range(RINGS - 1):
        for k in range(N):
            a0, a1 = i * N + k, i * N + (k + 1) % N
            b0, b1 = a0 + N, a1 + N
            F += [(a0, b1, b0), (a0, a1, b1)]
    first, last = RINGS * N, RINGS * N + 1
    for k in range(N):
        F.append((first, (k + 1) % N, k))
        F.append((last, (RINGS - 1) * N + k, (RINGS - 1) * N + (k + 1) % N))
    return V, np.asarray(F)


def box_with_rod(r):
    return joined(box(offset=(-0.1, -0.1, -0.1), scale=0.2), rod(r))


def outward(V, F):
    A, B, C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    return np.einsum("ij,ij->", A, np.cross(B - A, C - A)) > 0


class ThinParts(unittest.TestCase):
    def test_the_construction(self):
        V, F = rod(0.003)
        self.assertTrue(outward(V, F))
        self.assertTrue(outward(*box(offset=(-0.1, -0.1, -0.1), scale=0.2)))

    def test_a_thin_rod_is_found_with_its_thickness_and_place(self):
        V, F = box_with_rod(0.003)
        found = mesh_faults.thin(V, F, MIN_SEGMENT)
        self.assertEqual([f["cause"] for f in found], [mesh_faults.THIN])
        fault = found[0]
        self.assertAlmostEqual(fault["thinnest"], 0.003 * (1 + math.cos(math.pi / N)), places=9)
        self.assertAlmostEqual(fault["limit"], 3 / math.pi * MIN_SEGMENT, places=12)
        # every vertex of the rod's rings is thin; not the caps' centres (their rays run along the
        # rod and meet the other cap 0.15 m on) nor the box's 8 corners
        rod_vertices = RINGS * N
        self.assertAlmostEqual(fault["share"], rod_vertices / (rod_vertices + 2 + 8), places=9)
        np.testing.assert_allclose(fault["at"], [0.125, 0.0, 0.0], atol=1e-3)
        self.assertAlmostEqual(fault["size"], 0.3)
        words = mesh_faults.sentence(fault)
        self.assertIn("as thin as 6 mm, under the 14 mm", words)
        self.assertIn("around (125, 0, 0) mm", words)
        factor = 3 / math.pi * MIN_SEGMENT / (0.003 * (1 + math.cos(math.pi / N)))  # 2.41
        self.assertIn(f"scale the model up at least {factor:.2f} times (largest side 0.3 m -> {0.3 * factor:.4g} m)",
                      words)
        self.assertIn("expect no wire there", words)

    def test_two_thin_rods_are_two_places_the_larger_one_named(self):
        # a second, shorter rod of 0.002 m out of the -x side: 6 rings from -0.2 to -0.05
        V, F = joined(box_with_rod(0.003), rod(0.002, -0.2, -0.05, rings=6))
        (fault,) = mesh_faults.thin(V, F, MIN_SEGMENT)
        self.assertEqual(fault["places"], 2)
        np.testing.assert_allclose(fault["at"], [0.125, 0.0, 0.0], atol=1e-3)  # the rod of 11 rings
        self.assertAlmostEqual(fault["thinnest"], 0.003 * (1 + math.cos(math.pi / N)), places=9)
        self.assertIn("in 2 places", mesh_faults.sentence(fault))
        self.assertIn("the largest around (125, 0, 0) mm", mesh_faults.sentence(fault))

    def test_faces_wound_inwards_give_the_same_answer(self):
        V, F = box_with_rod(0.003)
        (inwards,), (outwards,) = mesh_faults.thin(V, F[:, ::-1], MIN_SEGMENT), mesh_faults.thin(V, F, MIN_SEGMENT)
        self.assertEqual(inwards["share"], outwards["share"])
        self.assertAlmostEqual(inwards["thinnest"], outwards["thinnest"], places=12)

    def test_a_thick_rod_and_a_plain_box_are_not_thin(self):
        self.assertEqual(mesh_faults.thin(*box_with_rod(0.020), MIN_SEGMENT), [])
        self.assertEqual(mesh_faults.thin(*box(scale=0.2), MIN_SEGMENT), [])

    def test_a_finer_wire_follows_the_thin_rod(self):
        # min_segment 5 mm: the limit is 4.77 mm, under the rod's 5.93 mm
        self.assertEqual(mesh_faults.thin(*box_with_rod(0.003), 0.005), [])

    def test_a_thin_part_is_no_reason_to_close_the_mesh(self):
        V, F = rod(0.003)
        self.assertFalse(mesh_faults.needs_closing(mesh_faults.check(V, F)))
        self.assertTrue(mesh_faults.thin(V, F, MIN_SEGMENT))

    def test_the_thin_part_leads_a_failed_verdict(self):
        fault = mesh_faults.thin(*box_with_rod(0.003), MIN_SEGMENT)
        design = {"stable": False, "reason": "no stable assembly", "mesh_faults": fault, "wires": [{}, {}]}
        self.assertTrue(mesh_faults.explain(design))
        self.assertTrue(design["reason"].startswith("parts of the model are thinner than a wire can go round"))
        self.assertIn(mesh_faults.THIN, design["reason_causes"])


if __name__ == "__main__":
    unittest.main()
