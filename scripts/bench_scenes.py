"""The benchmark scenes of scripts/bench, generated from code (no downloaded models).

    /usr/bin/python3.11 scripts/bench_scenes.py [--out out/bench] [--no-check] [NAME...]

Writes OUT/meshes/*.obj (triangle meshes of implicit shapes, meshed by marching tetrahedra, or
analytic UV ellipsoids) and OUT/<case>.json (scene files, docs/formats.md) plus OUT/manifest.json, the
list of cases the bench runs:

- `paper`: five stand-ins for the models of the paper's Table 2 (Duck, Teddy, Airplane, Car,
  Chair), each a smooth union of ellipsoids and rounded boxes cut by planes chosen so that the
  design has exactly the paper's number of wires P and crossings C, scaled (scene "size") so that
  the longest wire is as long as the paper's l_max;
- `crossings`: a sphere cut by three families of parallel planes (a + b + c planes, every pair of
  wires from different families crossing twice: C = 2(ab + bc + ca)), C from 10 to 150, fixed size
  0.6 m;
- `search`: the 5 + 5 + 4 sphere with its planes spread wider, where the layering search explodes;
- `example`: the bundled globe (scripts/examples/globe, three great circles: P 3, C 6), as it is;
- `length`: the 1 + 1 + 2 sphere (P 4, C 10, Teddy's counts) scaled so that its longest wire is
  0.5 m to 3 m.

Unless --no-check is given, every scene is loaded like a batch run (core.scene), sliced and
layered by the pipeline's own stages, and the generator stops with an error if a design does not
have the promised (P, C). The output is deterministic.
"""
import argparse
import itertools
import json
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
ADDON = os.path.join(ROOT, "addon")
if ADDON not in sys.path:
    sys.path.insert(0, ADDON)

# The paper's Table 2 (3.80 GHz, single thread, GLPK + KNitro): wires, crossings, longest wire
# (cm), seconds for stability/layering, shape (target) optimisation, rest configuration.
PAPER = {
    "duck": {"P": 5, "C": 14, "l_max_cm": 80.1, "stab_s": 0.19, "shape_s": 2.21, "rest_s": 7.54},
    "teddy": {"P": 4, "C": 10, "l_max_cm": 125.4, "stab_s": 0.09, "shape_s": 7.99, "rest_s": 0.02},
    "airplane": {"P": 6, "C": 18, "l_max_cm": 209.5, "stab_s": 0.60, "shape_s": 50.91, "rest_s": 5.86},
    "car": {"P": 6, "C": 22, "l_max_cm": 117.5, "stab_s": 1.83, "shape_s": 10.04, "rest_s": 16.12},
    "chair": {"P": 8, "C": 38, "l_max_cm": 133.1, "stab_s": 22.22, "shape_s": 11.47, "rest_s": 95.76},
}


# ---------------------------------------------------------------------------------------------
# Implicit shapes: approximate signed distances (negative inside), model units.

def ellipsoid(center, radii):
    c, r = np.asarray(center, float), np.asarray(radii, float)
    return lambda p: (np.linalg.norm((p - c) / r, axis=1) - 1.0) * r.min()


def rounded_box(center, half, radius):
    c, h = np.asarray(center, float), np.asarray(half, float) - radius

    def f(p):
        q = np.abs(p - c) - h
        return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0) - radius
    return f


def smooth_union(k, *parts):
    """Polynomial smooth minimum with blend radius k (model units)."""
    def f(p):
        d = parts[0](p)
        for part in parts[1:]:
            e = part(p)
            h = np.clip(0.5 + 0.5 * (e - d) / k, 0.0, 1.0)
            d = e * (1 - h) + d * h - k * h * (1 - h)
        return d
    return f


def _tetra_table():
    """Per sign mask of a tetrahedron's 4 corners (bit m: corner m inside): its triangles, each
    as three corner pairs (the edges its vertices lie on)."""
    table = {}
    for mask in range(1, 15):
        inside = [m for m in range(4) if mask >> m & 1]
        outside = [m for m in range(4) if not mask >> m & 1]
        if len(inside) in (1, 3):
            lone, others = (inside[0], outside) if len(inside) == 1 else (outside[0], inside)
            table[mask] = [[(lone, o) for o in others]]
        else:
            (a, b), (c, d) = inside, outside
            table[mask] = [[(a, c), (a, d), (b, d)], [(a, c), (b, d), (b, c)]]
    return table


