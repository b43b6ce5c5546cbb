"""Pre-stress, closure gaps and out-of-plane figures (docs/method-forces.md §10-12): each
scene solved twice in-process, without the pre-stress and the hook choice ("today": torque fraction
1, the layering's first hook pattern) and now (load factor 3, hooks chosen by their forces), one
markdown table on stdout:

    /usr/bin/python3.11 scripts/bench_forces.py SCENE.json [SCENE.json ...]

Per run: the torque fraction used; the largest closure gap as % of its wire's length (and in mm);
the paper's out-of-plane measure (|f·n| over the largest contact force, mean and max over the
hooked crossings and their wires; target <= 6.3%); the largest out-of-plane deflection (mm, the
3D check); the load capacity reached (the weakest direction's multiple of the weight).
"""
import copy
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import bench_scenes  # noqa: E402  (puts addon/ on sys.path)

AXES = ("+x", "-x", "+y", "-y", "+z", "-z")


def figures(design, seconds):
    if not design.get("stable") or "forces" in design.get("pending_stages", []):
        return "not stable" if not design.get("stable") else "no forces"
    gaps = [(w["closure_gap"] / w["length"], w["closure_gap"]) for w in design["wires"] if w.get("closed")]
    share, gap = max(gaps) if gaps else (0.0, 0.0)
    oop = design["out_of_plane"]
    bends = [w["out_of_plane_deflection"] for w in design["wires"] if "out_of_plane_deflection" in w]
    held = [design["load_capacity"][a] for a in AXES if design["load_capacity"][a] is not None]
    return (f"{design['torque_fraction']:.3f} | {100 * share:.1f}% ({1000 * gap:.0f} mm) | "
            f"{100 * oop['mean_to_max_force']:.1f}% / {100 * oop['max_to_max_force']:.1f}% | "
            f"{1000 * max(bends, default=0.0):.2f} mm | {min(held, default=float('inf')):.2f}x | {seconds:.1f} s")


def main(paths):
    from wiresculpt import pipeline

    print("| scene | run | torque fraction | largest closure gap (% of length) | out of plane, paper measure "
          "mean / max | max out-of-plane deflection | load capacity reached (weakest) | solve |")
    print("|---|---|---|---|---|---|---|---|")
    for path in paths:
        scene, _V, _F, _planes, sliced = bench_scenes.load_and_slice(path)
        name = os.path.splitext(os.path.basename(path))[0]
        if name == "scene":  # scripts/examples/NAME/scene.json
            name = os.path.basename(os.path.dirname(os.path.abspath(path)))
        # today: the plastic limit, the layering's first pattern, the force LP's vertex
        today = {"torque_fraction": 1.0, "least_out_of_plane": False}
        for label, overrides, patterns in (("today", today, 1), ("load factor 3", {}, None)):
            settings = {**scene.settings, **overrides}
            saved = pipeline.HOOK_PATTERNS
            if patterns is not None:
                pipeline.HOOK_PATTERNS = patterns
            try:
                start = time.monotonic()
                design = pipeline.solve(copy.deepcopy(sliced), scene.material, settings)
                row = figures(design, time.monotonic() - start)
            except Exception as exc:  # a failing scene is a row, not the end of the bench
                row = f"error: {exc}"
            finally:
                pipeline.HOOK_PATTERNS = saved
            print(f"| {name} | {label} | {row} |", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
