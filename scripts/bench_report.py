"""Turns the bench's raw measurements into docs/performance.json, docs/performance.md and the plot.

    bench_report.py SLICING.json [PIPELINE.json] DOCS [--plot PNG] [--bench-seconds S] [--live LIVE.json]

SLICING.json is wiresculpt_bench's output (native slicing sweep), PIPELINE.json that of
scripts/bench_pipeline.py (the Table 2 stand-ins and the growth sweeps). The Markdown is generated
here, prose included, so every number in it comes from the measurements; do not edit it by hand.
"""
import argparse
import datetime
import json
import re
import math
import os
import platform
import statistics
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "addon"))
from wiresculpt.core.files import write_atomic  # noqa: E402

LIVE_SETTLE_MS = 50  # live/engine.SETTLE_SECONDS, named in the prose
KNOWN_STAGES = ["layering", "target_shape", "forces", "rest_shape", "stands_3d"]
# The paper's Table 2 columns and the stages of ours they correspond to.
PAPER_COLUMNS = [("stab_s", "Stab.", ["layering"]), ("shape_s", "S.Opt.", ["target_shape"]),
                 ("rest_s", "R.Conf.", ["forces", "rest_shape"])]
COLORS = {"layering": "#1f77b4", "target_shape": "#d62728", "forces": "#2ca02c", "rest_shape": "#9467bd",
          "stands_3d": "#8c564b",
          "total": "#333333"}


def machine():
    model, mhz = "unknown CPU", None
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name") and model == "unknown CPU":
                    model = line.split(":", 1)[1].strip()
                elif line.startswith("cpu MHz") and mhz is None:
                    mhz = float(line.split(":", 1)[1])
    except OSError:
        pass
    return {"cpu": model, "mhz": mhz, "cores": os.cpu_count(), "system": platform.platform(),
            "python": platform.python_version(), "load_average": list(os.getloadavg())}


def secs(x):
    if x is None:
        return "–"
    if x == 0:
        return "0"
    if x < 0.001:
        return f"{x:.5f}"
    if x < 1:
        return f"{x:.3f}"
    if x < 100:
        return f"{x:.2f}"
    return f"{x:.0f}"


def stage_names(cases):
    # relayering is the record of the pipeline's rounds, whose stages are already counted
    seen = [n for c in cases for n in c.get("stages", {}) if n not in ("slicing", "relayering")]
    return [n for n in KNOWN_STAGES if n in seen] + [n for n in dict.fromkeys(seen) if n not in KNOWN_STAGES]


def stage_seconds(case, name):
    """The time a user waits for the stage: the wall time between the pipeline's progress calls,
    summed over every time the stage ran (nulling and coupling rounds re-run the target shape and
    the forces), Python glue included. The rest shape is computed inside the forces call, so its
    own native seconds are shown instead."""
    s = case.get("stages", {}).get(name)
    if s is None:
        return None
    if name == "rest_shape":
        return s.get("seconds", s.get("wall_seconds"))
    if name == "forces" and "hook_search" in case.get("stages", {}):
        # the wall time after the forces' progress call runs on through the other hook patterns
        # (hook_search, its own column): the forces' own seconds instead
        return s.get("seconds", s.get("wall_seconds"))
    return s.get("wall_seconds", s.get("seconds"))


def stat(case, name, key):
    return case.get("stages", {}).get(name, {}).get(key)


def glue_seconds(case):
    """Wall time of the solve minus the time inside native calls (each call timed by the bench):
    the Python around them."""
    return case.get("glue_seconds")


def target_solves(case):
    """Wires solved by the native target shape: one a call of optimize_target_shape, one a problem
    of optimize_target_shapes (bench_case.TimedModule)."""
    calls = case.get("native_calls", {})
    counts = [(calls.get(name) or {}).get("calls") for name in ("optimize_target_shape", "optimize_target_shapes")]
    counts = [c for c in counts if c is not None]
    return sum(counts) if counts else None


def ok(cases, kind=None):
    return [c for c in cases if "error" not in c and (kind is None or c["kind"] == kind)]


def mib(kib):
    return f"{kib / 1024:.0f}" if kib else "–"


def intf(x):
    return "–" if x is None else f"{int(round(x)):,}"


# ---------------------------------------------------------------------------------------------

