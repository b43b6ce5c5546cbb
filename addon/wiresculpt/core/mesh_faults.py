"""What is wrong with a mesh as the model of one wire sculpture, and what to do (bpy-free).

A sculpture's wires hang together only through their crossings, so a mesh of several separate
parts (shells) gives wires of one part that cannot hold another, and a mesh with holes (boundary
edges) gives open contours where the planes cross them. These are faults of the mesh, not of
the planes: when a design is not stable, its verdict says them first (explain), with what to do
(join the parts, or close the mesh by a voxel remesh of about the size given).

    check(vertices, faces)  -> [fault, ...]  causes as codes with their figures (below)
    sentence(fault)         -> the words of one fault, made only here
    explain(design)         a design that is not stable and whose mesh has faults: the mesh's
                            words lead its reason, the codes join reason_causes

Faults (each a dict with "cause" and its figures):
- SHELLS: "shells" separate parts (faces joined through shared edges or vertices, after welding
  vertices that coincide), "largest_share" the largest part's share of the surface area,
  "voxel" (m) the voxel size of a remesh that would join them (VOXEL_LADDER: the smallest rung
  at which every part lies within one voxel of another part, through the others), None when no
  rung does.
- OPEN: "edges" boundary edges (used by one face), "holes" their loops, "voxel" (m) a remesh
  size that closes them (VOXEL_SHARE of the model's size).
"""
import hashlib

import numpy as np

from .design import setup_problem
from .sizes import mesh_size

SHELLS = "mesh_shells"  # the mesh is several separate parts
OPEN = "mesh_open"      # the mesh has boundary edges (holes)
CODES = (SHELLS, OPEN)

WELD = 1e-9              # of the model's size: vertices closer than this are one
VOXEL_SHARE = 0.015      # of the model's size: a remesh that closes small holes and keeps the shape
VOXEL_LADDER = (0.005, 0.01, 0.015, 0.02, 0.03, 0.05)  # of the model's size: remesh sizes tried
SMALL_SHARE = 0.001      # of the surface area: a shell smaller than this is a speck, still counted

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
    _memo.update(V=vertices, F=faces, digest=digest, faults=[dict(f) for f in faults])
    return faults


def _mm(metres):
    return f"{metres * 1000:.0f} mm" if metres >= 0.0015 else f"{metres * 1000:.1f} mm"


def sentence(fault):
    """The words of one fault of check(), with its figures and what to do."""
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


def explain(design):
    """When `design` is not stable and its `mesh_faults` are not empty, the mesh's words lead its
    reason (the solver's own reason follows) and their codes join `reason_causes`. Returns
    whether it changed the design."""
    faults = design.get("mesh_faults") or []
    if design.get("stable", True) or not faults or setup_problem(design):
        return False
    said = words(faults)
    solver = design.get("reason") or ""
    design["reason"] = f"{said} (the solver: {solver})" if solver else said
    causes = design.setdefault("reason_causes", [])
    causes.extend(f["cause"] for f in faults if f["cause"] not in causes)
    return True
