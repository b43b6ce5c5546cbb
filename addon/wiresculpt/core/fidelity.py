"""Fidelity: how much of the model's outline, as a person sees it from the front, the side and the
top, the wires trace. bpy-free (numpy only).

For each of the three orthographic views along the world axes (front: looking along +y, x to the
right and z up, as Blender's front view; side: looking along -x, y to the right, as its right
view; top: looking down z, x to the right and y up) the mesh is rendered as a mask: every triangle
projected and rasterised at pixel centres (PIXELS pixels across the model size S, the largest side
of the mesh's bounding box; a pixel is inside when its centre lies in a projected triangle, edges
included). The silhouette boundary is the set of unit pixel edges between an inside and an outside
pixel ("cracks", outer outline and holes alike: the gap between a figure's legs is outline too).
A crack is *traced* when its midpoint lies within the tolerance

    tolerance = TOLERANCE * S          (15 mm for a 0.5 m model, 9 mm at 0.3 m, 22.5 mm at 0.75 m)

of a wire projected into the view (its target shape, the contour where the wire has none). A
view's share is traced cracks / all cracks (each crack a pixel long: the share of the outline's
length, measured along the pixel grid); the fidelity is the mean of the three views' shares. A
view whose mask is empty (a flat mesh seen edge on) has no share and is left out of the mean.

The tolerance depends on the model's size only, not on the design (not on the number of planes or
their spacing), so that designs of different plane counts are compared on the same outline. At
PIXELS = 400 it is 12 pixels, so the grid's own error (half a pixel) is small beside it.

The figure is 1 when the wires lie on the silhouette outlines (a sphere's three great circles along
the axes) and falls by the share of the outline a missing limb carries; it does not look at how much
of the inside the wires cross (a wire seen edge on crosses the silhouette as a line and traces only
where it meets the outline).
"""
import math

import numpy as np

from .sizes import mesh_size

TOLERANCE = 0.03  # fraction of the model size S: a crack within this of a projected wire is traced
PIXELS = 400  # pixels across S in every view
MARGIN = 2  # pixels of empty border around the silhouette
# (name, (screen x axis, screen y axis)) of each view, in world coordinates
VIEWS = (("front", (0, 2)), ("side", (1, 2)), ("top", (0, 1)))
CHUNK = 1 << 21  # candidate pixels (or crack-segment pairs) per vectorised step


def rasterise(points, triangles, shape):
    """(H, W) bool mask of the pixels whose centres (j + 0.5, i + 0.5) lie in one of the triangles
    (edges included). `points`: (n, 2) in pixel units (x = column, y = row); `triangles`: (t, 3)
    indices into them. Triangles of no area (seen edge on) are skipped."""
    H, W = shape
    mask = np.zeros((H, W), dtype=bool)
    P = np.asarray(points, dtype=float)
    T = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    if not len(T):
        return mask
    a, b, c = P[T[:, 0]], P[T[:, 1]], P[T[:, 2]]
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    keep = np.abs(area2) > 1e-12
    a, b, c, area2 = a[keep], b[keep], c[keep], area2[keep]
    flip = area2 < 0  # every triangle counter-clockwise: inside is left of each edge
    b[flip], c[flip] = c[flip].copy(), b[flip].copy()
    lo = np.minimum(np.minimum(a, b), c)
    hi = np.maximum(np.maximum(a, b), c)
    x0 = np.clip(np.ceil(lo[:, 0] - 0.5), 0, W).astype(np.int64)
    x1 = np.clip(np.floor(hi[:, 0] - 0.5), -1, W - 1).astype(np.int64)
    y0 = np.clip(np.ceil(lo[:, 1] - 0.5), 0, H).astype(np.int64)
    y1 = np.clip(np.floor(hi[:, 1] - 0.5), -1, H - 1).astype(np.int64)
    nx, ny = x1 - x0 + 1, y1 - y0 + 1
    some = (nx > 0) & (ny > 0)
    a, b, c, x0, y0, nx, ny = a[some], b[some], c[some], x0[some], y0[some], nx[some], ny[some]
    # each edge p -> q as e(x, y) = u * x + v * y + w, >= 0 on its inside (left)
    edges = []
    for p, q in ((a, b), (b, c), (c, a)):
        u, v = -(q[:, 1] - p[:, 1]), q[:, 0] - p[:, 0]
        edges.append((u, v, -(u * p[:, 0] + v * p[:, 1])))
    # triangle by triangle, each of the nx * ny candidate pixels of its bounding box
    for _start, _stop, tri, local in _chunks(nx * ny):
        px = x0[tri] + local % nx[tri]
        py = y0[tri] + local // nx[tri]
        cx, cy = px + 0.5, py + 0.5
        inside = np.ones(len(tri), dtype=bool)
        for u, v, w in edges:
            inside &= u[tri] * cx + v[tri] * cy + w[tri] >= -1e-9
        mask[py[inside], px[inside]] = True
    return mask


