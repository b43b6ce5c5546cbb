"""Wires longer than the stock: split into pieces joined at low-stress points, or said why not.

A wire whose rest shape (plus, on a closed wire, the profile's closed_overlap fed past the cut) is
longer than the machine profile's `stock_length` cannot be bent in one go. It is made of pieces,
each bent from its own stock by its own program, joined by a *joint* of length `joint_length`
(JOINT_LENGTH, 30 mm): the two pieces overlap over the joint, each running half of it past the
joint's centre, so the pieces' lengths add up to the wire's plus one joint length per joint.

The rule (docs/machine-protocol.md, "Wires longer than the stock"), with h = joint_length / 2 and
m the machine's min_segment, for a joint centred at arc length x from the cut along the rest shape:

- the joint [x - h, x + h] lies on the wire, no crossing within m of it (the hooks stay free);
- the piece that ends at x + h has its last feed (from its last bend, or the wire's start) at least
  m long, and the piece that starts at x - h its first feed (to its first bend, or the wire's end):
  the machine's minimum feed, the bend program's own rule;
- every piece, with its allowance (a closed wire's last piece: closed_overlap), fits the stock;
- the fewest pieces; among those, the joints where the largest in-plane bending moment over the
  joint is least (in_plane_moments: the torque the rest shape stores, Eq. 11), then the least
  sum of those moments.

A joint whose span has no bend is a *sleeve* (JOINT_SLEEVE): a straight tube over the two ends; a
span with bends is an *overlap* (JOINT_OVERLAP): the two ends, bent alike, laid side by side and
bound or soldered. Either is stiff: the 3D model keeps the wire whole.

bpy-free. Causes are codes (core/sizes.py); core/sizes.split_sentence makes their words.
"""
import math

import numpy as np

from .. import native
from ..core import sizes
from ..core.sizes import (JOINT_LENGTH, JOINT_OVERLAP, JOINT_SLEEVE, NO_JOINT_POINT, PIECE_NOT_BENDABLE,
                          PIECE_TOO_LONG)

STEP = 0.0005  # m: the spacing of the joint centres tried inside each admissible stretch
SNAP = 1e-6    # m: a piece's end this close to a rest point ends on that point (no zero-length segment)
RELATIVE = 1e-9


def walk(wire):
    """Target index of each rest point (docs/formats.md: rest starts at the cut)."""
    m = len(wire["target"])
    if wire["closed"]:
        return [(wire["cut"] + k) % m for k in range(m + 1)]
    return list(range(m))


def arc_lengths(points):
    """m from the first point to each point of a polyline."""
    p = np.asarray(points, dtype=np.float64)
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])


def rest_positions(design, wire):
    """[(rest index, crossing)] of the wire's crossings (rest starts at the cut)."""
    m = len(wire["target"])
    cut = max(wire.get("cut", -1), 0) if wire["closed"] else 0
    out = []
    for c in design.get("crossings", []):
        for k in (0, 1):
            if c["wires"][k] == wire["id"]:
                out.append((((c["vertices"][k] - cut) % m) if wire["closed"] else c["vertices"][k], c, k))
    return out


def in_plane_moments(design, wire):
    """N m per rest point: the in-plane torque t_v = n . sum_{k after v} (x_v - x_k) x f_k of
    docs/method-forces.md (Eq. 11), walking the wire from its cut on its target, f_k the force of
    crossing k on this wire (`force` on wires[0], its opposite on wires[1]); 0 at the free ends.
    Between two rest points the torque is linear in arc length (no force acts there)."""
    X = np.asarray(wire["target"], dtype=np.float64)[walk(wire)]
    n = np.asarray(wire["plane"]["normal"], dtype=np.float64)
    k = len(X)
    F = np.zeros((k, 3))
    for j, c, side in rest_positions(design, wire):
        f = np.asarray(c.get("force") or (0.0, 0.0, 0.0), dtype=np.float64)
        F[j] += f if side == 0 else -f
    # t_i = n . (X_i x sum_{j>i} F_j) - sum_{j>i} n . (X_j x F_j)
    tail_f = np.concatenate([np.cumsum(F[::-1], axis=0)[::-1][1:], np.zeros((1, 3))])
    own = np.cross(X, F) @ n
    tail_m = np.concatenate([np.cumsum(own[::-1])[::-1][1:], [0.0]])
    return np.cross(X, tail_f) @ n - tail_m