TETRA_TABLE = _tetra_table()


def marching_tetrahedra(f, lo, hi, cell):
    """(V, F) of the zero set of `f` in the box [lo, hi] on a grid of spacing `cell`: each cube is
    split into the six tetrahedra around its main diagonal (so neighbouring cubes share faces),
    vertices are shared along grid edges and triangles face outwards (towards f > 0)."""
    lo = np.asarray(lo, float) - 2 * cell
    hi = np.asarray(hi, float) + 2 * cell
    n = np.ceil((hi - lo) / cell).astype(int) + 1
    # shift the grid by an irrational fraction of a cell so no grid point lies on a slicing plane
    axes = [lo[i] + cell * (np.arange(n[i]) + 0.3819660113) for i in range(3)]
    G = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    values = f(G)
    values[values == 0.0] = 1e-12
    nx, ny, nz = n
    stride = np.array([ny * nz, nz, 1])
    base = (np.arange(nx - 1)[:, None, None] * stride[0] + np.arange(ny - 1)[None, :, None] * stride[1]
            + np.arange(nz - 1)[None, None, :]).ravel()
    corner = np.array([dx * stride[0] + dy * stride[1] + dz for dx in (0, 1) for dy in (0, 1) for dz in (0, 1)])
    cv = values[base[:, None] + corner[None, :]]
    base = base[(cv.min(axis=1) < 0) & (cv.max(axis=1) > 0)]  # cubes the surface passes through
    unit = {0: 4, 1: 2, 2: 1}  # bit of corner index per axis (dx dy dz)
    tets = []
    for a, b, _c in itertools.permutations(range(3)):
        tets.append([0, unit[a], unit[a] | unit[b], 7])
    T = (base[:, None, None] + corner[np.array(tets)][None, :, :]).reshape(-1, 4)
    inside = values[T] < 0
    masks = (inside * np.array([1, 2, 4, 8])).sum(axis=1)
    edge_a, edge_b = [], []
    for mask, triangles in TETRA_TABLE.items():
        sel = T[masks == mask]
        for tri in triangles:
            edge_a.append(np.stack([sel[:, i] for i, _j in tri], axis=1))
            edge_b.append(np.stack([sel[:, j] for _i, j in tri], axis=1))
    A = np.concatenate(edge_a)  # (K, 3) grid indices: each triangle vertex lies on edge A-B,
    B = np.concatenate(edge_b)  # A inside, B outside
    lo_idx, hi_idx = np.minimum(A, B), np.maximum(A, B)
    keys = lo_idx.astype(np.int64) * len(values) + hi_idx
    unique, first, F = np.unique(keys.ravel(), return_index=True, return_inverse=True)
    F = F.reshape(-1, 3)
    ea, eb = A.ravel()[first], B.ravel()[first]
    t = values[ea] / (values[ea] - values[eb])
    V = G[ea] + t[:, None] * (G[eb] - G[ea])
    normal = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    outward = G[B[:, 0]] - G[A[:, 0]]
    flip = (normal * outward).sum(axis=1) < 0
    F[flip] = F[flip][:, ::-1]
    area = np.linalg.norm(normal, axis=1)
    keep = (area > 1e-14 * cell * cell) & (F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 0] != F[:, 2])
    F = F[keep]
    used, F = np.unique(F.ravel(), return_inverse=True)
    return V[used], F.reshape(-1, 3)


def uv_ellipsoid(radii, segments=96, rings=48):
    """A UV ellipsoid about the origin (poles on z), outward-facing triangles."""
    rx, ry, rz = radii
    theta = np.pi * np.arange(1, rings) / rings
    phi = 2 * np.pi * np.arange(segments) / segments
    st, ct = np.sin(theta)[:, None], np.cos(theta)[:, None]
    ring = np.stack([rx * st * np.cos(phi), ry * st * np.sin(phi), rz * ct * np.ones_like(phi)], axis=-1)
    V = np.concatenate([[[0, 0, rz]], ring.reshape(-1, 3), [[0, 0, -rz]]])
    F = []
    s = np.arange(segments)
    s1 = (s + 1) % segments
    F.append(np.stack([np.zeros(segments, int), 1 + s, 1 + s1], axis=1))
    for r in range(rings - 2):
        a, b = 1 + r * segments, 1 + (r + 1) * segments
        F.append(np.stack([a + s, b + s, b + s1], axis=1))
        F.append(np.stack([a + s, b + s1, a + s1], axis=1))
    last, south = 1 + (rings - 2) * segments, len(V) - 1
    F.append(np.stack([last + s, np.full(segments, south), last + s1], axis=1))
    return V, np.concatenate(F)


