"""What is wrong with a mesh as the model of one wire sculpture, and what to do (bpy-free).

A sculpture's wires hang together only through their crossings, so a mesh of several separate
parts (shells) gives wires of one part that cannot hold another, and a mesh with holes (boundary
edges) gives open contours where the planes cross them. These are faults of the mesh, not of
the planes: when a design is not stable, its verdict says them first (explain), with what to do
(join the parts, or close the mesh by a voxel remesh of about the size given).

    check(vertices, faces)  -> [fault, ...]  causes as codes with their figures (below)
    sentence(fault)         -> the words of one fault, made only here
    explain(design)         a design that is not stable and whose mesh has faults: the mesh's
                            words lead its reason, the codes join reason_causes; a mesh closed
                            for slicing (design["mesh_closing"]) that left an obstacle says it
    closing_voxel(size, min_segment)  m: the voxel of the closing remesh (the rule below)
    closing(before, after, voxel, lost)  the record of a closing (CLOSED, its figures)
    closing_sentence(record) what was done, in words ("closed 223 boundary edges ... by a 4 mm
                            voxel remesh")

Faults (each a dict with "cause" and its figures):
- SHELLS: "shells" separate parts (faces joined through shared edges or vertices, after welding
  vertices that coincide), "largest_share" the largest part's share of the surface area,
  "voxel" (m) the voxel size of a remesh that would join them (VOXEL_LADDER: the smallest rung
  at which every part lies within one voxel of another part, through the others), None when no
  rung does.
- OPEN: "edges" boundary edges (used by one face), "holes" their loops, "voxel" (m) a remesh
  size that closes them (VOXEL_SHARE of the model's size).
- NONMANIFOLD: "edges" edges shared by more than two faces (after welding).

Thin parts (thin(vertices, faces, min_segment), apart from check(): a thin part is no reason to
close the mesh, and its threshold depends on the wire):
- THIN: "share" of the vertices where the model is thinner than "limit" (m), "places" how many
  separate places they make (thin vertices in neighbouring cells of the limit's size, or joined
  by an edge of the mesh, are one place), of the place with the most of them "thinnest" (m) its least thickness and "at" the
  centre of its bounding box (m); "size" the model's size (m, for the scale advice). A vertex's local thickness is the distance from it, inwards
  along its normal (area-weighted, flipped when the faces wind inwards), to the first face the ray
  leaves the solid through (numpy, faces found through a grid of cells of the limit's size; at
  most THIN_RAYS vertices, evenly spread over the mesh's vertex list). The limit is THIN_SEGMENTS
  of min_segment (l_min): a closed wire around a part is a polygon of at least three straight
  pieces of at least l_min each, a perimeter of at least 3 l_min, and a section of width t has a
  perimeter of about pi t, so a part narrower than 3 / pi l_min (about one l_min) holds no closed
  wire around it; a plane through it gives a contour the wire can only cut across. Reported when
  more than THIN_SHARE of the vertices are that thin; what to do: scale the model up (by limit /
  thinnest), thicken the part, or expect no wire there.

Closing for slicing (blend/mesh.py does it, in Blender, on a temporary copy: the user's mesh object
is never changed): every hole is capped (its boundary loop filled) and the capped mesh remeshed by
voxels, which fuses overlapping or touching parts into one surface and mends non-manifold edges.
The voxel (closing_voxel) is the smallest of CLOSE_SHARE of the model's size and CLOSE_SEGMENTS of
the wire's bend spacing (settings min_segment, l_min: the wire cannot follow a detail shorter than
that, and the remesh moves the surface by at most about half a voxel), but never under
1/CLOSE_CELLS of the model's size (the grid's cells along its largest side: time and memory). At
0.5 m and the default l_min of 15 mm that is 3.75 mm ("a 4 mm voxel remesh"). Parts thinner than
about a voxel vanish in the remesh: the record's "lost" is the share of the original vertices
farther than a voxel from the closed surface, "lost_at" the centre of their bounding box, said when
the design fails (a thin limb is then the obstacle).

The record (CLOSED) has "boundary_edges", "holes", "nonmanifold_edges", "shells" (parts before),
"shells_after" (parts of the closed mesh), "voxel" (m), "triangles" (of the closed mesh), "lost",
"lost_at" (None when nothing was lost), "specks" (parts of the closed mesh under SMALL_SHARE of
its surface, left out: remesh debris no wire can use).
"""
import hashlib