def _forbidden(bends, crossings, length, h, m):
    """Intervals of joint centres x the rule rules out (module text), closed-open as floats."""
    out = [(-math.inf, h), (length - h, math.inf)]
    for b in [0.0] + list(bends):  # the piece ending at x + h: no bend (nor the start) in (x + h - m, x + h]
        out.append((b - h, b - h + m))
    for b in list(bends) + [length]:  # the piece starting at x - h: no bend (nor the end) in [x - h, x - h + m)
        out.append((b + h - m, b + h))
    for c in crossings:
        out.append((c - h - m, c + h + m))
    return out


def admissible(bends, crossings, length, joint, min_segment):
    """Sorted [(a, b)] stretches of joint centres (m from the cut) the rule allows."""
    h = joint / 2
    cuts = sorted(_forbidden(bends, crossings, length, h, min_segment))
    out, at = [], -math.inf
    for a, b in cuts:
        if a > at:
            out.append((at, a))
        at = max(at, b)
    slack = 1e-9 * max(length, 1.0)
    return [(a + slack, b - slack) for a, b in out if b - a > 2 * slack and math.isfinite(a) and math.isfinite(b)]


def joint_moment(s, t, x, joint):
    """N m: the largest |in-plane torque| over the joint [x - h, x + h] (t per rest point at arc
    lengths s, linear between them)."""
    h = joint / 2
    inside = np.abs(t[(s > x - h) & (s < x + h)])
    ends = np.abs(np.interp([x - h, x + h], s, t))
    return float(max(ends.max(), inside.max() if inside.size else 0.0))


def _candidates(stretches):
    xs = []
    for a, b in stretches:
        count = max(int(math.floor((b - a) / STEP)), 0)
        xs.extend(a + STEP * np.arange(count + 1))
        xs.append(b)
    return np.unique(np.asarray(xs, dtype=np.float64))


def _windows(x, joint, min_segment, usable):
    """(lo, hi) per candidate j: the candidates i < j that may be the joint before it (a piece
    between them fits `usable`, their joints stand min_segment apart)."""
    lo = np.searchsorted(x, x + joint - usable - RELATIVE * usable, side="left")
    hi = np.searchsorted(x, x - joint - min_segment + 1e-12, side="right")
    return lo, hi


def choose(x, cost, length, joint, min_segment, usable, usable_last):
    """Joint centres (a subset of the candidates `x`, sorted) for the fewest pieces, then the least
    largest joint cost, then the least sum of costs; None when no set of them fits."""
    h = joint / 2
    N = len(x)
    if N == 0:
        return None
    tol = RELATIVE * usable
    first = x + h <= usable + tol
    last = length - x + h <= usable_last + tol
    lo, hi = _windows(x, joint, min_segment, usable)
    # pass 1: level k = joints so far; best[j] = least largest cost of a chain ending at joint j
    best = np.where(first, cost, np.inf)
    levels = [best]
    while not np.isfinite(best[last]).any():
        nxt = np.full(N, np.inf)
        for j in range(N):
            if hi[j] > lo[j]:
                nxt[j] = max(cost[j], best[lo[j]:hi[j]].min())
        if not np.isfinite(nxt).any() or len(levels) > N:
            return None
        best = nxt
        levels.append(best)
    bound = best[last].min() * (1 + 1e-9) + 1e-15
    # pass 2: the same number of joints, costs within the bound, the least sum; then backtrack
    ok = cost <= bound
    total = np.where(first & ok, cost, np.inf)
    back = []
    for _level in range(1, len(levels)):
        nxt, arg = np.full(N, np.inf), np.full(N, -1)
        for j in range(N):
            if ok[j] and hi[j] > lo[j]:
                k = int(np.argmin(total[lo[j]:hi[j]])) + lo[j]
                if np.isfinite(total[k]):
                    nxt[j], arg[j] = total[k] + cost[j], k
        total = nxt
        back.append(arg)
    end = int(np.argmin(np.where(last, total, np.inf)))
    chain = [end]
    for arg in reversed(back):
        chain.append(int(arg[chain[-1]]))
    return sorted(float(x[j]) for j in chain)