def _spread(counts, first=0):
    """(row, local) of the items of rows holding `counts` items each: for every item its row
    (numbered from `first`) and its index within its row."""
    row = np.repeat(np.arange(first, first + len(counts)), counts)
    local = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
    return row, local


def _chunks(counts):
    """The rows holding `counts` items each, in runs of at most CHUNK items (one row at least):
    yields (start, stop, row, local) for rows start..stop-1, with _spread's row and local of
    their items."""
    ends = np.cumsum(counts)
    start = 0
    while start < len(counts):
        base = ends[start - 1] if start else 0
        stop = max(int(np.searchsorted(ends, base + CHUNK, side="right")), start + 1)
        yield (start, stop) + _spread(counts[start:stop], start)
        start = stop


def cracks(mask):
    """(k, 2) midpoints (x, y, pixel units) of the unit edges between an inside and an outside pixel
    of `mask` (pixels beyond its border count as outside)."""
    M = np.pad(np.asarray(mask, dtype=bool), 1)
    r, j = np.nonzero(M[:, 1:] != M[:, :-1])  # between padded columns j and j + 1: x = j
    vertical = np.stack([j.astype(float), r - 0.5], axis=1)
    i, c = np.nonzero(M[1:, :] != M[:-1, :])  # between padded rows i and i + 1: y = i
    horizontal = np.stack([c - 0.5, i.astype(float)], axis=1)
    return np.concatenate([vertical, horizontal])


def segments(polylines):
    """(A, B): (m, 2) start and end points of the segments of `polylines`, [(points (n, 2), closed)]
    (a closed one also from its last point back to its first; a single point is a segment of no
    length)."""
    A, B = [], []
    for points, closed in polylines:
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        if not len(p):
            continue
        if len(p) == 1:
            A.append(p)
            B.append(p)
            continue
        q = np.concatenate([p, p[:1]]) if closed else p
        A.append(q[:-1])
        B.append(q[1:])
    if not A:
        return np.zeros((0, 2)), np.zeros((0, 2))
    return np.concatenate(A), np.concatenate(B)