import numpy as np

from .design import setup_problem
from .sizes import mesh_size, scale_words

SHELLS = "mesh_shells"  # the mesh is several separate parts
OPEN = "mesh_open"      # the mesh has boundary edges (holes)
NONMANIFOLD = "mesh_nonmanifold"  # the mesh has edges shared by more than two faces
CODES = (SHELLS, OPEN, NONMANIFOLD)
CLOSED = "mesh_closed"  # what was done: the mesh closed for slicing (closing)
# the obstacle a closed mesh can hold beyond check()'s faults of it (parts the remesh could not join
# stay SHELLS), said when the design fails (explain adds it to reason_causes)
THIN_LOST = "mesh_thin_lost"    # parts thinner than the voxel vanished in the remesh
THIN = "mesh_thin"              # parts thinner than a closed wire around them can be (thin)

WELD = 1e-9              # of the model's size: vertices closer than this are one
VOXEL_SHARE = 0.015      # of the model's size: a remesh that closes small holes and keeps the shape
VOXEL_LADDER = (0.005, 0.01, 0.015, 0.02, 0.03, 0.05)  # of the model's size: remesh sizes tried
SMALL_SHARE = 0.001      # of the surface area: a shell smaller than this is a speck, still counted
CLOSE_SHARE = 0.01       # of the model's size: the closing voxel at most (keeps a small model's shape)
CLOSE_SEGMENTS = 0.25    # of min_segment (l_min): the closing voxel at most (below what a wire shows)
CLOSE_CELLS = 256        # cells along the model's largest side at most: the closing voxel at least
LOST_SHARE = 0.005       # of the original vertices: more than this far from the closed surface is a part lost
THIN_SEGMENTS = 3 / np.pi  # of min_segment (l_min): the thinnest part a closed wire goes round (module doc)
THIN_SHARE = 0.005       # of the vertices (rays cast): more than this thin is a thin part
THIN_RAYS = 20000        # vertices whose thickness is measured at most
THIN_CELLS = 4_000_000   # (face, cell) entries of the grid at most: beyond, its cells grow
THIN_PAIRS = 5_000_000   # (ray, face) pairs tested at most (about a second): beyond, fewer rays

_closed = {}  # the last closed mesh: "V", "F", "digest", "record" (remember, closing_of)
_thin_memo = {}  # the last thin() answer: "key" (digest, min_segment), "faults"
_memo = {}  # the last mesh: "V", "F" (the arrays asked about), "digest", "faults" (Live slices it again and again)


def _roots(parent):
    """Each element's root in the union-find forest `parent`, by pointer jumping."""
    while True:
        up = parent[parent]
        if np.array_equal(up, parent):
            return parent
        parent = up


def _components(count, pairs):
    """(labels 0..k-1, k): the connected components of `count` nodes joined by `pairs` ((m, 2))."""
    parent = np.arange(count)
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    while len(pairs):
        a, b = parent[pairs[:, 0]], parent[pairs[:, 1]]
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        moved = lo != hi
        if not moved.any():
            break
        np.minimum.at(parent, hi[moved], lo[moved])
        parent = _roots(parent)
        pairs = pairs[moved]
    parent = _roots(parent)
    _unique, labels = np.unique(parent, return_inverse=True)
    return labels, int(labels.max()) + 1 if count else 0