def least_stock(x, length, joint, min_segment, allowance):
    """m: the shortest stock any set of the candidate joints needs (its longest piece, the last
    with `allowance`); the whole wire's when there is no candidate."""
    whole = length + allowance
    if len(x) == 0:
        return whole
    h = joint / 2
    longest = x + h  # the first piece ends at each candidate
    for j in range(len(x)):
        before = x[j] - x[:j] >= joint + min_segment - 1e-12
        if before.any():
            longest[j] = min(longest[j], float(np.maximum(longest[:j][before], x[j] - x[:j][before] + joint).min()))
    return float(min(whole, np.maximum(longest, length - x + h + allowance).min()))


def plan(s, moments, bends, crossings, stock_length, joint=JOINT_LENGTH, min_segment=0.015, allowance=0.0):
    """The split of one wire: s (m, arc length per rest point), moments (N m per rest point),
    bends and crossings (m from the cut), the stock (m), the joint's length, the machine's
    min_segment, the allowance of the last piece (m: closed_overlap on a closed wire).

    Returns {"pieces": [{"from", "to", "length", "allowance"}], "joints": [{"at", "from", "to", "kind",
    "moment"}]} or {"split_fault": {"cause", figures}} (core/sizes.split_sentence)."""
    s = np.asarray(s, dtype=np.float64)
    t = np.asarray(moments, dtype=np.float64)
    length = float(s[-1])
    h = joint / 2
    usable, usable_last = float(stock_length), float(stock_length) - allowance
    figures = {"length": length, "stock": float(stock_length), "allowance": float(allowance),
               "joint_length": float(joint), "min_segment": float(min_segment)}
    x = _candidates(admissible(bends, crossings, length, joint, min_segment))
    if len(x) == 0:
        return {"split_fault": {"cause": NO_JOINT_POINT, **figures, "least_stock": length + allowance}}
    cost = np.array([joint_moment(s, t, xi, joint) for xi in x])
    chosen = choose(x, cost, length, joint, min_segment, usable, usable_last) if usable_last > 0 else None
    if chosen is None:
        return {"split_fault": {"cause": PIECE_TOO_LONG, **figures,
                                "least_stock": least_stock(x, length, joint, min_segment, allowance)}}
    ends = [0.0] + chosen + [length]
    pieces = []
    for k in range(len(chosen) + 1):
        a = 0.0 if k == 0 else ends[k] - h
        b = length if k == len(chosen) else ends[k + 1] + h
        pieces.append({"from": a, "to": b, "length": b - a, "allowance": float(allowance) if k == len(chosen) else 0.0})
    bends = np.asarray(bends, dtype=np.float64)
    joints = [{"at": xi, "from": xi - h, "to": xi + h, "length": float(joint),
               "kind": JOINT_OVERLAP if ((bends > xi - h + 1e-9) & (bends < xi + h - 1e-9)).any() else JOINT_SLEEVE,
               "moment": joint_moment(s, t, xi, joint), "pieces": [k + 1, k + 2]}
              for k, xi in enumerate(chosen)]
    return {"pieces": pieces, "joints": joints}


def piece_polyline(points, s, a, b):
    """The part of a polyline (its arc lengths s) from arc length a to b, ends interpolated (an
    end within SNAP of a point ends on it)."""
    p = np.asarray(points, dtype=np.float64)
    inner = [i for i in range(len(s)) if a + SNAP < s[i] < b - SNAP]

    def at(value):
        return np.array([np.interp(value, s, p[:, k]) for k in range(p.shape[1])])

    return np.array([at(a)] + [p[i] for i in inner] + [at(b)])


def with_overlap(rest, closed, overlap):
    """The polyline the machine bends: a closed wire's rest shape with its last segment fed on
    straight by `overlap` m past the cut (the profile's closed_overlap), so the loop's ends
    overlap; an open wire, or no allowance, unchanged. Moving the last point keeps the program's
    bends and lengthens its final feed by exactly `overlap`."""
    rest = np.asarray(rest, dtype=np.float64)
    if not closed or overlap <= 0 or len(rest) < 2:
        return rest
    d = rest[-1] - rest[-2]
    out = rest.copy()
    out[-1] = rest[-1] + overlap * d / np.linalg.norm(d)
    return out


def piece_name(wire, number, count):
    """"X0/0 piece 1 of 2": the name a piece's files and messages give."""
    return f"{wire['name']} piece {number} of {count}"


