"""An independent re-check of a design.json: what `"stable": true` promises, recomputed with numpy
and scipy only, apart from the solver's code path (no wiresculpt module, no native module).

    recheck(design) -> list of problems (empty: the design keeps its promises)
    python3.11 blender_tests/pure/recheck.py DESIGN.json...     prints the problems, exit 1 if any

What is checked (docs/formats.md "Design file"; Miguel, Lepoutre, Bickel 2016, Sec. 4.1-4.2):

(a) geometry
    - every `target` point lies on its wire's plane;
    - at every crossing the two wires' target vertices coincide with each other and `point`;
    - the rest shape (`rest`, 2D, from the cut) has the target's edge lengths walked from the cut,
      one point more than `target` for a closed wire;
    - the machine: a *bend* is a rest vertex turning by at least `min_bend_deg`; every bend turns
      by at most `max_bend_deg`, and the wire between two consecutive bends (the bender's feed)
      is at least `min_segment` long. (Spring-back compensation lives in the bend program, not
      in design.json, and is not re-checked.)

(b) stability, Eq. 1 with the load basis of Sec. 4.2, each wire a rigid body
    Contact pyramids are built from the target geometry at each crossing with a non-null hook,
    with Sec. 4.1's definitions: the kink's bisector h = normalize(u_prev + u_next) (u: unit
    vectors from the crossing vertex to its two neighbours; it points into the kink's opening),
    each arm's in-plane normal pointing away from the opening, widened by friction: the normal
    turned by atan(mu) towards its own arm. A wire's pyramid at crossing c is its own two
    (widened) normals and the negatives of the other wire's two (Newton's third law), the
    paper's B_c = {-b_{r-1}^(i), -b_r^(i), b_{s-1}^(j), b_s^(j)}. The hook decides which side
    the kink opens to (docs/formats.md: hook = 1 means wires[0]'s bisector has h.d > 0 with
    d = normalize(n0 x n1), wires[1]'s h.d < 0): the geometry's bisector must agree (a problem
    otherwise); a straight kink (turn below `min_bend_deg`) takes h = +-d from the hook.
    Stable: for every column of L (a unit force or unit couple on one wire, its negative on the
    last wire; 6(P-1) columns) and for minus their sum, M a = -l has a solution a >= 0
    (scipy.optimize.linprog, HiGHS, objective sum a as in Eq. 1). Torques are taken about the
    crossings' centroid with lengths in units of their RMS distance to it (a choice of units for
    the couples that changes no verdict of a single load). Every prefix of `assembly_order` of
    length >= 3 is checked the same way (the wires so far and the crossings among them); when the
    design gives `assembly_steps`, only the prefixes that end a step (a two-hand step adds two
    wires at once: the state between them never exists).

(c) forces (`force`, on wires[0] by wires[1], present only after the forces stage)
    - zero at null crossings;
    - at hooked crossings inside the friction pyramid above (non-negative least squares);
    - each wire in equilibrium under its contact forces alone: the design's forces are the
      pre-stress of the assembled, unloaded sculpture (docs/method-forces.md: M a = 0), so they
      carry no weight; the weight is covered by (b), any self-equilibrated load, and by
      `load_capacity`, which is not re-checked here.
"""
import json
import math
import sys

import numpy as np
from scipy.optimize import linprog, nnls

PLANE_TOL = 1e-6      # m: a target point off its plane
POINT_TOL = 1e-6      # m: crossing vertices that do not coincide
LENGTH_TOL = 1e-6     # m (plus 1e-6 relative): rest edge lengths against target
ANGLE_TOL = 1e-6      # degrees beyond max_bend_deg
FORCE_TOL = 1e-6      # relative: pyramid membership and equilibrium of the forces


def _unit(v):
    v = np.asarray(v, dtype=float)
    n = np.linalg.norm(v)
    return v / n if n > 0 else v


def _turn_deg(a, b):
    """Turning angle in degrees between consecutive edge vectors a and b."""
    c = float(np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b)))
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


# ---------------------------------------------------------------------------------- (a) geometry

