"""The live round trip of scripts/bench: a plane moved -> the verdict shown, in a Blender
with a window (the Live toggle's timer needs the event loop):

    xvfb-run -a blender --factory-startup --python-exit-code 1 --python scripts/bench_live.py -- \
        MANIFEST.json OUT.json [NAME...]

For each case of the manifest whose kind is "paper" or "example" (and whose name contains a NAME,
when given): the scene as the batch loads it (mesh scaled to "size", the planes as slicing
handles, the contours the scene file picks ticked), Live on, and once the first verdict is shown,
MOVES moves of the scene's first plane by STEP metres along its normal (back and forth). Each
move's round trip runs from the moment the plane's location is set to the moment the verdict is
shown: the overlay's first draw of the new preview when the verdict has wires, else the moment
the panel's line changed (live/state.observed().shown_at; the panel redraw is tagged then).
It includes Live's settle time and timer granularity, the re-slicing and the solve with the
layering's own hooks. Writes OUT.json: {"cases": [{name, round_trips [s], verdicts, ...}]}.
"""
import json
import os
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path[:0] = [os.path.join(ROOT, "addon"), HERE]

import bpy  # noqa: E402

import wiresculpt  # noqa: E402

MOVES = 5
STEP = 0.001  # m along the first plane's normal: small, the verdict should not change
SETTLE_LIMIT = 120.0  # s: a verdict not shown by then is recorded as an error for the case
POLL = 0.002  # s between checks while waiting for a verdict


def argv():
    return sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []


def load_case(manifest_dir, case):
    """The case's scene in Blender: mesh, handles, ticked contours; returns the first handle."""
    import numpy as np
    from mathutils import Matrix, Vector

    from bench_scenes import load_and_slice
    from wiresculpt.blend.mesh import import_mesh
    from wiresculpt_batch import add_handles, scaled_planes

    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    path = os.path.join(manifest_dir, case["scene"])
    scene_file, _V, _F, _planes, sliced = load_and_slice(path)  # the picks the batch makes
    Vb, _Fb, objects = import_mesh(scene_file.mesh)  # as the batch imports and scales it
    factor = 1.0
    if scene_file.size is not None:
        factor = scene_file.size / float(np.max(Vb.max(axis=0) - Vb.min(axis=0)))
    objects[0].matrix_world = Matrix.Scale(factor, 4) @ objects[0].matrix_world
    bpy.context.view_layer.update()
    scene = bpy.context.scene
    scene.wiresculpt.model = objects[0]
    add_handles(scene, scaled_planes(scene_file.planes, factor), sliced)
    handle = scene.objects[scene_file.planes[0].name]
    return handle, Vector(scene_file.planes[0].normal).normalized(), len(sliced["wires"])


def measure(manifest_dir, case):
    """A generator the timer steps: yields seconds to wait; fills and returns the case's record."""
    from wiresculpt.live import engine as live

    record = {"name": case["name"], "round_trips": [], "verdicts": []}
    handle, normal, wires = load_case(manifest_dir, case)
    record["wires_ticked"] = wires

    def shown():
        now = live.observed()
        return now.job is None and now.solved is not None and now.solved == live.snapshot(bpy.context.scene)

    bpy.context.scene.wiresculpt.live = True
    began = time.monotonic()
    while not shown():
        if time.monotonic() - began > SETTLE_LIMIT:
            record["error"] = f"no first verdict in {SETTLE_LIMIT:.0f} s"
            return record
        yield 0.05
    record["first_verdict"] = live.line()
    for k in range(MOVES):
        handle.location += (STEP if k % 2 == 0 else -STEP) * normal
        moved = time.monotonic()
        results = len(live.observed().results)
        while not (shown() and len(live.observed().results) > results):
            if time.monotonic() - moved > SETTLE_LIMIT:
                record["error"] = f"move {k + 1}: no verdict in {SETTLE_LIMIT:.0f} s"
                return record
            yield POLL
        done = live.observed().shown_at
        record.setdefault("verdict_set", []).append(done - moved)  # the panel's line changed
        record.setdefault("job_seconds", []).append(live.observed().job_seconds)  # slicing + solve on the worker
        if live.observed().preview:  # shown = drawn: wait for the overlay's first draw after the verdict
            while live.observed().drawn_at is None or live.observed().drawn_at < done:
                if time.monotonic() - moved > SETTLE_LIMIT:
                    record["error"] = f"move {k + 1}: the preview was not drawn"
                    return record
                yield POLL
            done = live.observed().drawn_at
        record["round_trips"].append(done - moved)
        record["verdicts"].append(live.line())
    bpy.context.scene.wiresculpt.live = False
    durations = live.observed().durations
    record["longest_tick"] = max(durations) if durations else None
    record["median"] = statistics.median(record["round_trips"])
    record["job_median"] = statistics.median(record["job_seconds"])
    return record


def main():
    args = argv()
    manifest_path, out_path, names = args[0], args[1], args[2:]
    manifest_dir = os.path.dirname(os.path.abspath(manifest_path))
    with open(manifest_path) as f:
        cases = [c for c in json.load(f)["cases"] if c["kind"] in ("paper", "example")
                 and (not names or any(n in c["name"] for n in names))]
    wiresculpt.register()
    records = []
    state = {"k": 0, "gen": None}

    def finish():
        from wiresculpt.core.files import write_atomic

        write_atomic(out_path, json.dumps({"cases": records}, indent=1) + "\n")
        for r in records:
            trips = ", ".join(f"{t:.3f}" for t in r["round_trips"])
            jobs = ", ".join(f"{t:.3f}" for t in r.get("job_seconds", []))
            print(f"bench live {r['name']}: {r.get('error') or r['first_verdict']}; round trips {trips} s "
                  f"(the live jobs: {jobs} s)", flush=True)
        bpy.ops.wm.quit_blender()

    def step():
        try:
            if state["gen"] is None:
                if state["k"] >= len(cases):
                    finish()
                    return None
                state["gen"] = measure(manifest_dir, cases[state["k"]])
            return next(state["gen"])
        except StopIteration as done:
            records.append(done.value)
        except Exception as exc:  # one case's failure is recorded, the others still run
            records.append({"name": cases[state["k"]]["name"], "round_trips": [], "error": f"{type(exc).__name__}: {exc}"})
            bpy.context.scene.wiresculpt.live = False
        state["gen"] = None
        state["k"] += 1
        return 0.2

    bpy.app.timers.register(step, first_interval=1.0)


main()