def _weld(V, size):
    """(each vertex's welded index, welded count): vertices within WELD of the model's size are one."""
    tol = max(size * WELD, 1e-300)
    q = np.round((V - V.min(axis=0)) / tol)
    order = np.lexsort((q[:, 2], q[:, 1], q[:, 0]))
    new = np.ones(len(V), dtype=bool)
    new[1:] = np.any(q[order][1:] != q[order][:-1], axis=1)
    inverse = np.empty(len(V), dtype=np.int64)
    inverse[order] = np.cumsum(new) - 1
    return inverse, int(inverse.max()) + 1


# half of the 26 neighbouring cells and the cell itself: a pair of cells is looked at once
_OFFSETS = [o for o in np.array(np.meshgrid([-1, 0, 1], [-1, 0, 1], [-1, 0, 1], indexing="ij")).reshape(3, -1).T
            if tuple(o) >= (0, 0, 0)]


def _joins(P, labels, shells, h):
    """Whether every shell lies within about `h` of another, through the others: points in the
    same or neighbouring cells of side `h` fuse (a voxel remesh of that size)."""
    cells = np.floor((P - P.min(axis=0)) / h).astype(np.int64) + 1
    span = cells.max(axis=0) + 2
    home = np.unique(((cells[:, 0] * span[1] + cells[:, 1]) * span[2] + cells[:, 2]) * shells + labels)
    key, label = np.divmod(home, shells)
    pairs = []
    for dx, dy, dz in _OFFSETS:
        shifted = key + (dx * span[1] + dy) * span[2] + dz
        # the neighbours shifted into a cell meet the cell's own points: sorted by key, own first
        merged = np.concatenate([key * 2, shifted * 2 + 1])
        order = np.argsort(merged, kind="stable")
        k, both = merged[order] // 2, np.concatenate([label, label])[order]
        own = (merged[order] % 2) == 0
        first = np.searchsorted(k, k, side="left")
        join = own[first] & (both[first] != both)
        if join.any():
            pairs.append(np.column_stack([both[first][join], both[join]]))
    return bool(pairs) and _components(shells, np.concatenate(pairs))[1] == 1


def _joining_voxel(P, labels, shells, size):
    """m: the smallest rung of VOXEL_LADDER (times `size`) at which the shells fuse (_joins); None
    when even the largest does not. `P`: points, `labels`: their shells (0..shells-1)."""
    rungs = [share * size for share in VOXEL_LADDER]
    if not _joins(P, labels, shells, rungs[-1]):
        return None
    lo, hi = -1, len(rungs) - 1  # rungs[hi] joins; rungs[lo] does not (or lo = -1)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if _joins(P, labels, shells, rungs[mid]):
            hi = mid
        else:
            lo = mid
    return rungs[hi]


def check(vertices, faces):
    """The mesh's faults as a sculpture's model (module doc): [] for one closed part."""
    if _memo and _memo["V"] is vertices and _memo["F"] is faces:  # the very arrays of the last call
        return [dict(f) for f in _memo["faults"]]
    V = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    F = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if not len(V) or not len(F):
        return []
    digest = hashlib.blake2b(V.tobytes() + F.tobytes(), digest_size=16).digest()
    if _memo and _memo["digest"] == digest:
        return [dict(f) for f in _memo["faults"]]
    size = mesh_size(V)
    index, count = _weld(V, size)
    F = index[F]
    F = np.unique(np.sort(F, axis=1), axis=0)  # a repeated triangle is dropped, as the slicer drops it
    P = np.zeros((count, 3))
    P[index] = V
    faults = []
    edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    edges = edges[edges[:, 0] != edges[:, 1]]  # a degenerate face's collapsed edge joins nothing
    labels, _all = _components(count, edges)
    touched = np.unique(F)  # vertices of no face are no part
    present, labels_touched = np.unique(labels[touched], return_inverse=True)
    shells = len(present)
    if shells > 1:
        corner = P[F]
        area = 0.5 * np.linalg.norm(np.cross(corner[:, 1] - corner[:, 0], corner[:, 2] - corner[:, 0]), axis=1)
        shell_of = np.searchsorted(present, labels[F[:, 0]])
        by_shell = np.bincount(shell_of, weights=area, minlength=shells)
        total = float(by_shell.sum()) or 1.0
        faults.append({"cause": SHELLS, "shells": shells, "largest_share": float(by_shell.max() / total),
                       "voxel": _joining_voxel(P[touched], labels_touched.reshape(-1), shells, size)})
    keys, counts = np.unique(edges[:, 0] * count + edges[:, 1], return_counts=True)
    boundary = np.column_stack(np.divmod(keys[counts == 1], count))
    if len(boundary):
        _l, _k = _components(count, boundary)
        holes = len(np.unique(_l[np.unique(boundary)]))
        faults.append({"cause": OPEN, "edges": int(len(boundary)), "holes": holes, "voxel": VOXEL_SHARE * size})
    nonmanifold = int((counts > 2).sum())
    if nonmanifold:
        faults.append({"cause": NONMANIFOLD, "edges": nonmanifold})
    _memo.update(V=vertices, F=faces, digest=digest, faults=[dict(f) for f in faults])
    return faults