def check_geometry(design):
    problems = []
    machine = design.get("machine", {})
    min_segment = machine.get("min_segment", 0.015)
    max_bend = machine.get("max_bend_deg", 120.0)
    min_bend = machine.get("min_bend_deg", 1.0)
    wires = design["wires"]
    for w in wires:
        name = f"wire {w['id']} ({w.get('name', '?')})"
        target = np.asarray(w.get("target") or [], dtype=float)
        if len(target) < 2:
            problems.append(f"{name}: no target shape")
            continue
        n = _unit(w["plane"]["normal"])
        o = np.asarray(w["plane"]["origin"], dtype=float)
        off = np.abs((target - o) @ n)
        k = int(np.argmax(off))
        if off[k] > PLANE_TOL:
            problems.append(f"{name}: target point {k} is {off[k] * 1e3:.3g} mm off its plane")
        problems += _check_rest(w, name, target, min_segment, max_bend, min_bend)
    for c in design.get("crossings", []):
        i, j = c["wires"]
        vi, vj = c["vertices"]
        xi = np.asarray(wires[i]["target"][vi], dtype=float)
        xj = np.asarray(wires[j]["target"][vj], dtype=float)
        gap = max(np.linalg.norm(xi - xj), np.linalg.norm(xi - np.asarray(c["point"], dtype=float)))
        if gap > POINT_TOL:
            problems.append(f"crossing {c['id']}: target vertices of wires {i} and {j} are "
                            f"{gap * 1e3:.3g} mm apart (or from its point)")
    return problems


def _check_rest(w, name, target, min_segment, max_bend, min_bend):
    problems = []
    rest = w.get("rest")
    if rest is None:
        return [f"{name}: no rest shape"]
    rest = np.asarray(rest, dtype=float)
    closed = w.get("closed", True)
    n = len(target)
    if closed:
        cut = w.get("cut", 0)
        order = [(cut + k) % n for k in range(n + 1)]
    else:
        order = list(range(n))
    if len(rest) != len(order):
        return [f"{name}: rest has {len(rest)} points, expected {len(order)} from a target of {n}"]
    lt = np.linalg.norm(np.diff(target[order], axis=0), axis=1)
    lr = np.linalg.norm(np.diff(rest, axis=0), axis=1)
    bad = np.abs(lt - lr) > LENGTH_TOL + 1e-6 * lt
    if bad.any():
        k = int(np.argmax(np.abs(lt - lr)))
        problems.append(f"{name}: rest edge {k} from the cut is {lr[k] * 1e3:.4g} mm, "
                        f"target {lt[k] * 1e3:.4g} mm (inextensible wire)")
    # bends of the rest shape: interior vertices, the two ends of the cut wire are free ends
    edges = np.diff(rest, axis=0)
    s = np.concatenate([[0.0], np.cumsum(lr)])
    bends = []
    for k in range(1, len(rest) - 1):
        turn = _turn_deg(edges[k - 1], edges[k])
        if turn >= min_bend:
            bends.append(k)
            if turn > max_bend + ANGLE_TOL:
                problems.append(f"{name}: bend at rest vertex {k} from the cut (target vertex "
                                f"{order[k]}) turns {turn:.2f} deg > max_bend_deg {max_bend:g}")
    for a, b in zip(bends, bends[1:]):
        if s[b] - s[a] < min_segment - 1e-9:
            problems.append(f"{name}: {(s[b] - s[a]) * 1e3:.2f} mm between the bends at rest vertices "
                            f"{a} and {b} (target {order[a]}, {order[b]}) < min_segment "
                            f"{min_segment * 1e3:g} mm")
    return problems


# ------------------------------------------------------------------------- (b) contact pyramids

def _arms(target, r, closed):
    n = len(target)
    x = target[r]
    nb = []
    for k in (r - 1, r + 1):
        if closed:
            k %= n
        elif k < 0 or k >= n:
            continue
        nb.append(_unit(target[k] - x))
    return x, nb