def write_obj(path, V, F, comment):
    lines = [f"# {comment}", f"# {len(V)} vertices, {len(F)} triangles; generated by scripts/bench_scenes.py",
             "o " + os.path.splitext(os.path.basename(path))[0]]
    lines += ["v %.6f %.6f %.6f" % tuple(v) for v in V]
    lines += ["f %d %d %d" % tuple(t) for t in (F + 1)]
    from wiresculpt.core.files import write_atomic
    write_atomic(path, "\n".join(lines) + "\n")


def read_obj(path):
    """(V, F) of an OBJ file as written by write_obj (v and f lines; polygons fanned)."""
    V, F = [], []
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith("v "):
                V.append([float(x) for x in line.split()[1:4]])
            elif line.startswith("f "):
                idx = [int(t.split("/")[0]) for t in line.split()[1:]]
                idx = [i - 1 if i > 0 else len(V) + i for i in idx]
                F.extend([idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1))
    return np.asarray(V, dtype=np.float64), np.asarray(F, dtype=np.int64).reshape(-1, 3)


# ---------------------------------------------------------------------------------------------
# The scenes. Coordinates in model units (z up); plane families are parallel planes, so two
# wires of one family never cross and two of different families cross exactly twice.

def plane(name, origin, normal):
    return {"name": name, "origin": [float(x) for x in origin], "normal": [float(x) for x in normal],
            "contours": "largest"}


def duck():
    """Body, neck, head, beak and tail. 3 horizontal + 1 side + 1 transverse plane: 7 crossing
    pairs, P 5, C 14."""
    shape = smooth_union(
        0.06,
        ellipsoid((0.0, 0.0, 0.25), (0.45, 0.30, 0.22)),
        ellipsoid((0.30, 0.0, 0.45), (0.09, 0.08, 0.15)),  # neck
        ellipsoid((0.32, 0.0, 0.62), (0.17, 0.15, 0.15)),  # head
        ellipsoid((0.52, 0.0, 0.60), (0.13, 0.07, 0.035)),  # beak
        ellipsoid((-0.42, 0.0, 0.38), (0.12, 0.08, 0.06)),  # tail
    )
    planes = [plane("Low", (0, 0, 0.13), (0, 0, 1)), plane("Mid", (0, 0, 0.33), (0, 0, 1)),
              plane("Head", (0, 0, 0.63), (0, 0, 1)), plane("Side", (0, 0.011, 0), (0, 1, 0)),
              plane("Neck", (0.25, 0, 0), (1, 0, 0))]
    return shape, ((-0.62, -0.36, -0.02), (0.70, 0.36, 0.82)), 0.02, planes


def teddy():
    """Body, head, ears, arms, legs. 2 horizontal + front + side plane: 5 pairs, P 4, C 10."""
    shape = smooth_union(
        0.05,
        ellipsoid((0.0, 0.0, 0.35), (0.25, 0.20, 0.30)),
        ellipsoid((0.0, 0.0, 0.80), (0.20, 0.18, 0.19)),
        ellipsoid((0.15, 0.0, 0.97), (0.07, 0.04, 0.07)),
        ellipsoid((-0.15, 0.0, 0.97), (0.07, 0.04, 0.07)),
        ellipsoid((0.0, -0.17, 0.76), (0.08, 0.06, 0.06)),  # snout
        ellipsoid((0.30, 0.0, 0.47), (0.16, 0.08, 0.08)),
        ellipsoid((-0.30, 0.0, 0.47), (0.16, 0.08, 0.08)),
        ellipsoid((0.14, -0.06, 0.09), (0.10, 0.14, 0.09)),
        ellipsoid((-0.14, -0.06, 0.09), (0.10, 0.14, 0.09)),
    )
    planes = [plane("Arms", (0, 0, 0.47), (0, 0, 1)), plane("Head", (0, 0, 0.79), (0, 0, 1)),
              plane("Front", (0, 0.007, 0), (0, 1, 0)), plane("Side", (0.013, 0, 0), (1, 0, 0))]
    return shape, ((-0.50, -0.30, -0.03), (0.50, 0.26, 1.07)), 0.02, planes


