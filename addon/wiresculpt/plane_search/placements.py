"""Placements of the slicing planes and the nearby search's one-plane changes: a plane moved
along its normal, tilted about an axis in the plane, or given the other contour rule, each with
its cost (the package's docstring)."""
import math

import numpy as np

from ..core.scene import PlaneSpec
from ..core.sizes import mesh_size

OFFSETS = (0.02, 0.04, 0.07, 0.10, 0.15, 0.20)  # fractions of the model size S, both ways
TILTS_DEG = (5.0, 10.0, 15.0)
RULE_COST = 0.05


class Placement:
    """One plane as the search places it (a PlaneSpec plus what changed and what that costs)."""

    def __init__(self, name, origin, normal, contours, changes=(), cost=0.0):
        self.name, self.origin, self.contours = name, tuple(float(c) for c in origin), contours
        self.normal = tuple(float(c) for c in _unit(normal))
        self.changes, self.cost = list(changes), cost
        self._key = None

    def spec(self):
        return PlaneSpec(self.name, self.origin, self.normal, self.contours)

    def key(self):
        """(origin, normal) rounded to 1e-12: the slicing cache's key (made once; a search asks
        for it several times per candidate)."""
        if self._key is None:
            self._key = (tuple(round(c, 12) for c in self.origin), tuple(round(c, 12) for c in self.normal))
        return self._key

    def as_dict(self):
        return {"name": self.name, "origin": [float(c) for c in self.origin],
                "normal": [float(c) for c in self.normal], "contours": self.contours}


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def mesh_frame(vertices, faces):
    """(centre, axes 3x3 rows: principal axes by decreasing spread, size S) of the mesh surface
    (area-weighted triangle centroids)."""
    V = np.asarray(vertices, dtype=float)
    F = np.asarray(faces, dtype=np.int64)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    w = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    cent = (a + b + c) / 3.0
    if w.sum() <= 0:
        w = np.ones(len(F))
    centre = (w[:, None] * cent).sum(axis=0) / w.sum()
    x = cent - centre
    cov = (w[:, None] * x).T @ x / w.sum()
    values, vectors = np.linalg.eigh(cov)
    axes = vectors[:, ::-1].T.copy()
    for k in range(3):  # each axis pointing to its largest positive world component
        if axes[k][int(np.argmax(np.abs(axes[k])))] < 0:
            axes[k] = -axes[k]
    if np.ptp(values) < 1e-2 * max(values.max(), 1e-30):  # a sphere-like spread: the world axes
        axes = np.eye(3)
    return centre, axes, mesh_size(V)


def _perpendiculars(n):
    n = _unit(n)
    u = np.cross(n, [0.0, 0.0, 1.0] if abs(n[2]) < 0.9 else [1.0, 0.0, 0.0])
    u = _unit(u)
    return u, np.cross(n, u)


def _direction_word(n, sign):
    """'up'/'down' for a z-like normal, else '+x'-style words for the move along sign*n."""
    d = sign * _unit(n)
    k = int(np.argmax(np.abs(d)))
    if abs(d[k]) > 0.9:
        if k == 2:
            return "up" if d[k] > 0 else "down"
        return f"{'+' if d[k] > 0 else '-'}{'xyz'[k]}"
    return "along its normal" if sign > 0 else "against its normal"


def single_changes(plane, centre, size):
    """Every one-plane change of `plane` (a PlaneSpec) as Placements, cheapest first."""
    n = _unit(plane.normal)
    o = np.asarray(plane.origin, dtype=float)
    pivot = centre - float((centre - o) @ n) * n  # the plane's point nearest the mesh's centre
    out = []
    for f in OFFSETS:
        for sign in (1.0, -1.0):
            d = sign * f * size
            out.append(Placement(plane.name, pivot + d * n, n, plane.contours,
                                 [f"move plane {plane.name} {_direction_word(n, sign)} {abs(d) * 1000:.0f} mm"],
                                 abs(d) / size))
    u, v = _perpendiculars(n)
    for deg in TILTS_DEG:
        a = math.radians(deg)
        for axis, label in ((u, "u"), (-u, "u"), (v, "v"), (-v, "v")):
            turned = n * math.cos(a) + np.cross(axis, n) * math.sin(a)  # n turned about `axis` by a
            out.append(Placement(plane.name, pivot, _unit(turned), plane.contours,
                                 [f"tilt plane {plane.name} by {deg:g}\N{DEGREE SIGN} "
                                  f"(normal to {np.round(_unit(turned), 3).tolist()})"], a))
    other = "all" if plane.contours != "all" else "largest"
    out.append(Placement(plane.name, plane.origin, n, other,
                         [f"plane {plane.name}: use {'every contour' if other == 'all' else 'the largest contour'}"],
                         RULE_COST))
    out.sort(key=lambda p: p.cost)
    return out