def pyramid(design, crossing):
    """(4 x 3 array of unit forces on wires[0], list of problems): the crossing's friction
    pyramid from the target geometry, or (None, problems) when it cannot be built."""
    wires = design["wires"]
    mu = float(design["material"]["friction"])
    min_bend = design.get("machine", {}).get("min_bend_deg", 1.0)
    i, j = crossing["wires"]
    s = crossing["hook"]
    ni, nj = _unit(wires[i]["plane"]["normal"]), _unit(wires[j]["plane"]["normal"])
    d = _unit(np.cross(ni, nj))
    problems = []
    vectors = []
    for side, (w, r, n, sign) in enumerate(((i, crossing["vertices"][0], ni, s),
                                            (j, crossing["vertices"][1], nj, -s))):
        target = np.asarray(wires[w]["target"], dtype=float)
        x, arms = _arms(target, r, wires[w].get("closed", True))
        if len(arms) != 2:
            problems.append(f"crossing {crossing['id']}: wire {w} has no kink at its end vertex {r}")
            return None, problems
        hsum = arms[0] + arms[1]
        turn = 180.0 - math.degrees(math.acos(max(-1.0, min(1.0, float(arms[0] @ arms[1])))))
        if turn < min_bend or np.linalg.norm(hsum) < 1e-12:
            h = sign * d
        else:
            h = _unit(hsum)
            if sign * float(h @ d) <= 0:
                problems.append(f"crossing {crossing['id']} (hook {s:+d}): wire {w}'s kink opens towards "
                                f"{'+' if h @ d > 0 else '-'}d, the hook says {'+' if sign > 0 else '-'}d")
        for a in arms:
            m = _unit(np.cross(n, a))
            if m @ h > 0 or (abs(m @ h) < 1e-12 and m @ (arms[1] if a is arms[0] else arms[0]) > 0):
                m = -m
            q = _unit(m + mu * a)          # the normal turned by atan(mu) towards its arm
            vectors.append(q if side == 0 else -q)
    return np.array(vectors), problems


# ------------------------------------------------------------------------------- (b) stability

def _equilibrium_matrix(design, wire_ids, crossings, pyramids, centre, scale):
    """6P x 4C: column = one pyramid vector's force and couple on each wire (rows of wire_ids)."""
    row = {w: 6 * k for k, w in enumerate(wire_ids)}
    cols = []
    for c in crossings:
        i, j = c["wires"]
        x = (np.asarray(c["point"], dtype=float) - centre) / scale
        for b in pyramids[c["id"]]:
            col = np.zeros(6 * len(wire_ids))
            t = np.cross(x, b)
            col[row[i]:row[i] + 3], col[row[i] + 3:row[i] + 6] = b, t
            col[row[j]:row[j] + 3], col[row[j] + 3:row[j] + 6] = -b, -t
            cols.append(col)
    return np.array(cols).T if cols else np.zeros((6 * len(wire_ids), 0))


def load_basis(p):
    """Sec. 4.2: the 6P x 6(P-1) matrix L (unit load on component k, its negative on the same
    component of the last wire), extended by minus the sum of its columns."""
    L = np.zeros((6 * p, 6 * (p - 1)))
    for k in range(6 * (p - 1)):
        L[k, k] = 1.0
        L[6 * (p - 1) + k % 6, k] = -1.0
    return np.column_stack([L, -L.sum(axis=1)])


def carries_all_loads(design, wire_ids, pyramids):
    """None if the wires (rigid) can carry every load of the basis with their hooked crossings'
    pyramids, else a sentence naming the first load that cannot be carried."""
    wire_ids = list(wire_ids)
    ws = set(wire_ids)
    crossings = [c for c in design["crossings"] if c["hook"] != 0 and set(c["wires"]) <= ws]
    pts = np.array([c["point"] for c in design["crossings"] if set(c["wires"]) <= ws] or [[0.0, 0.0, 0.0]],
                   dtype=float)
    centre = pts.mean(axis=0)
    scale = float(np.sqrt(((pts - centre) ** 2).sum(axis=1).mean())) or 1.0
    M = _equilibrium_matrix(design, wire_ids, crossings, pyramids, centre, scale)
    L = load_basis(len(wire_ids))
    if M.shape[1] == 0:
        return f"wires {wire_ids}: no hooked crossing among them"
    names = ("force x", "force y", "force z", "couple x", "couple y", "couple z")
    for k in range(L.shape[1]):
        res = linprog(np.ones(M.shape[1]), A_eq=M, b_eq=-L[:, k], bounds=(0, None), method="highs")
        if res.status != 0:
            if k < L.shape[1] - 1:
                what = f"a unit {names[k % 6]} on wire {wire_ids[k // 6]} (against wire {wire_ids[-1]})"
            else:
                what = "minus the sum of the basis loads"
            return f"wires {wire_ids}: cannot carry {what}: {res.message.strip()}"
    return None


