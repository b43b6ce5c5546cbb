"""The forces the assembled structure carries (docs/method-forces.md §17) on a real design (three
great circles of a sphere), re-checked here apart from the solver: each carried force against its
shrunk pyramid by scipy's NNLS and its normal force against the mean, both from the design's own
pyramids and planes, and the carried forces against the nonlinear 3D check's (stages/stands3d.py,
Newton on the assembled rods with the weight on a table: another computation). bpy-free."""
import unittest

import numpy as np

from wiresculpt import native
from wiresculpt.core.settings import defaults
from wiresculpt.stages import stands3d

from helpers import sphere_design

MARGIN, SHARE = 0.2, 0.25  # the forces stage's carried_margin and carried_share (their defaults)


def hooked(design):
    return [c for c in design["crossings"] if c["hook"] != 0]


def common_line(design, c):
    n0, n1 = (np.asarray(design["wires"][w]["plane"]["normal"], dtype=float) for w in c["wires"])
    d = np.cross(n0, n1)
    return d / np.linalg.norm(d)


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class Carried(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.design = sphere_design()
        cls.planar = sphere_design(dict(defaults(), carried_3d=False))

    def test_the_rows_held_and_every_carried_force_lies_in_its_shrunk_pyramid(self):
        from scipy.optimize import nnls
        d = self.design
        self.assertTrue(d["stable"], d["reason"])
        self.assertIs(d["stages"]["forces"]["carried_3d"], True)
        largest = max(np.linalg.norm(c["carried_force"]) for c in hooked(d))
        self.assertGreater(largest, 0.1)  # not the zero forces every row allows
        normals = []
        for c in hooked(d):
            b = np.asarray(c["pyramid"], dtype=float)
            g = (1 - MARGIN) * b + MARGIN * b.mean(axis=0)
            f = np.asarray(c["carried_force"], dtype=float)
            _coefficients, residual = nnls(g.T, f)
            self.assertLess(residual, 1e-6 * largest, f"crossing {c['id']}: carried {f}")
            normals.append(-c["hook"] * f @ common_line(d, c))
        self.assertGreaterEqual(min(normals), SHARE * np.mean(normals) - 1e-6 * largest)

    def test_the_nonlinear_3d_check_carries_what_the_map_says(self):
        # Pre-stress alone (one node clamped, no weight): the map within 2% of the largest force.
        # (On the table the two interact: a node the pre-stress presses down finds the table, and
        # the 3D check's own forces differ from their sum by up to a fifth of the largest here.)
        d = self.design
        wires, ties, tied = stands3d.structure(d, d["material"])
        clamp = next([0, k] for k in range(len(wires[0]["start"]) - 1)
                     if all([0, k] != t[e] and [0, k + 1] != t[e] for t in ties for e in ("a", "b")))
        alone = native.structure3d(wires, ties=ties, clamps=[clamp],
                                   options=stands3d.options(d["material"], weight_factor=0.0))
        self.assertTrue(alone["converged"], alone["message"])
        by = {c["id"]: c for c in d["crossings"]}
        forces = alone["tie_forces"][len(ties) - len(tied):]
        largest = max(np.linalg.norm(f) for f in forces)
        for cid, f in zip(tied, forces):
            c = by[cid]
            prestress = np.asarray(c["carried_force"]) - np.asarray(c["carried_weight"])
            self.assertLess(np.linalg.norm(prestress - f), 0.02 * largest, f"crossing {cid}: {prestress} against {f}")
        # The weight's share: the 3D check's table (the sculpture rolled onto it as stands3d does),
        # solved at the full weight and at a thousandth of it; their difference is the weight's
        # part, which the map's share must match (within 2% of the largest force).
        turn, _supports = stands3d.resting(d)
        for w in wires:
            w["start"], w["rest"], w["normal"] = w["start"] @ turn.T, w["rest"] @ turn.T, turn @ w["normal"]
        z0 = min(float(np.min(w["start"][:, 2])) for w in wires)
        full, light = (native.structure3d(wires, ties=ties, table={"z0": z0},
                                          options=stands3d.options(d["material"], weight_factor=f)) for f in (1.0, 1e-3))
        self.assertTrue(full["converged"] and light["converged"])
        first = len(ties) - len(tied)
        for k, cid in enumerate(tied):
            part = (np.asarray(full["tie_forces"][first + k]) - np.asarray(light["tie_forces"][first + k])) @ turn / 0.999
            share = np.asarray(by[cid]["carried_weight"])
            self.assertGreater(np.linalg.norm(part), 0.0)
            self.assertLess(np.linalg.norm(share - part), 0.02 * largest, f"crossing {cid}: {share} against {part}")

    def test_it_stands_where_the_planar_forces_alone_need_not(self):
        self.assertTrue(self.design["stands_3d"]["stands"], self.design["stands_3d"])
        for c in hooked(self.design):
            self.assertTrue(c["admissible"], c["id"])

    def test_turned_off_the_forces_are_the_planar_models(self):
        p = self.planar
        self.assertIs(p["stages"]["forces"]["carried_3d"], False)
        self.assertTrue(all("carried_force" not in c for c in p["crossings"]))


if __name__ == "__main__":
    unittest.main()