def wire_plan(design, wire, stock_length, closed_overlap, machine, joint=JOINT_LENGTH):
    """plan() of one wire with a rest shape, on `machine` (a native profile dict: its min_segment,
    and the bends of its program of the whole rest shape); None when the wire fits the stock.
    Each piece gets its "name", each joint its "point" (3D, on the target) and the pieces'
    programs are checked (a piece the program refuses: PIECE_NOT_BENDABLE with its message). None
    too when the whole rest shape's program is refused (fab/buildability.py names why)."""
    rest = np.asarray(wire["rest"], dtype=np.float64)
    s = arc_lengths(rest)
    allowance = closed_overlap if wire.get("closed") else 0.0
    if s[-1] + allowance <= stock_length * (1 + RELATIVE):
        return None
    try:
        program = native.make_bend_program(rest, machine)
    except ValueError:  # the whole wire cannot be bent (buildability says so): no pieces either
        return None
    bends = [float(s[v]) for v in program["bend_vertices"]]
    crossings = sorted(float(s[j]) for j, _c, _k in rest_positions(design, wire))
    out = plan(s, in_plane_moments(design, wire), bends, crossings, stock_length, joint,
               float(machine["min_segment"]), allowance)
    if "pieces" not in out:
        return out
    count = len(out["pieces"])
    target = np.asarray(wire["target"], dtype=np.float64)[walk(wire)]
    for k, piece in enumerate(out["pieces"]):
        piece["name"] = piece_name(wire, k + 1, count)
        line = piece_polyline(rest, s, piece["from"], piece["to"])
        if k + 1 == count and allowance > 0:
            line = with_overlap(line, True, allowance)
        problems = native.bend_program_problems(line, machine)
        if problems:
            return {"split_fault": {"cause": PIECE_NOT_BENDABLE, "length": float(s[-1]), "stock": float(stock_length),
                                    "allowance": float(allowance), "joint_length": float(joint),
                                    "min_segment": float(machine["min_segment"]), "least_stock": float(s[-1]) + allowance,
                                    "piece": k + 1, "message": problems[0]["message"]}}
    for joint_ in out["joints"]:
        joint_["point"] = [float(np.interp(joint_["at"], s, target[:, k])) for k in range(3)]
    return out


def design_machine(design):
    """The native profile the pipeline checks wires with: the default machine with the design's
    limits (as fab/export.machine_profile gives it without a profile)."""
    out = dict(native.default_machine_profile())
    out.update({k: float(design["machine"][k]) for k in LIMIT_KEYS if k in design.get("machine", {})})
    return out


LIMIT_KEYS = ("min_segment", "max_bend_deg", "min_bend_deg")


def plans(design, stock_length=sizes.STOCK_LENGTH, closed_overlap=0.0, machine=None, joint=JOINT_LENGTH):
    """{wire id: wire_plan} of every wire with a rest shape longer than the stock; `machine` a
    native profile as fab/export.machine_profile makes it (None: design_machine)."""
    out = {}
    for wire in design.get("wires", []):
        if "rest" not in wire or len(wire["rest"]) < 2:
            continue
        length = float(arc_lengths(wire["rest"])[-1]) + (closed_overlap if wire.get("closed") else 0.0)
        if length <= stock_length * (1 + RELATIVE):
            continue
        if machine is None:
            machine = design_machine(design)
        out[wire["id"]] = wire_plan(design, wire, stock_length, closed_overlap, machine, joint)
    return out


KEYS = ("pieces", "joints", "split_fault")  # the per-wire keys written here


def apply(design, stock_length=sizes.STOCK_LENGTH, closed_overlap=0.0, machine=None, joint=JOINT_LENGTH):
    """plans() into the design: each split wire's `pieces` and `joints`, each wire that cannot be
    split its `split_fault`; earlier ones removed; `stages.pieces` with the stock, the joint's
    length, the allowance and the counts. Returns the plans."""
    found = plans(design, stock_length, closed_overlap, machine, joint)
    for wire in design.get("wires", []):
        for key in KEYS:
            wire.pop(key, None)
        wire.update(found.get(wire["id"]) or {})
    design.setdefault("stages", {})["pieces"] = {
        "stock_length": float(stock_length), "joint_length": float(joint), "closed_overlap": float(closed_overlap),
        "split": sum(1 for p in found.values() if p and "pieces" in p),
        "unsplittable": sum(1 for p in found.values() if p and "split_fault" in p)}
    return found