def paper_table(cases):
    lines = [
        "| model | P | C | longest wire (cm) paper / ours | Stab. (s) paper / layering | S.Opt. (s) paper / "
        "target shape | R.Conf. (s) paper / forces + rest | whole solve, layering's hooks (s) paper / ours (ratio) | "
        "live round trip (s) (ratio) | hook search (s) | whole solve with hook search (s) (ratio) | "
        "LP solves | search nodes | NLopt iterations | peak memory (MiB) | stable |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    for c in cases:
        if c["kind"] not in ("paper", "example"):
            continue
        p = c.get("paper") or {"P": c["P"], "C": c["C"], "l_max_cm": None, "stab_s": None, "shape_s": None,
                               "rest_s": None}
        name = c["name"].capitalize() + (" (bundled example)" if c["kind"] == "example" else "")

        def theirs(x, fmt="{:.2f}"):
            return "–" if x is None else fmt.format(x)

        if "error" in c:
            lines.append(f"| {name} | {p['P']} | {p['C']} | {theirs(p['l_max_cm'], '{}')} / – | "
                         f"{theirs(p['stab_s'], '{}')} / – | {theirs(p['shape_s'], '{}')} / – | "
                         f"{theirs(p['rest_s'], '{}')} / – | – | – | – | – | – | – | – | – | {c['error']} |")
            continue
        ours = []
        for key, _label, names in PAPER_COLUMNS:
            vals = [stage_seconds(c, n) for n in names]
            have = [v for v in vals if v is not None]
            # the forces' CPU seconds run on through the hook search, as their wall time does
            cpu = [None if n == "forces" and "hook_search" in c.get("stages", {}) else stat(c, n, "cpu_seconds")
                   for n in names]
            cpu = f" (CPU {secs(sum(cpu))})" if have and None not in cpu else ""
            ours.append(f"{theirs(p[key])} / {secs(sum(have)) + cpu if have else 'not run'}")
        # The paper's total: the sum of its three stages.
        total = None if p["stab_s"] is None else p["stab_s"] + p["shape_s"] + p["rest_s"]

        def ratio(x):
            return f" ({x / total:.1%})" if total and x is not None else ""

        # The whole solve as Live runs it: pipeline.solve with the layering's own hooks (as Live solves).
        own = c.get("own_hooks_solve_seconds")
        ours.append(f"{theirs(total)} / {secs(own)}{ratio(own)}" + ("" if c.get("own_hooks_stable", True) else ", not stable"))
        trip, job = (c.get("live") or {}).get("median"), (c.get("live") or {}).get("job_median")
        ours.append(f"{secs(trip)}{ratio(trip)}, job {secs(job)}" if trip is not None else ((c.get("live") or {}).get("error") or "not run"))
        ours.append(secs(stage_seconds(c, "hook_search")) if stage_seconds(c, "hook_search") is not None else "–")
        # The whole pipeline.solve (layering, target shape, forces, rest shape, the hook search and
        # the glue between), against the sum of the paper's three stages.
        ours.append(f"{secs(c.get('solve_seconds'))}{ratio(c.get('solve_seconds'))}")
        pc = f"{c['P']}" if c["P"] == p["P"] else f"{c['P']} (paper {p['P']})"
        cc = f"{c['C']}" if c["C"] == p["C"] else f"{c['C']} (paper {p['C']})"
        lines.append(
            f"| {name} | {pc} | {cc} | {theirs(p['l_max_cm'], '{}')} / {100 * c['longest_wire']:.1f} | "
            f"{' | '.join(ours)} | {intf(stat(c, 'layering', 'lp_solves'))} | {intf(stat(c, 'layering', 'nodes'))} | "
            f"{intf(stat(c, 'target_shape', 'iterations'))} | {mib(c.get('peak_rss_kib'))} | "
            f"{'yes' if c['stable'] else 'no'} |")
    return lines


def detail_table(cases, names, first="case"):
    head = [first, "P", "C", "longest wire (m)"] + [f"{n} (s)" for n in names] + [
        "Python glue (s)", "LP solves", "nodes", "LPs / node", "NLopt it. (target)", "wire solves (target)",
        "target points",
        "forces it.", "peak MiB", "runs", "stable"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" + "---:|" * (len(head) - 2) + "---|"]
    for c in cases:
        if "error" in c:
            lines.append(f"| {c['name']} | {c['P']} | {c['C']} | – | " + " | ".join("–" for _ in names)
                         + f" | – | – | – | – | – | – | – | – | – | {c['error']} |")
            continue
        lp, nodes = stat(c, "layering", "lp_solves"), stat(c, "layering", "nodes")
        ratio = f"{lp / nodes:.1f}" if lp and nodes else "–"
        stable = "yes" if c["stable"] else ("no: " + (f"{c['nulled_crossings']} crossings nulled"
                                                      if c.get("nulled_crossings") else "unstable"))
        if c["stable"] and c.get("nulled_crossings"):
            stable += f" ({c['nulled_crossings']} crossings nulled)"
        row = [c["name"], str(c["P"]), str(c["C"]), f"{c['longest_wire']:.2f}"]
        row += [secs(stage_seconds(c, n)) if stage_seconds(c, n) is not None else "not run" for n in names]
        its = intf(stat(c, "target_shape", "iterations"))
        if c.get("target_maxeval_wires"):
            its += f" ({c['target_maxeval_wires']} capped)"
        row += [secs(glue_seconds(c)), intf(lp), intf(nodes), ratio, its, intf(target_solves(c)),
                intf(c.get("target_points")), intf(stat(c, "forces", "iterations")), mib(c.get("peak_rss_kib")),
                str(c["repeats"]), stable]
        lines.append("| " + " | ".join(row) + " |")
    return lines


def growth(xs, ys):
    """Exponent k of y ~ x^k fitted through the first and last positive points, or None."""
    pts = [(x, y) for x, y in zip(xs, ys) if x and y and x > 0 and y > 0]
    if len(pts) < 2 or pts[0][0] == pts[-1][0]:
        return None
    (x0, y0), (x1, y1) = pts[0], pts[-1]
    return math.log(y1 / y0) / math.log(x1 / x0)


def prose(cases, names):
    out = []
    sweep = sorted(ok(cases, "crossings"), key=lambda c: c["C"])
    lengths = sorted(ok(cases, "length"), key=lambda c: c["longest_wire"])
    everything = ok(cases)

    # layering
    lp_per_node = [stat(c, "layering", "lp_solves") / stat(c, "layering", "nodes") for c in everything
                   if stat(c, "layering", "nodes")]
    us_per_lp = [1e6 * stat(c, "layering", "seconds") / stat(c, "layering", "lp_solves") for c in everything
                 if stat(c, "layering", "lp_solves")]
    out += ["### Layering (Sec. 4.2: GLPK feasibility LPs inside a branch and bound)", ""]
    if lp_per_node:
        out.append(f"Every search node costs {min(lp_per_node):.1f}–{max(lp_per_node):.1f} LP solves "
                   f"(median {statistics.median(lp_per_node):.1f}): one stability check per candidate hook "
                   f"assignment of the step, each check a GLPK problem re-solved for the 6(P−1)+1 loads from "
                   f"the previous basis; one LP solve takes {statistics.median(us_per_lp):.0f} µs "
                   f"(median, {min(us_per_lp):.0f}–{max(us_per_lp):.0f} µs), so the stage's time is the number "
                   "of nodes the search visits times a nearly constant cost.")
    if len(sweep) >= 2:
        a, b = sweep[0], sweep[-1]
        k_nodes = growth([c["C"] for c in sweep], [stat(c, "layering", "nodes") for c in sweep])
        out.append("")
        out.append(f"Over the sphere sweep the nodes grow from {intf(stat(a, 'layering', 'nodes'))} (C = {a['C']}) to "
                   f"{intf(stat(b, 'layering', 'nodes'))} (C = {b['C']})"
                   + (f", about C^{k_nodes:.1f} end to end" if k_nodes else "") + ": ")
        jumps = []
        for prev, cur in zip(sweep, sweep[1:]):
            n0, n1 = stat(prev, "layering", "nodes"), stat(cur, "layering", "nodes")
            if n0 and n1 and n1 / n0 > 5 and n1 > 2000:
                jumps.append(f"{intf(n0)} → {intf(n1)} nodes from C = {prev['C']} to {cur['C']} "
                             f"({secs(stat(prev, 'layering', 'seconds'))} s → {secs(stat(cur, 'layering', 'seconds'))} s)")
        out[-1] += ("not smoothly, the search explodes where it jumps " + "; ".join(jumps) + ". The search is exact "
                    "(it proves the lexicographic optimum), so once the first complete structure's bound stops "
                    "pruning, every order of the remaining wires whose prefixes stay stable is explored; the "
                    "paper's Chair (8 wires, 38 crossings) took 22 s in 2016 for the same reason."
                    if jumps else f"between {min(stat(c, 'layering', 'nodes') / c['P'] for c in sweep):.0f} and "
                    f"{max(stat(c, 'layering', 'nodes') / c['P'] for c in sweep):.0f} nodes per wire: the first "
                    "complete structure's bound prunes most of the tree.")
    stress = [c for c in everything if c["kind"] == "search"]
    for c in stress:
        twin = next((t for t in sweep if t["C"] == c["C"] and t["P"] == c["P"]), None)
        if twin:
            out.append("")
            out.append(f"Geometry matters more than size: `{c['name']}` has the same P = {c['P']} and C = {c['C']} as "
                       f"`{twin['name']}`, but its planes are spread wider (the optimum's largest deviation e_c is "
                       f"{stat(c, 'layering', 'max_metric') or 0:.2f} against {stat(twin, 'layering', 'max_metric') or 0:.2f}) "
                       f"and the bound prunes late: {intf(stat(c, 'layering', 'nodes'))} "
                       f"nodes and {intf(stat(c, 'layering', 'lp_solves'))} LP solves, "
                       f"{secs(stat(c, 'layering', 'seconds'))} s, against {intf(stat(twin, 'layering', 'nodes'))} "
                       f"nodes and {secs(stat(twin, 'layering', 'seconds'))} s.")
    out.append("")

    # target shape
    out += ["### Target shape (Sec. 4.3: one problem per wire, windows on long wires; a Newton SQP per block, "
            "led by SLSQP's first steps where kinks open, SLSQP where the SQP fails)", ""]
    if lengths:
        per_m = [(stat(c, "target_shape", "iterations") or 0) / max(c["total_wire"], 1e-9) for c in lengths]
        s_per_pt = [1e3 * stage_seconds(c, "target_shape") / max(c.get("target_points") or 1, 1) for c in lengths
                    if stage_seconds(c, "target_shape")]
        k_t = growth([c["longest_wire"] for c in lengths], [stage_seconds(c, "target_shape") for c in lengths])
        a, b = lengths[0], lengths[-1]
        out.append(f"The problem size is the wire length, not the mesh: each wire is resampled every 1.5 × l_min "
                   f"(2.25 cm) between crossings, so the same scene scaled from a {a['longest_wire']:.1f} m to a "
                   f"{b['longest_wire']:.1f} m longest wire goes from {intf(a.get('target_points'))} to "
                   f"{intf(b.get('target_points'))} optimised points and from {secs(stage_seconds(a, 'target_shape'))} "
                   f"to {secs(stage_seconds(b, 'target_shape'))} s"
                   + (f" (about length^{k_t:.1f})" if k_t else "") + f". That is {min(per_m):,.0f}–{max(per_m):,.0f} "
                   f"energy evaluations per metre of wire and {statistics.median(s_per_pt):.2f} ms per point: the "
                   "windowed solve (8-point windows swept until nothing moves by 0.1 µm, each by a Newton SQP "
                   "that converges in 4–6 iterations; docs/method-target-shape.md, The solver) keeps each "
                   "iteration small, so the cost is the number of sweeps times the number of windows. The paper saw "
                   "the same effect (its Airplane, two long wires, 51 s).")
        capped = [c for c in everything if any("MAXEVAL" in str(w) for w in [c.get("nlopt_result", "")])]
        del capped
    nulled = [c for c in everything if c.get("nulled_crossings")]
    if nulled:
        out.append("")
        out.append("Where a crossing cannot be realised (two crossings too close for the machine's l_min, or "
                   "a kink the solver leaves outside its contact cone) the stage nulls it and solves the wires "
                   "through it again (up to 4 rounds), which multiplies its time; then the assembly is re-checked "
                   "and, if it "
                   "is no longer stable, forces and rest shape do not run: " + ", ".join(
                       f"{c['name']} ({c['nulled_crossings']} nulled, {'still stable' if c['stable'] else 'unstable'})"
                       for c in nulled) + ".")
    glue = [(c["name"], glue_seconds(c), c["solve_seconds"]) for c in everything
            if c.get("solve_seconds") and glue_seconds(c) is not None]
    if glue:
        frac = [g / t for _n, g, t in glue if t > 0]
        worst = max(glue, key=lambda g: g[1] / max(g[2], 1e-9))
        out.append("")
        out.append(f"Python glue (the wall time of a solve minus the time inside every native call, each call "
                   f"timed by the bench: building arrays, plane frames, deep copies of the design, copying "
                   f"results into it) is {100 * statistics.median(frac):.1f}% of a solve (median; at most "
                   f"{100 * worst[1] / worst[2]:.1f}%, {worst[0]}, {secs(worst[1])} s): the time is in the native "
                   "solvers, not in the Python around them.")
    capped = [c for c in everything if c.get("target_maxeval_wires")]
    if capped:
        out.append("")
        out.append("NLopt's budget (max_iterations, 20,000 energy evaluations per wire, shared by all windows) "
                   "runs out on long wires: " + ", ".join(f"{c['name']} ({c['target_maxeval_wires']} of {c['P']} "
                                                          "wires)" for c in capped)
                   + ". There the target shape stops at NLOPT_MAXEVAL_REACHED rather than converging, so its "
                   "time levels off while the problem keeps growing; the length exponent above is a lower bound.")
    rounds = [c for c in everything if (stat(c, "target_shape", "coupling_rounds") or 1) > 1]
    if rounds:
        out.append("")
        out.append("The pipeline couples target and rest shape (Sec. 4.3: a rest bend over the machine's limit "
                   "lowers the target's limit and solves again), so target shape and forces may run more than "
                   "once; the stage times above add all rounds: " + ", ".join(
                       f"{c['name']} ({stat(c, 'target_shape', 'coupling_rounds'):.0f} rounds, "
                       f"{intf(target_solves(c))} wire solves for {c['P']} wires)" for c in rounds) + ".")
    out.append("")

    # forces
    if any(stat(c, "forces", "seconds") for c in everything):
        out += ["### Forces and rest shape (Sec. 4.4, Eq. 6–12)", ""]
        rows = [c for c in sweep if stat(c, "forces", "seconds")]
        if rows:
            b = rows[-1]
            parts = [(k, stat(b, "forces", k)) for k in ("lp_seconds", "nlp_seconds", "load_capacity_seconds")]
            parts = ", ".join(f"{k.replace('_seconds', '').replace('_', ' ')} {secs(v)} s" for k, v in parts if v is not None)
            k_f = growth([c["C"] for c in rows], [stat(c, "forces", "seconds") for c in rows])
            out.append(f"Over the sphere sweep the forces stage grows from {secs(stat(rows[0], 'forces', 'seconds'))} s "
                       f"(C = {rows[0]['C']}) to {secs(stat(b, 'forces', 'seconds'))} s (C = {b['C']})"
                       + (f", about C^{k_f:.1f}" if k_f else "") + f"; at C = {b['C']} it splits into {parts} "
                       f"({intf(stat(b, 'forces', 'iterations'))} NLopt iterations, "
                       f"{intf(stat(b, 'forces', 'lp_iterations'))} LP iterations). The rest shape is computed in the same "
                       f"native call and takes at most "
                       f"{secs(max(stat(c, 'rest_shape', 'seconds') or 0 for c in everything))} s.")
        out.append("")
    return out


def slowest(cases, names):
    """Per case the stage with the most time."""
    counts = {}
    for c in ok(cases):
        best = max(names, key=lambda n: stage_seconds(c, n) or 0.0)
        counts.setdefault(best, []).append(c["name"])
    return counts


def markdown(data):
    m = data["machine"]
    cases = data.get("pipeline", {}).get("cases", [])
    names = stage_names(cases)
    lines = [
        "# Performance",
        "",
        "Written by `scripts/bench` (do not edit by hand; the prose lives in `scripts/bench_report.py`).",
        f"Machine: {m['cpu']}" + (f" at {m['mhz'] / 1000:.2f} GHz" if m.get("mhz") else "")
        + f", {m['cores']} cores, {m['system']}, Python {m['python']}; wiresculpt {data['version']}; "
        f"{data.get('date', '')}.",
        "The solver's stages are single-threaded except the target shape, which solves up to two wires at "
        "once (its CPU seconds can then exceed its wall time). Pipeline times are medians over repeated solves of one "
        "sliced design (1–5 runs: as many as fit in about 12 s), each case in its own process; peak memory is "
        "that process's maximum resident set (Python, numpy, the mesh and the solver).",
    ]
    if m.get("load_average"):
        lines.append(f"Load average when the report was written: {m['load_average'][0]:.1f} (1 min), "
                     f"{m['load_average'][2]:.1f} (15 min) on {m['cores']} cores; other work on the machine "
                     "inflates wall times (the Table 2 comparison adds each stage's CPU seconds in parentheses; every "
                     "case's CPU seconds are in performance.json).")
    if data.get("bench_seconds"):
        lines.append(f"The whole bench (build check, native slicing sweep, scene generation with its (P, C) check, "
                     f"every case) took {data['bench_seconds']:.0f} s.")
    lines.append("")
    if cases:
        lines += [
            "![Stage time against the number of crossings and against wire length](images/performance.png)",
            "",
            "## Against the paper's Table 2",
            "",
            "The paper's models are not available, so `scripts/bench_scenes.py` generates stand-ins from code: "
            "smooth unions of ellipsoids and rounded boxes meshed by marching tetrahedra, cut by planes chosen so "
            "that the design has exactly the paper's number of wires P and crossings C (parallel planes never "
            "cross; two wires of non-parallel planes cross twice), and scaled (scene `size`) so that the longest "
            "wire is as long as the paper's l_max. The generator slices and layers every scene and stops if (P, C) "
            "differ; the table shows the counts the bench measured. Paper: 3.80 GHz desktop, one thread, GLPK and "
            "KNitro, 2016. Its *R.Conf.* (rest configuration) is our forces + rest shape stages. *Hook search* "
            "(beyond the paper) solves the target shape and forces again for the other hook patterns "
            "of equal Eq. 2 cost and keeps the one whose forces are best (docs/method-forces.md §12); its "
            "seconds include the chosen pattern's target shape and forces, so the whole solve with hook search "
            "is the wall time of pipeline.solve, not the sum of the columns. *Whole solve, layering's hooks* "
            "is the wall time of pipeline.solve limited to the layering's own hook pattern "
            "(`hook_patterns=1`, as Live solves): layering, target shape, forces and rest shape, with "
            "re-layering rounds where they happen; the ratio is to the sum of the paper's three stages. "
            "*Live round trip* (`scripts/bench_live.py`, Blender 3.4 with a window under Xvfb, 1280×800, "
            "software OpenGL): a slicing plane moved 1 mm along its normal, back and forth, five times, "
            "with Live on; each from the moment the plane's location is set to the overlay's first draw "
            "of the new verdict's wires (median; *job*: the median wall time of the live job itself, slicing, solve and the preview's curves, on its worker thread). It includes Live's settle time "
            f"({LIVE_SETTLE_MS} ms), its timer, re-slicing and the solve, and Blender's own redraws, "
            "which here take longer than the solve: under software OpenGL a redraw of the 3D view takes "
            "about 0.2 s, the viewport's default anti-aliasing redraws it 8 times after every change, and "
            "the timer only runs between redraws, so the round trip is about four redraws (the move's, the "
            "one after the timer first sees it, the one the solve runs beside, the verdict's) plus the job; "
            "with a GPU a redraw takes milliseconds (docs/history/target-shape-rounds.md). The globe "
            "is the bundled example (scripts/examples/globe), which has no counterpart in the paper.",
            "",
        ]
        lines += paper_table(cases)
        paper_cases = ok(cases, "paper")
        if paper_cases:
            ours = sum(c["solve_seconds"] for c in paper_cases)
            theirs = sum(c["paper"]["stab_s"] + c["paper"]["shape_s"] + c["paper"]["rest_s"] for c in paper_cases)
            own = [c.get("own_hooks_solve_seconds") for c in paper_cases]
            own = (f" (with the layering's own hooks: {secs(sum(own))} s)" if None not in own else "")
            lines += ["", f"Together the five solves take {secs(ours)} s here{own} against {theirs:.1f} s in the paper. "
                      "The stand-ins are not the paper's shapes, so only the orders of magnitude compare: the "
                      "(P, C, l_max) that the paper names as the drivers of its times are matched."]
        lines += ["", "Every stage of every case, with the counters behind the times:", ""]
        lines += detail_table(ok(cases, "paper") + [c for c in cases if "error" in c and c["kind"] == "paper"], names,
                              "model")
        lines += [
            "",
            "## Growth with the number of crossings",
            "",
            "A UV sphere (9,024 triangles, diameter 0.6 m, so the largest section is about 1.9 m long) cut by "
            "three families of parallel planes spread over ±40% of the radius, a + b + c planes with "
            "C = 2(ab + bc + ca), from 4 wires and 10 crossings to 15 wires and 150 (case `sphere-abc`).",
            "",
        ]
        lines += detail_table(sorted([c for c in cases if c["kind"] == "crossings"], key=lambda c: c["C"]), names)
        search = [c for c in cases if c["kind"] == "search"]
        if search:
            lines += [
                "",
                "The same 5 + 5 + 4 network with its planes spread over ±50% of the radius of a 0.45 m sphere "
                "(`search-554`): the same P and C as `sphere-554`, but a different geometry of contact pyramids, "
                "and the layering's branch and bound has to work much harder:",
                "",
            ]
            lines += detail_table(search + [c for c in cases if c["name"] == "sphere-554"], names)
        lines += [
            "",
            "## Growth with wire length",
            "",
            "The 1 + 1 + 2 sphere (P 4, C 10: Teddy's counts) scaled so that its longest wire is 0.5 m to 3 m: "
            "the same network, longer wires. The machine's l_min (1.5 cm) is fixed, so the number of points "
            "the target shape optimises grows with the length. (With 2 + 2 + 2 planes, 0.5 m wires put "
            "crossings closer than the 3 cm a free bending point between them needs, and the target shape "
            "nulls them.)",
            "",
        ]
        lines += detail_table(sorted([c for c in cases if c["kind"] == "length"], key=lambda c: c["longest_wire"]),
                              names)
        lines += ["", "## Where the time goes", ""]
        lines += prose(cases, names)
        counts = slowest(cases, names)
        if counts:
            lines.append("Slowest stage per case: " + "; ".join(
                f"{n} in {len(v)} ({', '.join(v)})" for n, v in sorted(counts.items(), key=lambda kv: -len(kv[1]))) + ".")
            lines.append("")
        lines += [
            "What was done: every solve is timed stage by stage and native call by native call, so the glue "
            "column separates Python from the solvers; it is small everywhere, and the bench keeps the mesh "
            "sliced once per case so it measures the solver, not OBJ parsing or Python start-up. For the "
            "slowest stage, the target shape: after a crossing is nulled only the wires through it are solved "
            "again (the first version solved every wire in every round: on the Chair 40 wire solves and 79,098 "
            "NLopt iterations became 28 and 49,243, iterations then counted in the last coupling round only), and a crossing counts as realised within 0.1 deg of its "
            "contact cone instead of 1e-6 rad, which had nulled crossings missing it by 0.0003-0.02 deg, "
            "forced extra rounds and made the Chair unstable. Then (measured on the Chair's 28 recorded wire solves, "
            "replayed on one core): the windows stop when nothing moves by 0.1 µm instead of 1 nm (at 1 nm the "
            "sweeps chased SLSQP's own stopping noise, up to 135 sweeps on a 43-point wire, for the same energy "
            "to 7 digits), and each Sec. 4.3 coupling round starts with the crossings the previous one nulled "
            "and reuses every wire whose optimum already fits the lower bend limit: 28 wire solves, 93,681 "
            "NLopt evaluations and 1.84 s of solver CPU time became 14, 12,921 and 0.25 s, with every wire's "
            "largest and RMS distance to its contour unchanged to the µm (Duck and Airplane likewise). The stage's "
            "NLopt iterations and wire solves now add every coupling round. For the forces stage: its SLSQP "
            "sees a working set of the torque rows (those near their bound at the LP's optimum, then any the "
            "solution violates, until none is) instead of all of them, the same optimum (a test compares it "
            "with the full problem on random networks); on the Chair one call went from about 845 rows and "
            "0.54 s to 245 rows and 0.13 s. Then the plastic limit became the paper's 3D bound |t_v| <= t_max "
            "(an inscribed polytope of 180 rows per vertex, added to the LPs lazily as solutions violate "
            "them): more LP rounds and 15 load-capacity LPs instead of 6 put the Chair's forces + rest "
            "back to about 0.28 s per call (two coupling rounds: the table's 0.55 s). Still open: the layering "
            "search on unfavourable networks (exact branch and bound, exponential once its bound stops "
            "pruning; `search-554`), the forces stage's NLP and load capacity at large C (each added LP row "
            "re-solves GLPK from scratch; `search-554` spends 17.6 s in two forces calls), and NLopt's "
            "per-wire evaluation cap on wires over about 2.5 m.",
            "",
        ]
    lines += [
        "## Slicing",
        "",
        "A UV sphere of radius 1 m cut by 10 planes (five horizontal, five through the axis), measured by the "
        "native `wiresculpt_bench`.",
        "*Prepare* validates the mesh, welds vertices and drops degenerate and duplicate triangles",
        "(once per mesh); *slice* cuts all 10 planes. The issue's goal: 1M triangles x 10 planes well",
        "under a second.",
        "",
        "| triangles | vertices | planes | contours | prepare (s) | slice 10 planes (s) | total (s) |",
        "|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for c in data["slicing"]:
        lines.append(f"| {c['triangles']:,} | {c['vertices']:,} | {c['planes']} | {c['contours']} | "
                     f"{c['prepare_seconds']:.4f} | {c['slice_seconds']:.4f} | "
                     f"{c['prepare_seconds'] + c['slice_seconds']:.4f} |")
    lines += [
        "",
        "Both grow linearly with the triangle count. Preparation is hashing: welding probes a",
        "neighbouring grid cell only when a vertex lies within the tolerance of its cell's face, and",
        "duplicate triangles are found by bucketing on their smallest vertex (an earlier version with",
        "`std::unordered_map`/`unordered_set` took 0.42 s at 1M triangles). Slicing is one signed",
        "distance per vertex and one sign test per triangle per plane; only crossed triangles touch a",
        "hash table. In Blender, reading the evaluated mesh into arrays adds its own cost on top.",
        "",
    ]
    return "\n".join(lines)


def console_table(data):
    """The short table scripts/bench prints."""
    cases = data.get("pipeline", {}).get("cases", [])
    names = stage_names(cases)
    head = f"{'case':<14}{'P':>4}{'C':>5}{'l_max m':>9}" + "".join(f"{n[:12]:>14}" for n in names) + \
        f"{'LPs':>9}{'nodes':>8}{'NLopt it':>10}{'MiB':>6}  stable"
    rows = [head]
    for c in cases:
        if "error" in c:
            rows.append(f"{c['name']:<14}{c['P']:>4}{c['C']:>5}  {c['error'][:100]}")
            continue
        cells = "".join(f"{secs(stage_seconds(c, n)) if stage_seconds(c, n) is not None else '-':>14}" for n in names)
        rows.append(f"{c['name']:<14}{c['P']:>4}{c['C']:>5}{c['longest_wire']:>9.2f}{cells}"
                    f"{intf(stat(c, 'layering', 'lp_solves')):>9}{intf(stat(c, 'layering', 'nodes')):>8}"
                    f"{intf(stat(c, 'target_shape', 'iterations')):>10}{mib(c.get('peak_rss_kib')):>6}  "
                    f"{'yes' if c['stable'] else 'no'}")
    for c in data["slicing"]:
        rows.append(f"slicing {c['triangles']:>9,} triangles x {c['planes']} planes: prepare "
                    f"{c['prepare_seconds']:.4f} s, slice {c['slice_seconds']:.4f} s")
    return "\n".join(rows)


def plot(data, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = data.get("pipeline", {}).get("cases", [])
    names = stage_names(cases)
    sweep = sorted(ok(cases, "crossings"), key=lambda c: c["C"])
    lengths = sorted(ok(cases, "length"), key=lambda c: c["longest_wire"])
    paper = ok(cases, "paper")
    fig, axes = plt.subplots(1, 3, figsize=(16, 6), dpi=100)
    paper_marks = {"layering": ("stab_s", "s"), "target_shape": ("shape_s", "^"), "forces": ("rest_s", "D")}

    def stage_lines(ax, rows, x):
        for n in names:
            pts = [(x(c), stage_seconds(c, n)) for c in rows if stage_seconds(c, n)]
            if pts:
                ax.plot(*zip(*pts), "-o", color=COLORS.get(n), label=n.replace("_", " "), ms=5)
        pts = [(x(c), c["solve_seconds"]) for c in rows if c.get("solve_seconds")]
        if pts:
            ax.plot(*zip(*pts), "--", color=COLORS["total"], label="whole solve", lw=1)
        # hollow: where the design was not stable after the target shape (forces not run)
        for c in rows:
            if not c["stable"]:
                ax.axvline(x(c), color="#bbbbbb", lw=0.8, ls=":", zorder=0)

    def paper_points(ax, x, label_paper=True):
        for n, (key, marker) in paper_marks.items():
            pts = [(x(c), c["paper"][key]) for c in paper]
            if pts:
                ax.plot(*zip(*pts), marker, mfc="none", mec=COLORS[n], ms=8, ls="none",
                        label=f"paper {dict(stab_s='Stab.', shape_s='S.Opt.', rest_s='R.Conf.')[key]} (2016)"
                        if label_paper else None)

    ax = axes[0]
    stage_lines(ax, sweep, lambda c: c["C"])
    paper_points(ax, lambda c: c["paper"]["C"])
    for c in paper:  # our stand-ins, same colours, small filled crosses
        for n in names:
            s = stage_seconds(c, n)
            if s:
                ax.plot(c["C"], s, "x", color=COLORS.get(n), ms=6)
    ax.set_xlabel("crossings C (sphere sweep: lines; Table 2 stand-ins: x)")
    ax.set_ylabel("seconds (median)")
    ax.set_title("Stage time against the number of crossings")
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.25)
    ax.plot([], [], "x", color="#555555", label="our Table 2 stand-ins")
    handles, labels = ax.get_legend_handles_labels()

    ax = axes[1]
    stage_lines(ax, lengths, lambda c: c["longest_wire"])
    paper_points(ax, lambda c: c["paper"]["l_max_cm"] / 100, label_paper=False)
    pc = f"P {lengths[0]['P']}, C {lengths[0]['C']}" if lengths else ""
    ax.set_xlabel(f"longest wire (m) (sphere {pc} scaled; paper's models at their l_max)")
    ax.set_ylabel("seconds (median)")
    ax.set_title("Stage time against wire length")
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.25)

    ax = axes[2]
    series = [("layering", "lp_solves", "LP solves (layering)", "#1f77b4", "-o"),
              ("layering", "nodes", "search nodes (layering)", "#17becf", "-s"),
              ("target_shape", "iterations", "NLopt iterations (target shape)", "#d62728", "-^"),
              ("forces", "iterations", "NLopt iterations (forces)", "#2ca02c", "-D")]
    for stage, key, label, color, style in series:
        pts = [(c["C"], stat(c, stage, key)) for c in sweep if stat(c, stage, key)]
        if pts:
            ax.plot(*zip(*pts), style, color=color, label=label, ms=5)
    ax.set_xlabel("crossings C (sphere sweep)")
    ax.set_ylabel("count (median per solve)")
    ax.set_title("Solver work against the number of crossings")
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=8, loc="upper left")

    m = data["machine"]
    fig.suptitle(f"wiresculpt {data['version']} on {m['cpu']}, one thread; dotted verticals: design not stable "
                 "after the target shape (forces not run)", fontsize=10)
    fig.legend(handles, labels, loc="lower center", ncol=5, fontsize=9, frameon=False)
    fig.tight_layout(rect=(0, 0.1, 1, 1))
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = path + ".tmp.png"
    fig.savefig(tmp)
    plt.close(fig)
    os.replace(tmp, path)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("inputs", nargs="+", help="SLICING.json [PIPELINE.json] DOCS")
    parser.add_argument("--plot", help="PNG to write (default DOCS/images/performance.png)")
    parser.add_argument("--bench-seconds", type=float)
    parser.add_argument("--live", help="scripts/bench_live.py's output: the live round trips by case")
    args = parser.parse_args(argv)
    if len(args.inputs) not in (2, 3):
        parser.error("expected SLICING.json [PIPELINE.json] DOCS")
    raw_path, docs = args.inputs[0], args.inputs[-1]
    with open(raw_path) as f:
        data = json.load(f)
    if len(args.inputs) == 3:
        with open(args.inputs[1]) as f:
            data["pipeline"] = json.load(f)
    if args.live and data.get("pipeline") and os.path.exists(args.live):
        with open(args.live) as f:
            live = {r["name"]: r for r in json.load(f)["cases"]}
        for c in data["pipeline"]["cases"]:
            if c["name"] in live:
                c["live"] = live[c["name"]]
    data["machine"] = machine()
    data["date"] = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    if args.bench_seconds:
        data["bench_seconds"] = args.bench_seconds
    if data.get("pipeline"):
        from bench_scenes import PAPER  # noqa: E402
        data["paper_table2"] = PAPER
        plot(data, args.plot or os.path.join(docs, "images", "performance.png"))
    write_atomic(os.path.join(docs, "performance.json"), json.dumps(data, indent=1) + "\n")
    text = markdown(data)
    write_atomic(os.path.join(docs, "performance.md"), text + kept_sections(os.path.join(docs, "performance.md"), text))
    print(console_table(data))


KEPT = re.compile(r"<!-- (\w+):begin -->.*?<!-- \1:end -->\n", re.S)


def kept_sections(path, text):
    """The sections of the earlier report that other runs write between `<!-- NAME:begin -->` and
    `<!-- NAME:end -->` (the plane assistant's corpus table, scripts/plane_search_corpus.py), which
    this report does not make: kept as they were, after it. The corpus section is put back by
    scripts/corpus.py from docs/corpus.json."""
    try:
        with open(path, encoding="utf-8") as f:
            old = f.read()
    except OSError:
        return ""
    return "".join("\n" + m.group(0) for m in KEPT.finditer(old)
                   if m.group(1) != "corpus" and f"<!-- {m.group(1)}:begin -->" not in text)


if __name__ == "__main__":
    main()
