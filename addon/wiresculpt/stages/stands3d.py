"""The sculpture as it would stand (beyond the paper, docs/method-structure3d.md): every wire's rest
shape as a discrete elastic rod, tied to the others at its hooked crossings (a sticking point
contact: force, no moment), a closed wire's two ends tied at its cut, under the sculpture's weight,
on a table: the rigid sculpture first rolls onto the table until it rests there (settle), then the
rods bend, solved in 3D from the target shapes so turned (native.structure3d). It tells whether
the assembled structure stands as the planar model says: the equilibrium is found, every
crossing's force lies in its pyramid (the forces stage's `pyramid`, friction and hook, from the
target's kinks; a force in it presses), and no wire's shape changes by more than the sag limit
(its largest distance from its target once the whole structure is laid back onto the targets,
rigidly: how it sits on the table is `tilt_deg`, not a sag).

Fills `stands_3d` (*extra*, docs/formats.md): `stands`, `cause` (one of CAUSES), `sag_limit` (m),
`max_sag` (m) and `max_sag_wire`, `slipping` (crossing ids whose force leaves its pyramid),
`tilt_deg` (how far it rolls on the table), `solver_cause` and `solver_message`; `stages.stands_3d`
(`seconds`, `iterations`, `residual`); per wire `sag` (m: its largest distance from its target) and
`as_built` (3D, one point per rest point, from the cut); per hooked crossing `force_3d` (N, on
wires[0] by wires[1], in the deformed structure) and `admissible`. The words: core/standing.py.
"""
import math
import time

import numpy as np

from .. import native
from ..core.frames import plane_frame, to_3d
from ..core.sizes import model_size
from ..core.standing import NO_EQUILIBRIUM, PYRAMID_TOLERANCE, SAGS, SLIPS, STANDS, sag_limit, words

def _rotation(axis, angle):
    """The 3x3 rotation by `angle` (radians) about the unit `axis` (Rodrigues)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def _outward(contacts, c):
    """A horizontal unit direction from the contact points' support towards the centre of mass's
    foot `c` (xy) when it lies outside their convex hull (with a point on the hull edge it leaves
    by), else None: the support holds it."""
    pts = contacts[:, :2]
    if len(pts) == 1:
        h = c - pts[0]
        return (h / np.linalg.norm(h), pts[0]) if np.linalg.norm(h) > 0 else None
    best = None
    for i in range(len(pts)):  # every pair as a candidate hull edge: the support polygon's sides
        for j in range(i + 1, len(pts)):
            e = pts[j] - pts[i]
            if np.linalg.norm(e) == 0:
                continue
            n = np.array([e[1], -e[0]]) / np.linalg.norm(e)
            side = (pts - pts[i]) @ n
            above, below = np.any(side > 1e-12), np.any(side < -1e-12)
            if above and below:
                continue  # an inner pair, not a side of the hull
            # the outward normal of a side; both, where every point lies on one line
            for out in ((n, -n) if not (above or below) else (-n,) if above else (n,)):
                reach = float((c - pts[i]) @ out)
                if reach > 1e-12 and (best is None or reach > best[0]):
                    best = (reach, out, pts[i])
    return None if best is None else (best[1], best[2])


def settle(points, weights, tolerance, steps=200):
    """The rigid rotation R (3x3) that lets the rigid points (N, 3) with `weights` roll on the
    table z = min z under gravity -z until the foot of their centre of mass lies within the convex
    hull of the points touching it (within `tolerance` m): at each step the body turns about its
    support's edge (or point) that the centre of mass leaves by, until the next point touches."""
    P = np.asarray(points, dtype=np.float64)
    total = np.eye(3)
    w = np.asarray(weights, dtype=np.float64) / float(np.sum(weights))
    for _ in range(steps):
        z0 = float(P[:, 2].min())
        touching = P[:, 2] <= z0 + tolerance
        c = w @ P
        out = _outward(P[touching], c[:2])
        if out is None:
            break
        h, pivot2 = out
        pivot = np.array([pivot2[0], pivot2[1], z0])
        axis = np.cross([0.0, 0.0, 1.0], [h[0], h[1], 0.0])
        axis /= np.linalg.norm(axis)
        r = P - pivot
        a_height = r[:, 2]
        b_height = np.cross(axis, r - np.outer(r @ axis, axis))[:, 2]
        ahead = (~touching) & (b_height < 0)
        if not ahead.any():
            break
        angle = float(np.min(np.arctan2(a_height[ahead], -b_height[ahead])))
        R = _rotation(axis, angle)
        P = pivot + r @ R.T
        total = R @ total
    return total


def _fit(P, Q):
    """(R, t): the rigid map x -> R x + t taking the points P closest to Q in least squares
    (Kabsch, rotations only)."""
    cp, cq = P.mean(axis=0), Q.mean(axis=0)
    U, _s, Vt = np.linalg.svd((P - cp).T @ (Q - cq))
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T))])
    R = Vt.T @ D @ U.T
    return R, cq - R @ cp


def walk(n, closed, cut):
    """Target index of each rest point (rest_shape.hpp's wire_walk): from the cut round to it
    again for a closed wire, 0..n-1 for an open one."""
    if not closed:
        return list(range(n))
    return [(cut + k) % n for k in range(n + 1)]


