"""Polyline measures on (n, d) point arrays, metres."""
import itertools

import numpy as np


def point_array(points, dim=3):
    """A list of points, each `dim` numbers (a design's contour), as an (n, dim) float64 array: the
    same numbers as np.asarray(points, dtype=np.float64) in about half its time on a list of lists
    (the target-shape stage converts every contour of every solve). Anything else (an array, a
    ragged list) goes through np.asarray."""
    if isinstance(points, list) and points:
        try:
            if set(map(len, points)) == {dim}:
                flat = np.fromiter(itertools.chain.from_iterable(points), dtype=np.float64, count=dim * len(points))
                return flat.reshape(len(points), dim)
        except (TypeError, ValueError):  # not a list of lists of numbers: np.asarray says what is wrong
            pass
    return np.asarray(points, dtype=np.float64)


class ContourArrays:
    """Contours (lists of points) as float64 arrays, by the lists' identity, for the length of one
    solve: its layering hands over its new contours' arrays (the native layering's `arrays_too`)
    and its later stages read them instead of converting the same lists again (a re-layering round
    makes new contours, docs/method-target-shape.md "Coupling rounds"). The lists must not be
    edited while it is in use: a solve never edits a contour, its layering replaces them."""

    def __init__(self):
        self._by_id = {}  # id(list) -> (list, array); the list is held, so its id is not reused

    def remember(self, points, array):
        """`array`: point_array(points), computed elsewhere."""
        self._by_id[id(points)] = (points, array)

    def get(self, points):
        """point_array(points), converted once per list."""
        entry = self._by_id.get(id(points))
        if entry is None or entry[0] is not points:
            entry = (points, point_array(points))
            self._by_id[id(points)] = entry
        return entry[1]


def polyline_length(points, closed):
    """Sum of edge lengths; a closed polyline includes the edge from its last point to its first."""
    p = np.asarray(points, dtype=np.float64)
    if len(p) < 2:
        return 0.0
    # The edges and their norms as np.diff and np.linalg.norm(axis=1) compute them (the same
    # arithmetic), without their wrappers: 6 us against 17 us for a 36-point wire, once per wire
    # and round in the target shape.
    edges = np.empty((len(p) if closed else len(p) - 1,) + p.shape[1:])
    np.subtract(p[1:], p[:-1], out=edges[:len(p) - 1])
    if closed:
        edges[-1] = p[0] - p[-1]
    return float(np.sqrt(np.add.reduce(edges * edges, axis=-1)).sum())


def self_crossings(rest, closed):
    """Where a 2D polyline crosses itself: [(edge i, edge j, point (2,), s_i, s_j)] with i < j - 1,
    s the arc length from the first point. For a closed wire's rest shape its first and last edges
    (the two sides of the cut) do not count as crossing each other."""
    p = np.asarray(rest, dtype=np.float64)
    a, b = p[:-1], p[1:]
    d = b - a
    length = np.linalg.norm(d, axis=1)
    s = np.concatenate([[0.0], np.cumsum(length)])
    n = len(d)
    if n < 3:
        return []
    i, j = np.triu_indices(n, k=2)
    if closed:
        keep = ~((i == 0) & (j == n - 1))
        i, j = i[keep], j[keep]
    r, q = d[i], d[j]
    denom = r[:, 0] * q[:, 1] - r[:, 1] * q[:, 0]
    w = a[j] - a[i]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (w[:, 0] * q[:, 1] - w[:, 1] * q[:, 0]) / denom
        u = (w[:, 0] * r[:, 1] - w[:, 1] * r[:, 0]) / denom
    hit = (np.abs(denom) > 1e-18) & (t >= 0) & (t <= 1) & (u >= 0) & (u <= 1)
    # A crossing through a shared point of two edges is found twice: keep one per point.
    out = []
    for k in np.flatnonzero(hit):
        point = a[i[k]] + t[k] * r[k]
        if any(np.linalg.norm(point - o[2]) < 1e-9 for o in out):
            continue
        out.append((int(i[k]), int(j[k]), point, float(s[i[k]] + t[k] * length[i[k]]),
                    float(s[j[k]] + u[k] * length[j[k]])))
    return out