def _vertex_normals(P, F):
    """Unit area-weighted vertex normals of the welded mesh (P, F), turned outwards when the faces
    wind inwards (negative signed volume); zero for a vertex of no face."""
    A, B, C = P[F[:, 0]], P[F[:, 1]], P[F[:, 2]]
    cross = np.cross(B - A, C - A)  # twice the area times the face's normal
    if np.einsum("ij,ij->", A, cross) < 0:  # six times the signed volume
        cross = -cross
    N = np.zeros_like(P)
    for k in range(3):
        np.add.at(N, F[:, k], cross)
    length = np.linalg.norm(N, axis=1)
    return np.divide(N, length[:, None], out=np.zeros_like(N), where=length[:, None] > 0), cross


def _cells(lo, hi, h, origin):
    """Integer cell ranges (first, last) of boxes lo..hi ((n, 3)) on a grid of side h."""
    return (np.floor((lo - origin) / h).astype(np.int64), np.floor((hi - origin) / h).astype(np.int64))


def _expand(first, last):
    """(owner, cell (m, 3)): every cell of every box first..last (inclusive ranges, (n, 3))."""
    span = last - first + 1
    count = span.prod(axis=1)
    owner = np.repeat(np.arange(len(first)), count)
    k = np.arange(len(owner)) - np.repeat(np.cumsum(count) - count, count)  # index inside the box
    s = span[owner]
    offset = np.column_stack([k // (s[:, 1] * s[:, 2]), (k // s[:, 2]) % s[:, 1], k % s[:, 2]])
    return owner, first[owner] + offset


def local_thickness(P, F, reach, rays):
    """m: for each vertex in `rays` (indices into the welded mesh P, F), the distance inwards along
    its normal to the first face the ray leaves the solid through (not one touching the vertex or
    a neighbour of it), when within `reach`; inf
    otherwise (or for a vertex without a normal); nan for a ray left out (THIN_PAIRS)."""
    normals, cross = _vertex_normals(P, F)
    out = np.full(len(rays), np.inf)
    if not len(rays) or not len(F):
        return out
    origin = P.min(axis=0)
    corner = P[F]
    h = reach
    while True:  # the grid's cells: faces much larger than the reach would fill too many
        f_first, f_last = _cells(corner.min(axis=1), corner.max(axis=1), h, origin)
        if (f_last - f_first + 1).prod(axis=1).sum() <= THIN_CELLS:
            break
        h *= 2
    face_of, face_cell = _expand(f_first, f_last)
    dims = np.maximum(f_last.max(axis=0), np.floor((P.max(axis=0) + reach - origin) / h).astype(np.int64)) + 3

    def key(cell):
        c = cell + 1  # a cell at -1 (a ray's end below the origin) keeps a non-negative key
        return (c[:, 0] * dims[1] + c[:, 1]) * dims[2] + c[:, 2]

    # vertex pairs (a * len(P) + b) of each vertex with itself and with its neighbours
    edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    ring = np.unique(np.concatenate([edges[:, 0] * len(P) + edges[:, 1], edges[:, 1] * len(P) + edges[:, 0],
                                     np.arange(len(P)) * (len(P) + 1)]))
    face_key = key(face_cell)
    order = np.argsort(face_key, kind="stable")
    face_key, face_of = face_key[order], face_of[order]
    o = P[rays]
    d = -normals[rays]
    end = o + reach * d
    r_first, r_last = _cells(np.minimum(o, end), np.maximum(o, end), h, origin)
    ray_of, ray_cell = _expand(r_first, r_last)
    k = key(ray_cell)
    lo, hi = np.searchsorted(face_key, k, "left"), np.searchsorted(face_key, k, "right")
    per_ray = np.bincount(ray_of, weights=hi - lo, minlength=len(rays))
    # a small dense part puts many faces in each cell: beyond THIN_PAIRS (ray, face) pairs in all,
    # every so-many-th ray only (the others stay inf)
    step = max(1, int(np.ceil(per_ray.sum() / THIN_PAIRS)))
    keep = (ray_of % step) == 0
    ray_of, lo, hi = ray_of[keep], lo[keep], hi[keep]
    out[np.arange(len(rays)) % step != 0] = np.nan
    bounds = np.searchsorted(np.cumsum(hi - lo), np.arange(1, int((hi - lo).sum() // 1_000_000) + 1) * 1_000_000)
    for part in np.split(np.arange(len(ray_of)), np.unique(bounds)):  # about a million pairs at a time
        if not len(part):
            continue
        n = hi[part] - lo[part]
        ray = np.repeat(ray_of[part], n)
        at = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n) + np.repeat(lo[part], n)
        face = face_of[at]
        pair = np.unique(ray * len(F) + face)
        ray, face = np.divmod(pair, len(F))
        # the faces touching the ray's vertex or its neighbours: a ray grazes them on a curved or
        # creased surface (a hit at about no distance), and no part is as thin as its own faces
        near = np.isin(rays[ray][:, None] * len(P) + F[face], ring).any(axis=1)
        ray, face = ray[~near], face[~near]
        exits = np.einsum("ij,ij->i", cross[face], d[ray]) > 0  # leaving the solid: the face looks along the ray
        ray, face = ray[exits], face[exits]
        A = P[F[face, 0]]
        e1, e2 = P[F[face, 1]] - A, P[F[face, 2]] - A
        dr = d[ray]
        p = np.cross(dr, e2)
        det = np.einsum("ij,ij->i", e1, p)
        ok = np.abs(det) > 1e-300
        inv = np.divide(1.0, det, out=np.zeros_like(det), where=ok)
        sv = o[ray] - A
        u = np.einsum("ij,ij->i", sv, p) * inv
        q = np.cross(sv, e1)
        v = np.einsum("ij,ij->i", dr, q) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0) & (t <= reach)
        np.minimum.at(out, ray[hit], t[hit])
    out[~(np.linalg.norm(normals[rays], axis=1) > 0) & ~np.isnan(out)] = np.inf
    return out


def thin(vertices, faces, min_segment):
    """[THIN fault] when more than THIN_SHARE of the mesh's vertices lie where it is thinner than
    THIN_SEGMENTS * min_segment (module doc), else []."""
    V = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    F = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if not len(V) or not len(F) or not min_segment > 0:
        return []
    memo_key = (_digest(V, F), float(min_segment))  # Live slices the same mesh again and again
    if _thin_memo.get("key") == memo_key:
        return [dict(f) for f in _thin_memo["faults"]]
    faults = _thin(V, F, min_segment)
    _thin_memo.update(key=memo_key, faults=[dict(f) for f in faults])
    return faults


def _thin(V, F, min_segment):
    size = mesh_size(V)
    index, count = _weld(V, size)
    F = index[F]
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])]
    P = np.zeros((count, 3))
    P[index] = V
    used = np.unique(F)
    rays = used[np.linspace(0, len(used) - 1, min(len(used), THIN_RAYS)).round().astype(np.int64)] \
        if len(used) > THIN_RAYS else used
    limit = THIN_SEGMENTS * min_segment
    t = local_thickness(P, F, limit, rays)
    measured = ~np.isnan(t)
    thin_rays = measured & (t < limit)
    share = float(thin_rays.sum() / max(measured.sum(), 1))
    if share <= THIN_SHARE:
        return []
    where, depth = P[rays[thin_rays]], t[thin_rays]
    # the thin places: thin vertices in the same or neighbouring cells of the limit's size are one
    cell = np.floor((where - where.min(axis=0)) / limit).astype(np.int64)
    cells, of = np.unique(cell, axis=0, return_inverse=True)
    of = of.reshape(-1)
    span = cells.max(axis=0) + 2
    keys = (cells[:, 0] * span[1] + cells[:, 1]) * span[2] + cells[:, 2]  # sorted, as cells are
    pairs = []
    for dx, dy, dz in _OFFSETS:
        other = np.searchsorted(keys, keys + (dx * span[1] + dy) * span[2] + dz)
        found = (other < len(keys)) & (keys[np.minimum(other, len(keys) - 1)] == keys + (dx * span[1] + dy) * span[2] + dz)
        ok = found & ((cells[np.minimum(other, len(keys) - 1)] - cells)[:, [1, 2]] <= 1).all(axis=1) \
            & ((cells[np.minimum(other, len(keys) - 1)] - cells)[:, [1, 2]] >= -1).all(axis=1)
        pairs.append(np.column_stack([np.nonzero(ok)[0], other[ok]]))
    # and thin vertices joined by an edge of the mesh (a coarse mesh's edges are longer than a cell)
    thin_index = np.full(len(P), -1)
    thin_index[rays[thin_rays]] = np.arange(len(where))
    ends = thin_index[np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])]
    ends = ends[(ends >= 0).all(axis=1)]
    pairs.append(np.column_stack([of[ends[:, 0]], of[ends[:, 1]]]))
    label, places = _components(len(cells), np.concatenate(pairs))
    part = label[of]
    largest = int(np.argmax(np.bincount(part, minlength=places)))
    mine = part == largest
    at = (where[mine].min(axis=0) + where[mine].max(axis=0)) / 2
    return [{"cause": THIN, "share": share, "places": int(places), "thinnest": float(depth[mine].min()),
             "limit": float(limit), "at": [float(c) for c in at], "size": float(size)}]


