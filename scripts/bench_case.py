"""One case of scripts/bench, run in its own process so its peak memory is its own:

    /usr/bin/python3.11 scripts/bench_case.py SCENE.json [--budget SECONDS] [--max-repeats N]

Loads the scene like a batch run (bench_scenes.load_and_slice: mesh scaled to "size", planes
with it), times slicing, then solves the sliced design repeatedly (a fresh copy each time) and
prints one JSON document on stdout: the design's P, C, longest wire, verdict, and per stage the
median over the runs of every number the stage records in design["stages"] (stage names are read
from the design, so new stages appear without changes here), plus the wall time between the
pipeline's progress calls (which includes the Python glue around the native calls). Then the same design solved with the
layering's own hooks (pipeline.solve(hook_patterns=1): the whole solve as Live runs it),
its median wall time as own_hooks_solve_seconds.

Repeats: the first solve decides, so slow cases stay affordable: as many runs as fit in
--budget seconds (default 12), at least 1 and at most --max-repeats (default 5).
"""
import argparse
import copy
import json
import os
import resource
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import bench_scenes  # noqa: E402  (puts addon/ on sys.path)


def vm_kib(field):
    """VmHWM / VmRSS of this process in KiB from /proc (None where /proc is missing)."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith(field + ":"):
                    return int(line.split()[1])
    except OSError:
        pass
    return None


def numbers(d):
    """The numeric (non-bool) entries of a stage's record, by key."""
    return {k: v for k, v in d.items() if isinstance(v, (int, float)) and not isinstance(v, bool)}


class TimedModule:
    """The native module with every call timed: {name: [calls, seconds]} in `calls`; a call of
    optimize_target_shapes counts once per wire it solves (its problems)."""

    def __init__(self, module):
        self._module = module
        self.calls = {}

    def __getattr__(self, name):
        attr = getattr(self._module, name)
        if not callable(attr) or isinstance(attr, type):
            return attr

        def timed(*args, **kwargs):
            start = time.perf_counter()
            result = None
            try:
                result = attr(*args, **kwargs)
                return result
            finally:
                entry = self.calls.setdefault(name, [0, 0.0])
                # its problems may come from a generator: count the results
                entry[0] += len(result or ()) if name == "optimize_target_shapes" else 1
                entry[1] += time.perf_counter() - start
        return timed


def solve_once(sliced, scene, hook_patterns=None):
    from wiresculpt import native, pipeline

    timed = TimedModule(native.require())
    original = native.require
    native.require = lambda: timed
    design = copy.deepcopy(sliced)
    wall = {}
    last = [time.perf_counter(), time.process_time()]

    def progress(stage, _message):
        # Wall time, and this process's CPU time (on a quiet machine the two agree, except in the
        # target shape, which solves two wires at once; on a shared one the CPU time is what the
        # stage itself cost).
        now, cpu = time.perf_counter(), time.process_time()
        wall[stage] = wall.get(stage, 0.0) + now - last[0]
        wall[stage + "/cpu"] = wall.get(stage + "/cpu", 0.0) + cpu - last[1]
        last[0], last[1] = now, cpu

    start = time.perf_counter()
    try:
        solved = pipeline.solve(design, scene.material, scene.settings, progress, hook_patterns=hook_patterns)
    finally:
        native.require = original
    total = time.perf_counter() - start
    design = solved if solved is not None else design
    design["_native_calls"] = timed.calls
    return design, wall, total


def native_seconds(design):
    """Seconds spent inside the native calls of stages that report them per call."""
    out = {}
    target = design["stages"].get("target_shape")
    if target and isinstance(target.get("wires"), list):
        out["target_shape"] = sum(w.get("seconds", 0.0) for w in target["wires"])
    return out