def check_stability(design, prefixes=True):
    problems, pyramids = [], {}
    for c in design.get("crossings", []):
        if c["hook"] == 0:
            continue
        b, p = pyramid(design, c)
        problems += p
        if b is not None:
            pyramids[c["id"]] = b
    if problems:
        return problems, pyramids
    order = list(design.get("assembly_order") or [w["id"] for w in design["wires"]])
    if sorted(order) != sorted(w["id"] for w in design["wires"]):
        problems.append(f"assembly_order {order} is not a permutation of the wires")
        return problems, pyramids
    if len(order) < 2:
        return problems, pyramids
    lengths = range(3, len(order) + 1) if prefixes else [len(order)]
    steps = design.get("assembly_steps")
    if prefixes and steps and [w for step in steps for w in step] == order:
        # a step that adds two wires at once (two_hand_steps) is one state, not two: only the
        # prefixes that end a step are real
        ends = [sum(len(step) for step in steps[:i + 1]) for i in range(len(steps))]
        lengths = [k for k in ends if k >= 3]
    if len(order) == 2:
        lengths = [2]  # only one pair: check it with torques too (the finished sculpture)
    for k in lengths:
        why = carries_all_loads(design, order[:k], pyramids)
        if why:
            problems.append(("unstable: " if k == len(order) else f"assembly prefix of {k} unstable: ") + why)
    return problems, pyramids


# ----------------------------------------------------------------------------------- (c) forces

def check_forces(design, pyramids):
    crossings = design.get("crossings", [])
    if not crossings or any("force" not in c for c in crossings):
        return []  # the forces stage did not run: nothing to check
    problems = []
    fmax = max([np.linalg.norm(c["force"]) for c in crossings] + [1e-12])
    net = {w["id"]: np.zeros(6) for w in design["wires"]}
    pts = np.array([c["point"] for c in crossings], dtype=float)
    centre = pts.mean(axis=0)
    for c in crossings:
        f = np.asarray(c["force"], dtype=float)
        if c["hook"] == 0:
            if np.linalg.norm(f) > FORCE_TOL * fmax:
                problems.append(f"crossing {c['id']}: null hook but a force of {np.linalg.norm(f):.3g} N")
            continue
        b = pyramids.get(c["id"])
        if b is not None and np.linalg.norm(f) > FORCE_TOL * fmax:
            _, resid = nnls(b.T, f)
            if resid > 1e-4 * np.linalg.norm(f) + FORCE_TOL * fmax:
                problems.append(f"crossing {c['id']}: force {np.round(f, 4).tolist()} N is outside its friction "
                                f"pyramid (distance {resid:.3g} N)")
        i, j = c["wires"]
        t = np.cross(np.asarray(c["point"], dtype=float) - centre, f)
        net[i] += np.concatenate([f, t])
        net[j] -= np.concatenate([f, t])
    size = float(np.ptp(pts, axis=0).max()) or 1.0
    for w, r in net.items():
        if np.linalg.norm(r[:3]) > 1e-5 * fmax or np.linalg.norm(r[3:]) > 1e-5 * fmax * size:
            problems.append(f"wire {w}: contact forces do not balance (net force {np.linalg.norm(r[:3]):.3g} N, "
                            f"net torque {np.linalg.norm(r[3:]):.3g} N m)")
    return problems


def recheck(design, prefixes=True):
    """Every broken promise of a design (docs/formats.md, Sec. 4.1-4.2) as a sentence; [] if none."""
    problems = check_geometry(design)
    stab, pyramids = check_stability(design, prefixes=prefixes)
    problems += stab
    problems += check_forces(design, pyramids)
    return problems


def main(argv):
    status = 0
    for path in argv:
        with open(path) as f:
            design = json.load(f)
        problems = recheck(design)
        print(f"{path}: {'ok' if not problems else f'{len(problems)} problem(s)'}")
        for p in problems:
            print(f"  - {p}")
        status |= bool(problems)
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