def _mm(metres):
    return f"{metres * 1000:.0f} mm" if metres >= 0.0015 else f"{metres * 1000:.1f} mm"


def sentence(fault):
    """The words of one fault of check() or obstacle of obstacles(), with its figures and what to do."""
    if fault["cause"] == THIN_LOST:
        return obstacle_sentence(fault)
    if fault["cause"] == THIN:
        at = ", ".join(f"{1000 * c:.0f}" for c in fault["at"])
        places = fault.get("places", 1)
        where = (f"in {places} places, {100 * fault['share']:.0f} % of its vertices; the largest around ({at}) mm"
                 if places > 1 else f"{100 * fault['share']:.0f} % of its vertices, around ({at}) mm")
        return (f"parts of the model are thinner than a wire can go round: {where}, as thin as "
                f"{_mm(fault['thinnest'])}, under the {_mm(fault['limit'])} a closed wire of straight pieces of at "
                f"least the minimum segment needs: {scale_words(fault['size'], fault['limit'] / fault['thinnest'])}, "
                f"thicken them, or expect no wire there")
    if fault["cause"] == NONMANIFOLD:
        return (f"the mesh has {fault['edges']} non-manifold edge{'s' if fault['edges'] != 1 else ''} (shared by "
                f"more than two faces), where a plane's contour can branch: merge or separate the faces there")
    if fault["cause"] == SHELLS:
        remesh = (f", or fuse them by a voxel remesh (about {_mm(fault['voxel'])})" if fault.get("voxel")
                  else ", or move them together and join them (they lie too far apart for a voxel remesh)")
        return (f"the mesh has {fault['shells']} separate parts (the largest {100 * fault['largest_share']:.0f} % "
                f"of its surface); the wires of one part cannot hold another: join them{remesh}")
    holes = f"{fault['holes']} hole{'s' if fault['holes'] != 1 else ''}"
    return (f"the mesh is open: {fault['edges']} boundary edge{'s' if fault['edges'] != 1 else ''} in {holes}, "
            f"where a plane cuts open contours: fill the holes, or close it by a voxel remesh "
            f"(about {_mm(fault['voxel'])})")


