"""Record, replay and compare the native target-shape calls of whole solves (the "same
optimum" check and its instruction counts, kept with the code rather than in /tmp):

    /usr/bin/python3.11 scripts/target_calls.py record CALLS.pkl [NAME...]
    /usr/bin/python3.11 scripts/target_calls.py replay CALLS.pkl RESULTS.pkl [--root CHECKOUT] [--only K] [--case NAME]
    /usr/bin/python3.11 scripts/target_calls.py compare A.pkl B.pkl

record: every wire solved by native.optimize_target_shapes in pipeline.solve(hook_patterns=1) (as Live
solves) on the Table 2 stand-ins and the bundled globe (or the cases named), with its inputs.
replay: runs the recorded calls (--only K: call K alone; --case NAME: that case's) through --root's
module (default this checkout's) and keeps the results. Under `valgrind --tool=callgrind
--toggle-collect='*optimize*'` the counts are the solver's instructions (the release module is
stripped; a RelWithDebInfo build names the functions).
compare: per call, the largest distance between the two results' points, the change of each wire's
largest and RMS distance to its contour, and whether every crossing's status is the same; prints
the calls that differ by more than 0.1 mm or in a status, and a summary.
"""
import argparse
import copy
import os
import pickle
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
CASES = ["duck", "teddy", "airplane", "car", "chair", "globe"]
TOLERANCE = 1e-4  # metres: the "within 0.1 mm"


def record(out, names):
    sys.path.insert(0, HERE)
    import bench_scenes  # noqa: E402
    from wiresculpt import native, pipeline  # noqa: E402

    scenes = os.path.join(ROOT, "out", "bench")
    bench_scenes.generate(scenes, names, run_check=False, say=lambda *_: None)
    import json
    with open(os.path.join(scenes, "manifest.json")) as f:
        cases = {c["name"]: c for c in json.load(f)["cases"]}
    module = native.require()
    calls = []
    real = module.optimize_target_shapes

    class Recording:
        def __getattr__(self, name):
            return getattr(module, name)

        @staticmethod
        def optimize_target_shapes(problems, progress=None, threads=2):
            problems = list(problems)  # the stage hands a generator over
            calls.extend({"case": current[0], "contour": copy.deepcopy(p["points"]), "closed": p["closed"],
                          "specs": copy.deepcopy(p["crossings"]), "options": copy.deepcopy(p["options"])}
                         for p in problems)
            return real(problems, progress, threads)

    current = [None]
    original = native.require
    native.require = lambda: Recording()
    try:
        for name in names:
            current[0] = name
            scene, _V, _F, _planes, sliced = bench_scenes.load_and_slice(os.path.join(scenes, cases[name]["scene"]))
            pipeline.solve(copy.deepcopy(sliced), scene.material, scene.settings, hook_patterns=1)
    finally:
        native.require = original
    with open(out, "wb") as f:
        pickle.dump(calls, f)
    print(f"{len(calls)} calls recorded into {out}")


def replay(calls_path, out, root, only, case=None):
    sys.path.insert(0, os.path.join(os.path.abspath(root), "addon"))
    from wiresculpt import native  # noqa: E402

    module = native.require()
    with open(calls_path, "rb") as f:
        calls = pickle.load(f)
    results = []
    for k, c in enumerate(calls):
        if (only is not None and k != only) or (case is not None and c["case"] != case):
            continue
        r = module.optimize_target_shape(c["contour"], c["closed"], c["specs"], c["options"], None)
        results.append({"case": c["case"], "index": k, "points": [tuple(map(float, p)) for p in r["points"]],
                        "max_distance": r["max_distance"], "rms_distance": r["rms_distance"],
                        "statuses": [s["status"] for s in r["crossings"]], "energy": r["energy"],
                        "iterations": r["iterations"], "nlopt_result": r["nlopt_result"]})
    if out:
        with open(out, "wb") as f:
            pickle.dump(results, f)
    print(f"{len(results)} calls replayed by {os.path.dirname(native.__file__)}")


def compare(a_path, b_path):
    import numpy as np

    with open(a_path, "rb") as f:
        a = pickle.load(f)
    with open(b_path, "rb") as f:
        b = pickle.load(f)
    if [r["index"] for r in a] != [r["index"] for r in b]:
        sys.exit("the two files replayed different calls")
    differ, worst = 0, 0.0
    for ra, rb in zip(a, b):
        pa, pb = np.asarray(ra["points"]), np.asarray(rb["points"])
        moved = float(np.max(np.linalg.norm(pa - pb, axis=1))) if pa.shape == pb.shape else float("inf")
        dd = max(abs(ra["max_distance"] - rb["max_distance"]), abs(ra["rms_distance"] - rb["rms_distance"]))
        worst = max(worst, moved)
        if moved > TOLERANCE or dd > TOLERANCE or ra["statuses"] != rb["statuses"]:
            differ += 1
            print(f"call {ra['index']} ({ra['case']}): points up to {moved * 1000:.4f} mm apart, distances "
                  f"{dd * 1000:.4f} mm apart, statuses {'same' if ra['statuses'] == rb['statuses'] else 'differ'}, "
                  f"energy {ra['energy']:.6e} vs {rb['energy']:.6e}")
    evals = (sum(r["iterations"] for r in a), sum(r["iterations"] for r in b))
    print(f"{len(a)} calls: {differ} differ by more than {TOLERANCE * 1000:.1f} mm or in a status; points at most "
          f"{worst * 1000:.6f} mm apart; evaluations {evals[0]} vs {evals[1]}")
    return differ


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("record")
    p.add_argument("out")
    p.add_argument("names", nargs="*")
    p = sub.add_parser("replay")
    p.add_argument("calls")
    p.add_argument("out", nargs="?")
    p.add_argument("--root", default=ROOT)
    p.add_argument("--only", type=int)
    p.add_argument("--case", help="replay only the calls of this case")
    p = sub.add_parser("compare")
    p.add_argument("a")
    p.add_argument("b")
    args = parser.parse_args(argv)
    if args.command == "record":
        record(args.out, [c for c in CASES if not args.names or any(n in c for n in args.names)])
    elif args.command == "replay":
        replay(args.calls, args.out, args.root, args.only, args.case)
    else:
        sys.exit(1 if compare(args.a, args.b) else 0)


if __name__ == "__main__":
    main()
