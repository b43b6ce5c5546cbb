"""The target-shape stage alone, timed as Live runs it, for comparing builds:

    /usr/bin/python3.11 scripts/bench_target.py [--root CHECKOUT] [--reps N] [--json OUT] [NAME...]

For each Table 2 stand-in and the bundled globe (or the cases whose names contain a NAME), the scene
is sliced as a batch run slices it, then solved REPS times by the checkout's own
pipeline.solve(hook_patterns=1) (older checkouts without hook_patterns: pipeline.solve). The clock
covers every call of stages.target_shape.run (its Python and its native solves, on as many threads
as that version uses), summed per solve; prints the best and the median per case, in ms.

--root runs another checkout's add-on (a worktree with its module built) with this script's scenes,
so two builds are timed on the same inputs one after the other: run it for each and compare.
The scenes are generated into out/bench (bench_scenes.generate) when missing there.
"""
import argparse
import inspect
import json
import os
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
CASES = ["duck", "teddy", "airplane", "car", "chair", "globe"]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", default=ROOT, help="the checkout whose add-on is timed")
    parser.add_argument("--reps", type=int, default=21)
    parser.add_argument("--scenes", default=os.path.join(ROOT, "out", "bench"))
    parser.add_argument("--json", help="write {case: [ms of each solve]} here")
    parser.add_argument("names", nargs="*")
    args = parser.parse_args(argv)
    names = [c for c in CASES if not args.names or any(n in c for n in args.names)]

    # The scenes come from this checkout's generator; the add-on timed is --root's.
    sys.path.insert(0, HERE)
    import bench_scenes  # noqa: E402  (puts this checkout's addon/ on sys.path)
    assert "wiresculpt" not in sys.modules
    sys.path.insert(0, os.path.join(os.path.abspath(args.root), "addon"))  # before this checkout's
    from wiresculpt import pipeline  # noqa: E402
    from wiresculpt.stages import target_shape  # noqa: E402

    manifest = os.path.join(args.scenes, "manifest.json")
    have = set()
    if os.path.exists(manifest):
        with open(manifest) as f:
            have = {c["name"] for c in json.load(f)["cases"]}
    if not set(names) <= have:
        bench_scenes.generate(args.scenes, names, run_check=False, say=lambda *_: None)
    with open(manifest) as f:
        cases = {c["name"]: c for c in json.load(f)["cases"]}

    spent = [0.0]
    run = target_shape.run

    def timed(*a, **k):
        began = time.perf_counter()
        try:
            return run(*a, **k)
        finally:
            spent[0] += time.perf_counter() - began
    target_shape.run = timed
    print(f"add-on: {os.path.dirname(pipeline.__file__)}", flush=True)
    own_hooks = "hook_patterns" in inspect.signature(pipeline.solve).parameters

    import copy
    out = {}
    for name in names:
        case = cases[name]
        scene_path = os.path.join(args.scenes, case["scene"])
        scene, _V, _F, _planes, sliced = bench_scenes.load_and_slice(scene_path)
        times = []
        for _ in range(args.reps):
            design = copy.deepcopy(sliced)
            spent[0] = 0.0
            if own_hooks:
                design = pipeline.solve(design, scene.material, scene.settings, hook_patterns=1)
            else:
                design = pipeline.solve(design, scene.material, scene.settings)
            times.append(spent[0] * 1000.0)
        out[name] = times
        print(f"{name:9s} best {min(times):8.3f} ms  median {statistics.median(times):8.3f} ms  "
              f"({args.reps} solves, {'stable' if design['stable'] else 'not stable'})", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