def words(faults):
    """The faults' sentences as one: "" for none."""
    return "; ".join(sentence(f) for f in faults)


def closing_voxel(size, min_segment):
    """m: the voxel of the closing remesh of a model `size` m across whose wires bend no closer than
    `min_segment` m (module doc: the smaller of CLOSE_SHARE of the size and CLOSE_SEGMENTS of
    min_segment, never under size / CLOSE_CELLS)."""
    voxel = max(min(CLOSE_SHARE * size, CLOSE_SEGMENTS * min_segment), size / CLOSE_CELLS)
    return round(voxel, 6) or voxel  # to the micrometre: the panel's float32 l_min gives the batch's voxel


def drop_specks(vertices, faces):
    """(faces, dropped): `faces` without the parts (faces joined through shared vertices) of less
    than SMALL_SHARE of the surface area, and how many parts went. A voxel remesh leaves such specks
    where thin parts break up; no wire can use them."""
    V = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    F = np.asarray(faces).reshape(-1, 3)
    if not len(F):
        return F, 0
    labels, count = _components(len(V), np.concatenate([F[:, [0, 1]], F[:, [1, 2]]]))
    if count < 2:
        return F, 0
    corner = V[F]
    area = 0.5 * np.linalg.norm(np.cross(corner[:, 1] - corner[:, 0], corner[:, 2] - corner[:, 0]), axis=1)
    part = labels[F[:, 0]]
    by_part = np.bincount(part, weights=area, minlength=count)
    present = np.bincount(part, minlength=count) > 0
    speck = present & (by_part < SMALL_SHARE * max(float(by_part.sum()), 1e-300))
    return F[~speck[part]], int(speck.sum())