def airplane():
    """Fuselage, wings, tailplane and fin. The top outline and the side profile are the two long
    wires; four transverse sections cross both (and not each other): 9 pairs, P 6, C 18."""
    shape = smooth_union(
        0.04,
        ellipsoid((0.0, 0.0, 0.0), (0.80, 0.09, 0.09)),  # fuselage along x
        rounded_box((0.02, 0.0, 0.0), (0.13, 0.62, 0.025), 0.02),  # wings
        rounded_box((-0.66, 0.0, 0.0), (0.08, 0.25, 0.018), 0.015),  # tailplane
        rounded_box((-0.66, 0.0, 0.13), (0.09, 0.018, 0.13), 0.015),  # fin
    )
    planes = [plane("Top", (0, 0, 0.003), (0, 0, 1)), plane("Side", (0, 0.004, 0), (0, 1, 0)),
              plane("Nose", (0.52, 0, 0), (1, 0, 0)), plane("Wing", (0.05, 0, 0), (1, 0, 0)),
              plane("Rear", (-0.35, 0, 0), (1, 0, 0)), plane("Tail", (-0.64, 0, 0), (1, 0, 0))]
    return shape, ((-0.85, -0.65, -0.12), (0.85, 0.65, 0.30)), 0.015, planes


def car():
    """Body and cabin. 3 transverse + 2 horizontal + the side profile: 11 pairs, P 6, C 22."""
    shape = smooth_union(
        0.08,
        rounded_box((0.0, 0.0, 0.22), (0.90, 0.38, 0.14), 0.10),  # body
        rounded_box((-0.08, 0.0, 0.45), (0.45, 0.33, 0.14), 0.10),  # cabin
        ellipsoid((0.55, 0.0, 0.20), (0.40, 0.36, 0.16)),  # rounded bonnet
    )
    planes = [plane("Low", (0, 0, 0.20), (0, 0, 1)), plane("Roof", (0, 0, 0.46), (0, 0, 1)),
              plane("Side", (0, 0.006, 0), (0, 1, 0)), plane("Front", (0.20, 0, 0), (1, 0, 0)),
              plane("Middle", (-0.08, 0, 0), (1, 0, 0)), plane("Back", (-0.35, 0, 0), (1, 0, 0))]
    return shape, ((-0.95, -0.42, 0.0), (0.95, 0.42, 0.66)), 0.022, planes


def chair():
    """An armchair: seat, backrest, two arms. 4 side profiles + 3 horizontal sections + one
    frontal section through the backrest: 12 + 4 + 3 = 19 pairs, P 8, C 38."""
    shape = smooth_union(
        0.05,
        rounded_box((0.0, 0.0, 0.22), (0.45, 0.45, 0.22), 0.06),  # seat block
        rounded_box((0.0, 0.36, 0.47), (0.45, 0.10, 0.47), 0.06),  # backrest
        rounded_box((0.39, 0.0, 0.34), (0.07, 0.45, 0.34), 0.05),  # arms
        rounded_box((-0.39, 0.0, 0.34), (0.07, 0.45, 0.34), 0.05),
    )
    planes = [plane("ArmL", (-0.39, 0, 0), (1, 0, 0)), plane("SeatL", (-0.14, 0, 0), (1, 0, 0)),
              plane("SeatR", (0.15, 0, 0), (1, 0, 0)), plane("ArmR", (0.40, 0, 0), (1, 0, 0)),
              plane("Seat", (0, 0, 0.21), (0, 0, 1)), plane("Arms", (0, 0, 0.55), (0, 0, 1)),
              plane("Back", (0, 0, 0.80), (0, 0, 1)), plane("Rest", (0, 0.35, 0), (0, 1, 0))]
    return shape, ((-0.47, -0.47, -0.01), (0.47, 0.47, 0.95)), 0.022, planes


PAPER_SCENES = {"duck": duck, "teddy": teddy, "airplane": airplane, "car": car, "chair": chair}