def near(points, polylines, tolerance):
    """(k,) bool: whether each of `points` (k, 2) lies within `tolerance` of a segment of
    `polylines` (as segments()). Exact point-to-segment distances, over the segments whose bounding
    box, grown by the tolerance, holds the point's cell of a grid of cells `tolerance` wide."""
    P = np.asarray(points, dtype=float).reshape(-1, 2)
    out = np.zeros(len(P), dtype=bool)
    A, B = segments(polylines)
    if not len(P) or not len(A) or not tolerance > 0:
        return out
    cell = float(tolerance)
    # each segment is listed in every cell its grown bounding box touches; a point then needs only
    # the segments of its own cell (a segment within the tolerance of a point has its grown box
    # over the point, hence over the point's cell)
    lo = np.floor((np.minimum(A, B) - tolerance) / cell).astype(np.int64)
    hi = np.floor((np.maximum(A, B) + tolerance) / cell).astype(np.int64)
    origin = lo.min(axis=0)
    lo, hi = lo - origin, hi - origin
    span = hi.max(axis=0) + 1
    nx, ny = hi[:, 0] - lo[:, 0] + 1, hi[:, 1] - lo[:, 1] + 1
    seg, local = _spread(nx * ny)
    cells = (lo[seg, 0] + local % nx[seg]) * span[1] + (lo[seg, 1] + local // nx[seg])
    order = np.argsort(cells, kind="stable")
    cells, seg = cells[order], seg[order]
    pc = np.floor(P / cell).astype(np.int64) - origin
    inside = (pc >= 0).all(axis=1) & (pc < span).all(axis=1)
    which = np.nonzero(inside)[0]
    key = pc[which, 0] * span[1] + pc[which, 1]
    first = np.searchsorted(cells, key, side="left")
    last = np.searchsorted(cells, key, side="right")
    m = last - first
    for start, stop, pt, local in _chunks(m):  # point by point, the segments of its cell
        s = seg[np.repeat(first[start:stop], m[start:stop]) + local]
        p = P[which[pt]]
        a, d = A[s], B[s] - A[s]
        length2 = (d * d).sum(axis=1)
        t = np.where(length2 > 0, ((p - a) * d).sum(axis=1) / np.where(length2 > 0, length2, 1.0), 0.0)
        t = np.clip(t, 0.0, 1.0)
        gap = p - (a + t[:, None] * d)
        hit = (gap * gap).sum(axis=1) <= tolerance * tolerance
        out[which[np.unique(pt[hit])]] = True
    return out


def traced(mask, polylines, tolerance):
    """(traced cracks, all cracks) of `mask` (cracks()) for `polylines` [(points (n, 2), closed)] in
    pixel units, `tolerance` in pixels."""
    k = cracks(mask)
    return int(near(k, polylines, tolerance).sum()), len(k)


def share(mask, polylines, tolerance):
    """The share of the outline of `mask` traced by `polylines` (traced()), None for an empty mask."""
    hit, total = traced(mask, polylines, tolerance)
    return hit / total if total else None


class View:
    """One view of a mesh: its name, screen axes (world indices), pixel size (m), the world
    coordinates of the pixel grid's corner, and the mask and its cracks."""

    def __init__(self, name, axes, vertices, faces, pixel):
        self.name, self.axes, self.pixel = name, axes, pixel
        uv = vertices[:, list(axes)]
        self.corner = uv.min(axis=0) - MARGIN * pixel
        extent = uv.max(axis=0) - uv.min(axis=0)
        W, H = (int(math.ceil(e / pixel)) + 2 * MARGIN + 1 for e in extent)
        self.mask = rasterise(self.project(vertices), faces, (H, W))
        self.cracks = cracks(self.mask)

    def project(self, points):
        """(n, 2) pixel coordinates (x = column, y = row) of world `points` (n, 3)."""
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        return (p[:, list(self.axes)] - self.corner) / self.pixel

    def share(self, shapes, tolerance):
        """Share of this view's outline within `tolerance` (m) of `shapes` [(points (n, 3), closed)]
        projected; None when the mask is empty."""
        if not len(self.cracks):
            return None
        hit = near(self.cracks, [(self.project(p), closed) for p, closed in shapes], tolerance / self.pixel)
        return float(hit.mean())


class Silhouettes:
    """The three views of a mesh (`vertices` (n, 3), `faces` (t, 3)), rendered once; fidelity() of
    any set of wires against them. `size`: the model size S (default: the mesh's)."""

    def __init__(self, vertices, faces, size=None):
        V = np.asarray(vertices, dtype=float).reshape(-1, 3)
        F = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        self.size = mesh_size(V) if size is None else float(size)
        self.pixel = self.size / PIXELS if self.size > 0 else 1.0
        self.tolerance = TOLERANCE * self.size
        self.views = [View(name, axes, V, F, self.pixel) for name, axes in VIEWS]

    def fidelity(self, shapes):
        """The design file's `fidelity` record for `shapes` [(points (n, 3), closed)]: {"share":
        mean of the views' shares (None when every view is empty), "views": {name: share or None},
        "tolerance": m, "pixel": m}."""
        views = {v.name: v.share(shapes, self.tolerance) for v in self.views}
        known = [s for s in views.values() if s is not None]
        return {"share": float(np.mean(known)) if known else None, "views": views,
                "tolerance": self.tolerance, "pixel": self.pixel}

    def of_design(self, design):
        """fidelity() of the design's wires (wire_shapes)."""
        return self.fidelity(wire_shapes(design))


def wire_shapes(design):
    """[(points (n, 3), closed)] of the design's wires: each wire's target shape (what is built),
    its contour when it has none."""
    out = []
    for w in design.get("wires") or ():
        target = w.get("target")
        points = target if target is not None and len(target) else w.get("contour")
        if points is not None and len(points):
            out.append((np.asarray(points, dtype=float).reshape(-1, 3), bool(w.get("closed"))))
    return out


def record(design, vertices, faces):
    """Writes the design's `fidelity` record (Silhouettes.fidelity of its wires against the mesh)
    and returns it."""
    design["fidelity"] = Silhouettes(vertices, faces).of_design(design)
    return design["fidelity"]