def needs_closing(faults):
    """Whether a mesh with check()'s `faults` is closed for slicing: it has holes, several parts or
    non-manifold edges."""
    return bool(faults)


def closing(before, after, voxel, triangles, lost=0.0, lost_at=None, specks=0):
    """The record (CLOSED) of a mesh closed for slicing: `before`, `after` check()'s faults of the
    mesh and of the closed one, `voxel` (m) the remesh's, `triangles` the closed mesh's, `lost` the
    share of the original vertices farther than a voxel from the closed surface, `lost_at` their
    box's centre, `specks` the parts left out (drop_specks)."""
    by = {f["cause"]: f for f in before}
    shells_after = next((f["shells"] for f in after if f["cause"] == SHELLS), 1)
    return {"cause": CLOSED, "boundary_edges": by.get(OPEN, {}).get("edges", 0),
            "holes": by.get(OPEN, {}).get("holes", 0), "nonmanifold_edges": by.get(NONMANIFOLD, {}).get("edges", 0),
            "shells": by.get(SHELLS, {}).get("shells", 1), "shells_after": int(shells_after),
            "voxel": float(voxel), "triangles": int(triangles), "lost": float(lost),
            "lost_at": None if lost_at is None else [float(x) for x in lost_at], "specks": int(specks)}


def _digest(V, F):
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    return hashlib.blake2b(V.tobytes() + F.tobytes(), digest_size=16).digest()


def remember(vertices, faces, record):
    """The closed mesh (vertices, faces) was made by the closing `record`: closing_of says so when
    the pipeline slices that mesh (the plane search passes the mesh on without the record)."""
    _closed.clear()
    _closed.update(V=vertices, F=faces, digest=_digest(vertices, faces), record=dict(record))