def family_planes(a, b, c, spread=0.4):
    """a planes x = const, b planes y = const, c planes z = const through the unit sphere, each
    family spread over [-spread, spread] with small distinct offsets (no three planes meet on the
    sphere and no plane passes through another pair's crossing)."""
    planes = []
    for axis, count, offset in ((0, a, 0.021), (1, b, -0.033), (2, c, 0.047)):
        positions = np.linspace(-spread, spread, count) if count > 1 else np.zeros(1)
        for k, s in enumerate(positions):
            origin = [0.0, 0.0, 0.0]
            origin[axis] = float(s + offset)
            normal = [0.0, 0.0, 0.0]
            normal[axis] = 1.0
            planes.append(plane(f"{'XYZ'[axis]}{k}", origin, normal))
    return planes


# (a, b, c) families of the crossing sweep; C = 2(ab + bc + ca).
CROSSING_FAMILIES = [(1, 1, 2), (2, 2, 2), (3, 3, 2), (3, 3, 3), (4, 4, 3), (4, 4, 4), (5, 4, 4), (5, 5, 4),
                     (5, 5, 5)]
CROSSING_SIZE = 0.6  # metres: the sphere's diameter (its largest section is about 1.8 m long)
# The length sweep: Teddy's counts (P 4, C 10), which stay realisable down to 0.5 m wires (with
# 2 + 2 + 2 planes, crossings on a 0.5 m wire are closer than the machine's 2 l_min).
LENGTH_FAMILY = (1, 1, 2)
LENGTHS = [0.5, 1.0, 1.5, 2.0, 2.5, 3.0]  # metres: the longest wire of the length sweep
# A layering stress case: 5 + 5 + 4 planes spread wider over a smaller sphere. Same counts as
# sphere-554, but its branch and bound visits ~20x the nodes (docs/performance.md).
SEARCH_STRESS = {"name": "search-554", "families": (5, 5, 4), "spread": 0.5, "size": 0.45}


def expected_crossings(a, b, c):
    return 2 * (a * b + b * c + c * a)


# ---------------------------------------------------------------------------------------------

def load_and_slice(scene_path):
    """(scene, V, F, design) as a batch run sees them: the scene file validated, the mesh scaled to
    "size" about the origin, the planes with it, and the design after slicing and picking."""
    from wiresculpt import pipeline
    from wiresculpt.core.scene import PlaneSpec, load_scene

    scene = load_scene(scene_path)
    V, F = read_obj(scene.mesh)
    factor = 1.0
    if scene.size is not None:
        factor = scene.size / float(np.max(V.max(axis=0) - V.min(axis=0)))
    V = V * factor
    planes = [PlaneSpec(p.name, tuple(factor * x for x in p.origin), p.normal, p.contours) for p in scene.planes]
    design = pipeline.slice_and_pick(V, F, planes, scene.material, scene.settings)
    return scene, V, F, planes, design


def wire_length(points, closed):
    p = np.asarray(points, dtype=np.float64)
    if closed:
        p = np.vstack([p, p[:1]])
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())


def longest_wire(design, key="contour"):
    return max(wire_length(w[key], w["closed"]) for w in design["wires"])


def write_scene(out, name, mesh_file, size, planes):
    from wiresculpt.core.files import write_atomic
    data = {"mesh": f"meshes/{mesh_file}", "size": round(size, 4), "material": "steel", "planes": planes}
    text = json.dumps(data, indent=1)
    path = os.path.join(out, f"{name}.json")
    write_atomic(path, text + "\n")
    return path


def sized(out, name, mesh_file, V, planes, target_length):
    """Writes the scene at size 1 (largest side 1 m), measures its longest sliced wire and writes it
    again scaled so that wire is `target_length` metres."""
    extent = float(np.max(V.max(axis=0) - V.min(axis=0)))
    path = write_scene(out, name, mesh_file, extent, planes)  # mesh units = metres
    _scene, _V, _F, _planes, design = load_and_slice(path)
    if not design["wires"]:
        raise SystemExit(f"bench scene {name}: no plane cuts the mesh")
    size = extent * target_length / longest_wire(design)
    return write_scene(out, name, mesh_file, size, planes)


def check(case):
    """Slices the case's scene and builds its crossing network with the layering stage's native
    call (the search itself cut off after one node: the network does not depend on it); returns
    (P, C, longest wire in m) or exits naming the case whose counts differ from the promised ones."""
    from wiresculpt import native
    from wiresculpt.stages import layering

    scene, _V, _F, _planes, design = load_and_slice(case["scene"])
    settings = dict(layering.settings_for(scene.material, scene.settings), max_nodes=1)
    result = native.layering(layering.wire_specs(design), settings, None)
    P, C = len(design["wires"]), len(result["network"]["crossings"])
    if (P, C) != (case["P"], case["C"]):
        raise SystemExit(f"bench scene {case['name']}: the design has P={P} wires and C={C} crossings, "
                         f"expected P={case['P']}, C={case['C']}")
    return P, C, longest_wire(design)