def structure(design, material):
    """(wires, ties, walks) for native.structure3d: each wire's rest shape laid in its plane from
    the cut, starting at its target; a tie per hooked crossing and one joining a closed wire's
    ends."""
    wires, walks, ties = [], [], []
    for k, w in enumerate(design["wires"]):
        n, u, v = plane_frame(w["plane"]["normal"])
        target = np.asarray(w["target"], dtype=np.float64)
        order = walk(len(target), w["closed"], int(w.get("cut", -1)))
        start = target[order]
        rest = to_3d(w["rest"], w["plane"]["origin"], u, v)
        wires.append({"name": w["name"], "rest": rest, "start": start, "normal": n})
        walks.append({t: p for p, t in enumerate(order)})
        if w["closed"]:
            ties.append({"a": [k, 0], "b": [k, len(order) - 1]})
    tied = []
    for c in design["crossings"]:
        if int(c["hook"]) == 0:
            continue  # a null crossing carries no force (its wires merely touch)
        (wa, wb), (va, vb) = c["wires"], c["vertices"]
        a, b = [wa, walks[wa][va]], [wb, walks[wb][vb]]
        offset = wires[wa]["start"][a[1]] - wires[wb]["start"][b[1]]
        ties.append({"a": a, "b": b, "offset": offset})
        tied.append(c["id"])
    return wires, ties, tied


# Newton's iterations: from the rolled pose the corpus's designs that reach an equilibrium take 5-9
# (106 at most, a cactus at 0.75 m); a design past this finds none (each iteration 5-20 ms).
MAX_ITERATIONS = 120


def options(material, gravity=(0.0, 0.0, -9.81), weight_factor=1.0):
    """The solver's options from the material (SI): E I, d, G, the linear density (0 without a
    density: pre-stress alone) times `weight_factor`."""
    d = material["wire_diameter"]
    density = material.get("density") or 0.0
    return {"bending_stiffness": material["bending_stiffness"], "wire_diameter": d,
            "shear_modulus": material.get("shear_modulus") or 79.3e9,
            "linear_density": density * math.pi * d * d / 4.0 * weight_factor, "gravity": list(gravity),
            "max_iterations": MAX_ITERATIONS}


def resting(design):
    """How the sculpture rests on its table, from its targets alone: (turn, supports), the rigid
    rotation that settles it (settle) and the (wire, target vertex) pairs touching the table."""
    targets = [np.asarray(w["target"], dtype=np.float64) for w in design["wires"]]
    points = np.vstack(targets)
    turn = settle(points, np.concatenate([_lumped(t) for t in targets]), 1e-9 * model_size(design))
    z = [t @ turn.T for t in targets]
    z0 = min(float(np.min(p[:, 2])) for p in z)
    tolerance = 1e-6 * model_size(design)
    supports = [[k, int(v)] for k, p in enumerate(z) for v in np.flatnonzero(p[:, 2] <= z0 + tolerance)]
    return turn, supports


def run(design, material, native_progress=None):
    """Solves the standing structure of a design whose rest shapes exist and writes `stands_3d`
    and the per-wire and per-crossing figures. Returns the progress line."""
    began = time.perf_counter()
    wires, ties, tied = structure(design, material)
    targets = np.vstack([w["start"] for w in wires])
    lengths = np.concatenate([_lumped(w["start"]) for w in wires])
    size = model_size(design)
    # the sculpture first rolls, rigid, onto the table until it rests there (Newton then only bends it)
    turn = settle(targets, lengths, 1e-9 * size)
    for w in wires:  # rest shape, start and material frame turn together (the rest is intrinsic)
        w["start"], w["rest"], w["normal"] = w["start"] @ turn.T, w["rest"] @ turn.T, turn @ w["normal"]
    z0 = min(float(np.min(w["start"][:, 2])) for w in wires)
    result = native.structure3d(wires, ties=ties, table={"z0": z0}, options=options(material),
                                progress=native_progress)
    limit = sag_limit(design)
    record = {"sag_limit": limit, "tilt_deg": math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(turn) - 1.0) / 2.0)))),
              "slipping": [], "max_sag": 0.0, "max_sag_wire": None}
    if result["converged"]:
        built = np.vstack([r["points"] for r in result["wires"]])
        R, t = _fit(built, targets)  # the shape's change, not how the sculpture sits on the table
        at = 0
        for w, r in zip(design["wires"], result["wires"]):
            n = len(r["points"])
            w["as_built"] = (built[at:at + n] @ R.T + t).tolist()
            w["sag"] = float(np.max(np.linalg.norm(built[at:at + n] @ R.T + t - targets[at:at + n], axis=1)))
            at += n
            if w["sag"] >= record["max_sag"]:
                record["max_sag"], record["max_sag_wire"] = w["sag"], w["name"]
        by_id = {c["id"]: c for c in design["crossings"]}
        for cid, force in zip(tied, result["tie_forces"][len(ties) - len(tied):]):
            c = by_id[cid]
            force = np.asarray(force, dtype=np.float64) @ turn  # in the design's frame, as `force`
            fit = native.pyramid_fit(force, c["pyramid"])  # the forces stage's, from the target's kinks
            c["force_3d"] = [float(x) for x in force]
            c["admissible"] = bool(fit["distance"] <= PYRAMID_TOLERANCE * max(float(np.linalg.norm(force)), 1e-12))
            if not c["admissible"]:
                record["slipping"].append(cid)
    record["cause"] = (NO_EQUILIBRIUM if not result["converged"] else SLIPS if record["slipping"]
                       else SAGS if record["max_sag"] > limit else STANDS)
    record["solver_cause"], record["solver_message"] = result["cause"], result["message"]
    record["stands"] = record["cause"] == STANDS
    design["stands_3d"] = record
    design["stages"]["stands_3d"] = {"seconds": time.perf_counter() - began, "iterations": result["iterations"],
                                     "residual": result["residual"]}
    return words(record)


def _lumped(points):
    """Each node's share of its wire's length (half of each edge beside it): its weight's share."""
    edges = np.linalg.norm(np.diff(points, axis=0), axis=1)
    out = np.zeros(len(points))
    out[:-1] += edges / 2.0
    out[1:] += edges / 2.0
    return out