def closing_of(vertices, faces):
    """The closing record of the mesh (vertices, faces) when it is the last closed mesh (remember),
    else None."""
    if not _closed:
        return None
    if not (_closed["V"] is vertices and _closed["F"] is faces) and _closed["digest"] != _digest(vertices, faces):
        return None
    return dict(_closed["record"])


def _count(n, word):
    return f"{n} {word}{'s' if n != 1 else ''}"


def closing_sentence(record):
    """What closing did, in words: "closed 223 boundary edges (4 holes) by a 4 mm voxel remesh"."""
    done = []
    if record["boundary_edges"]:
        done.append(f"closed {_count(record['boundary_edges'], 'boundary edge')} "
                    f"({_count(record['holes'], 'hole')})")
    if record["shells"] > 1 and record["shells_after"] < record["shells"]:
        joined = (f"into {record['shells_after']}" if record["shells_after"] > 1 else "into one")
        done.append(f"joined {record['shells']} parts {joined}")
    if record["nonmanifold_edges"]:
        done.append(f"mended {_count(record['nonmanifold_edges'], 'non-manifold edge')}")
    what = ", ".join(done[:-1]) + (" and " if len(done) > 1 else "") + done[-1] if done else "remeshed the mesh"
    apart = (f"; its {record['shells_after']} parts stay apart (too far for the remesh to join)"
             if record["shells_after"] > 1 and record["shells_after"] >= record["shells"] else "")
    return (f"{what} by a {_mm(record['voxel'])} voxel remesh for slicing "
            f"({record['triangles']} triangles; the mesh object itself is unchanged){apart}")


def obstacles(record):
    """The obstacles a closed mesh holds beyond check()'s faults of it, as faults with their figures
    ([] for none): THIN_LOST when more than LOST_SHARE of the given mesh's vertices lie farther than
    a voxel from the closed surface (parts thinner than the voxel vanished). Parts the remesh could
    not join are check()'s SHELLS of the closed mesh."""
    if record.get("lost", 0.0) > LOST_SHARE:
        return [{"cause": THIN_LOST, "lost": record["lost"], "at": record.get("lost_at"), "voxel": record["voxel"]}]
    return []


def obstacle_sentence(fault):
    """The words of one obstacle of obstacles(), with what to try."""
    at = ("" if fault.get("at") is None else
          " around ({})".format(", ".join(f"{1000 * c:.0f}" for c in fault["at"])) + " mm")
    return (f"parts of the model thinner than the {_mm(fault['voxel'])} voxel ({100 * fault['lost']:.0f} % of its "
            f"vertices{at}, a thin limb or sheet) vanished when it was closed for slicing, so no wire follows them: "
            f"thicken them, scale the model up, or lower min_segment for a finer remesh")


def failures(vertices, faces):
    """What about the mesh (vertices, faces) can stop a stable design, as faults with their figures:
    the obstacles of its closing (obstacles of closing_of, when it is a closed mesh) and check()'s
    faults of it (parts the remesh could not join are its SHELLS)."""
    record = closing_of(vertices, faces)
    return (obstacles(record) if record else []) + check(vertices, faces)


def explain(design):
    """When `design` is not stable and its `mesh_faults` are not empty, or its mesh was closed for
    slicing (`mesh_closing`) and the closed mesh still holds an obstacle (obstacles), the mesh's
    words lead its reason (the solver's own reason follows) and their codes join `reason_causes`.
    Returns whether it changed the design."""
    faults = design.get("mesh_faults") or []
    record = design.get("mesh_closing")
    found = obstacles(record) if record else []
    if design.get("stable", True) or not (faults or found) or setup_problem(design):
        return False
    faults = found + faults
    said = words(faults)
    solver = design.get("reason") or ""
    design["reason"] = f"{said} (the solver: {solver})" if solver else said
    causes = design.setdefault("reason_causes", [])
    causes.extend(f["cause"] for f in faults if f["cause"] not in causes)
    return True