def generate(out, names=None, run_check=True, say=print):
    """Writes the meshes, scenes and manifest.json into `out`; returns the manifest's cases."""
    os.makedirs(os.path.join(out, "meshes"), exist_ok=True)
    cases = []

    def wanted(name):
        return not names or any(n in name for n in names)

    sphere = None

    def unit_sphere():
        """The UV sphere the sweeps share, made and written to meshes/sphere.obj once."""
        nonlocal sphere
        if sphere is None:
            sphere = uv_ellipsoid((1.0, 1.0, 1.0))
            write_obj(os.path.join(out, "meshes", "sphere.obj"), *sphere, "UV sphere, radius 1")
        return sphere

    for name, build in PAPER_SCENES.items():
        if not wanted(name):
            continue
        shape, (lo, hi), cell, planes = build()
        V, F = marching_tetrahedra(shape, lo, hi, cell)
        write_obj(os.path.join(out, "meshes", f"{name}.obj"), V, F, f"{name} stand-in (smooth union of primitives)")
        row = PAPER[name]
        path = sized(out, name, f"{name}.obj", V, planes, row["l_max_cm"] / 100)
        cases.append({"name": name, "kind": "paper", "scene": path, "P": row["P"], "C": row["C"],
                      "triangles": int(len(F)), "paper": row})
    if wanted("globe"):
        path = os.path.join(ROOT, "scripts", "examples", "globe", "scene.json")
        V, F = read_obj(os.path.join(os.path.dirname(path), "globe.obj"))
        cases.append({"name": "globe", "kind": "example", "scene": path, "P": 3, "C": 6, "triangles": int(len(F))})
    for a, b, c in CROSSING_FAMILIES:
        name = f"sphere-{a}{b}{c}"
        if not wanted(name):
            continue
        mesh = unit_sphere()
        path = write_scene(out, name, "sphere.obj", CROSSING_SIZE, family_planes(a, b, c))
        cases.append({"name": name, "kind": "crossings", "scene": path, "P": a + b + c,
                      "C": expected_crossings(a, b, c), "triangles": int(len(mesh[1]))})
    if wanted(SEARCH_STRESS["name"]):
        mesh = unit_sphere()
        fams = SEARCH_STRESS["families"]
        path = write_scene(out, SEARCH_STRESS["name"], "sphere.obj", SEARCH_STRESS["size"],
                           family_planes(*fams, spread=SEARCH_STRESS["spread"]))
        cases.append({"name": SEARCH_STRESS["name"], "kind": "search", "scene": path, "P": sum(fams),
                      "C": expected_crossings(*fams), "triangles": int(len(mesh[1]))})
    for length in LENGTHS:
        name = f"length-{length:.1f}m"
        if not wanted(name):
            continue
        mesh = unit_sphere()
        path = sized(out, name, "sphere.obj", mesh[0], family_planes(*LENGTH_FAMILY), length)
        cases.append({"name": name, "kind": "length", "scene": path, "P": sum(LENGTH_FAMILY),
                      "C": expected_crossings(*LENGTH_FAMILY), "triangles": int(len(mesh[1])),
                      "target_length": length})
    for case in cases:
        case["scene"] = os.path.relpath(case["scene"], out)
        if run_check:
            P, C, lmax = check(dict(case, scene=os.path.join(out, case["scene"])))
            case["longest_wire"] = lmax
            say(f"bench scene {case['name']}: P={P}, C={C}, longest wire {lmax:.3f} m, "
                f"{case['triangles']} triangles")
    from wiresculpt.core.files import write_atomic
    write_atomic(os.path.join(out, "manifest.json"), json.dumps({"cases": cases}, indent=1) + "\n")
    return cases


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=os.path.join(ROOT, "out", "bench"))
    parser.add_argument("--no-check", action="store_true", help="do not slice and layer to check (P, C)")
    parser.add_argument("names", nargs="*", help="only the cases whose names contain one of these")
    args = parser.parse_args(argv)
    generate(args.out, args.names, not args.no_check)


if __name__ == "__main__":
    main()