def run(scene_path, budget, max_repeats):
    load_start = time.perf_counter()
    scene, V, F, planes, sliced = bench_scenes.load_and_slice(scene_path)
    load_seconds = time.perf_counter() - load_start
    slicing_runs = []
    from wiresculpt import pipeline
    for _ in range(5):
        t = time.perf_counter()
        pipeline.slice_and_pick(V, F, planes, scene.material, scene.settings)
        slicing_runs.append(time.perf_counter() - t)
    rss_before = vm_kib("VmHWM")

    runs = []
    design, wall, total = solve_once(sliced, scene)
    runs.append((design, wall, total))
    repeats = max(1, min(max_repeats, int(budget / max(total, 1e-6))))
    for _ in range(repeats - 1):
        runs.append(solve_once(sliced, scene))

    # The whole solve as Live runs it: layering, target shape, forces and rest shape with the layering's own
    # hooks (the hook search limited to one pattern, as Live solves), repeated like the runs above.
    first = solve_once(sliced, scene, hook_patterns=1)
    own_hooks = [first] + [solve_once(sliced, scene, hook_patterns=1)
                           for _ in range(max(1, min(max_repeats, int(budget / max(first[2], 1e-6)))) - 1)]

    stage_names = list(dict.fromkeys(name for d, _w, _t in runs for name in d["stages"]))
    stages = {}
    for name in stage_names:
        records = [numbers(d["stages"][name]) for d, _w, _t in runs if name in d["stages"]]
        keys = list(dict.fromkeys(k for r in records for k in r))
        stages[name] = {k: statistics.median([r[k] for r in records if k in r]) for k in keys}
        walls = [w[name] for _d, w, _t in runs if name in w]
        if walls:
            stages[name]["wall_seconds"] = statistics.median(walls)
            stages[name]["cpu_seconds"] = statistics.median(w[name + "/cpu"] for _d, w, _t in runs if name in w)
        natives = [native_seconds(d).get(name) for d, _w, _t in runs]
        natives = [x for x in natives if x is not None]
        if natives:
            stages[name]["native_seconds"] = statistics.median(natives)
    stages.setdefault("slicing", {})["wall_seconds"] = statistics.median(slicing_runs)

    calls = {}
    for name in dict.fromkeys(n for d, _w, _t in runs for n in d["_native_calls"]):
        per_run = [d["_native_calls"].get(name, [0, 0.0]) for d, _w, _t in runs]
        calls[name] = {"calls": statistics.median(c for c, _s in per_run),
                       "seconds": statistics.median(s for _c, s in per_run)}
    glue = statistics.median(t - sum(s for _c, s in d["_native_calls"].values()) for d, _w, t in runs)
    design = runs[-1][0]
    target_results = [w.get("nlopt_result", "") for w in design["stages"].get("target_shape", {}).get("wires", [])]
    lengths = [bench_scenes.wire_length(w["contour"], w["closed"]) for w in design["wires"]]
    targets = [bench_scenes.wire_length(w["target"], w["closed"]) for w in design["wires"] if "target" in w]
    dofs = sum(len(w["target"]) for w in design["wires"] if "target" in w)
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return {
        "scene": os.path.abspath(scene_path),
        "P": len(design["wires"]),
        "C": len(design.get("crossings", [])),
        "hooked": sum(1 for c in design.get("crossings", []) if c.get("hook")),
        "longest_wire": max(lengths) if lengths else 0.0,
        "total_wire": sum(lengths),
        "longest_target": max(targets) if targets else None,
        "target_points": dofs,
        "triangles": int(len(F)),
        "size": scene.size,
        "stable": bool(design["stable"]),
        "reason": design.get("reason", ""),
        "pending_stages": design.get("pending_stages", []),
        "nulled_crossings": len(design["stages"].get("target_shape", {}).get("nulled_crossings", [])),
        "warnings": len(design.get("warnings", [])),
        "repeats": len(runs),
        "load_seconds": load_seconds,
        "solve_seconds": statistics.median(t for _d, _w, t in runs),
        "own_hooks_solve_seconds": statistics.median(t for _d, _w, t in own_hooks),
        "own_hooks_stable": bool(own_hooks[-1][0]["stable"]),
        "own_hooks_repeats": len(own_hooks),
        "native_calls": calls,
        "glue_seconds": glue,
        "target_maxeval_wires": sum("MAXEVAL" in r for r in target_results),
        "stages": stages,
        "rss_before_solve_kib": rss_before,
        "peak_rss_kib": vm_kib("VmHWM") or usage.ru_maxrss,
        "cpu_seconds": usage.ru_utime + usage.ru_stime,
    }


# The exit status when the solver module cannot be loaded (bench_pipeline retries then: the module
# may be being rebuilt), its reason on stderr.
NO_SOLVER_STATUS = 3


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene")
    parser.add_argument("--budget", type=float, default=12.0, help="seconds of solving per case (default 12)")
    parser.add_argument("--max-repeats", type=int, default=5)
    args = parser.parse_args(argv)
    from wiresculpt import native
    if not native.available():
        print(f"RuntimeError: {native.LOAD_ERROR}", file=sys.stderr)
        sys.exit(NO_SOLVER_STATUS)
    result = run(args.scene, args.budget, args.max_repeats)
    json.dump(result, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
