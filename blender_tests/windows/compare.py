"""How a Windows (or macOS) globe design is compared with the Linux one: the differences, as
sentences, between two reports of globe_design.py ([] when they agree within the tolerances).

    python compare.py LINUX.json OTHER.json     (exit 1 and one line per difference)

Used by test_windows.py under Wine and by .github/workflows/platforms.yml on real Windows and
macOS runners. Exactly equal: stability and reason, the wires (names, closed), each crossing's
wires and hook, the assembly order and the load-capacity bases; within POINT_TOL (metres) every
contour, target and rest point, within FORCE_RTOL each crossing's normal force and each load
capacity. The builds share the method but not the C library (glibc against msvcrt: sin, cos,
exp may differ in the last bit), so the iterative stages may end a few ulps apart; the measured
differences are in docs/testing.md.
"""
import json
import sys

POINT_TOL = 1e-9  # m: a nanometre, 4e-9 of the globe's 0.25 m
FORCE_RTOL = 1e-6
AXES = ("+x", "-x", "+y", "-y", "+z", "-z")


def worst_point_gap(a, b):
    return max((abs(x - y) for p, q in zip(a, b) for x, y in zip(p, q)), default=0.0)


def differences(linux, other):
    lin, oth = linux["design"], other["design"]
    out = []

    def same(what, a, b):
        if a != b:
            out.append(f"{what}: {b!r} here, {a!r} on Linux")

    same("stable", lin["stable"], oth["stable"])
    same("reason", lin["reason"], oth["reason"])
    same("wires", [(w["name"], w["closed"]) for w in lin["wires"]], [(w["name"], w["closed"]) for w in oth["wires"]])
    for l, o in zip(lin["wires"], oth["wires"]):
        for key in ("contour", "target", "rest"):
            if len(l[key]) != len(o[key]):
                out.append(f"wire {l['name']} {key}: {len(o[key])} points here, {len(l[key])} on Linux")
                continue
            gap = worst_point_gap(l[key], o[key])
            if gap > POINT_TOL:
                out.append(f"wire {l['name']} {key}: points up to {gap:.3g} m apart (tolerance {POINT_TOL:g} m)")
    same("crossings (wires, hook)", [(c["wires"], c["hook"]) for c in lin["crossings"]],
         [(c["wires"], c["hook"]) for c in oth["crossings"]])
    for i, (l, o) in enumerate(zip(lin["crossings"], oth["crossings"])):
        if abs(l["normal_force"] - o["normal_force"]) > FORCE_RTOL * abs(l["normal_force"]):
            out.append(f"crossing {i} normal force: {o['normal_force']!r} here, {l['normal_force']!r} on Linux")
    same("assembly order", lin["assembly_order"], oth["assembly_order"])
    for axis in AXES:
        a, b = lin["load_capacity"][axis], oth["load_capacity"][axis]
        if abs(a - b) > FORCE_RTOL * abs(a):
            out.append(f"load capacity {axis}: {b!r} here, {a!r} on Linux")
    same("load capacity bases", lin["load_capacity"]["base"], oth["load_capacity"]["base"])
    return out


def measured(linux, other):
    """The largest differences, for the record: (point gap in m, force relative gap)."""
    lin, oth = linux["design"], other["design"]
    gap = max(worst_point_gap(l[k], o[k]) for l, o in zip(lin["wires"], oth["wires"]) for k in ("contour", "target", "rest"))
    forces = [(l["normal_force"], o["normal_force"]) for l, o in zip(lin["crossings"], oth["crossings"])]
    forces += [(lin["load_capacity"][a], oth["load_capacity"][a]) for a in AXES]
    rel = max(abs(a - b) / abs(a) for a, b in forces if a)
    return gap, rel


if __name__ == "__main__":
    with open(sys.argv[1]) as f:
        linux = json.load(f)
    with open(sys.argv[2]) as f:
        other = json.load(f)
    found = differences(linux, other)
    for line in found:
        print(line)
    gap, rel = measured(linux, other)
    print(f"compare: points within {gap:.3g} m, forces within {rel:.3g} (relative); "
          f"{len(found)} difference(s) beyond the tolerances")
    sys.exit(1 if found else 0)
