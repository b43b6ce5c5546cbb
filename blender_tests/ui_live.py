"""Driven by test_live.py in a Blender with a window (under Xvfb): the globe with Live on; a
timer moves slicing plane "Slice A" in steps (through the centre, off the mesh, back near the
centre) and records the live verdict once each step has settled, then moves it twice within a
tick while a solve runs (latest position wins), turns Live off and loads a new file (the timer
stops). Every tick of the live timer records its duration (live/state.observed().durations).
Prints one line `MODAL {json}` with what it saw, then quits."""
import json  # noqa: F401
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [os.path.join(os.path.dirname(HERE), "addon"), HERE]

import bpy  # noqa: E402

import wiresculpt  # noqa: E402

wiresculpt.register()
from wiresculpt import pipeline  # noqa: E402
from wiresculpt.live import engine as live  # noqa: E402
from ui_steps import Held, globe_scene as setup, guarded, report, start_watchdog  # noqa: E402

seen = {"verdicts": [], "durations": []}
# plane A's z (the globe's radius is 0.125): through the mesh (stable), near its top (a small
# contour whose kink cannot be opened within the machine's limits: not stable), above it (no
# contour: cannot solve), through it again (stable)
STEPS = [0.0, 0.12, 0.3, 0.02]
SETTLE_SECONDS = 40.0


def plane():
    return bpy.context.scene.objects["Slice A"]


def settled():
    """The verdict of the current position is shown (no job, the solved snapshot is the scene's)."""
    now = live.observed()
    return now.job is None and now.solved is not None and now.solved == live.snapshot(bpy.context.scene)


def data_state():
    """What a live update must not write: the data-blocks (every live update would be an undo step)."""
    return sorted(f"{kind}:{block.name}" for kind in ("objects", "curves", "texts", "materials", "meshes")
                  for block in getattr(bpy.data, kind))


def start():
    seen["data_before"] = data_state()
    bpy.context.scene.wiresculpt.live = True
    seen["timer_on"] = bpy.app.timers.is_registered(live.tick)
    step(0)
    return None


def step(k):
    plane().location.z = STEPS[k]
    began = time.monotonic()

    def wait():
        if not settled():
            if time.monotonic() - began > SETTLE_SECONDS:
                raise RuntimeError(f"step {k} did not settle: {live.observed().verdict!r}")
            return 0.05
        seen["verdicts"].append({"z": STEPS[k], "line": live.line(), "seconds": time.monotonic() - began,
                                 "preview_wires": len(live.observed().preview), "drawn": live.observed().drawn})
        if k + 1 < len(STEPS):
            step(k + 1)
        else:
            bpy.app.timers.register(guarded(seen, latest_wins), first_interval=0.05)
        return None

    bpy.app.timers.register(guarded(seen, wait), first_interval=0.05)


# pipeline.solve waits (polling its cancel) up to this long first, so that the second move surely
# lands while the first position's job runs (the globe solves within a tick).
HOLD_SECONDS = 3.0


def latest_wins():
    """Two moves: the second lands while the first's solve runs; only the last one is shown."""
    slow = Held(pipeline, "solve", HOLD_SECONDS)
    shown = len(live.observed().results)
    plane().location.z = 0.04
    began = time.monotonic()
    state = {"moved": False}

    def wait():
        if not state["moved"]:
            if live.observed().job is None:
                if time.monotonic() - began > SETTLE_SECONDS:
                    raise RuntimeError("no live job started")
                return 0.01
            state["first_job"] = live.observed().job
            plane().location.z = 0.3  # off the mesh again, while the job of 0.04 runs
            state["moved"] = True
            return 0.05
        if not settled():
            if time.monotonic() - began > SETTLE_SECONDS:
                raise RuntimeError(f"latest position did not settle: {live.observed().verdict!r}")
            return 0.05
        slow.restore()
        first = state["first_job"]
        first.thread.join(5.0)
        seen["first_job_cancelled"] = first.cancel_event.is_set() and first.cancelled
        seen["latest_results"] = live.observed().results[shown:]  # the first position's verdict never shown
        seen["latest_line"] = live.line()
        seen["latest_z_solved"] = dict(live.observed().solved[2])["Slice A"][11]  # matrix row 2, column 3
        bpy.app.timers.register(guarded(seen, turn_off), first_interval=0.05)
        return None

    bpy.app.timers.register(guarded(seen, wait), first_interval=0.01)
    return None


def turn_off():
    seen["results"] = list(live.observed().results)
    seen["durations"] = list(live.observed().durations)
    seen["data_unchanged"] = data_state() == seen.pop("data_before")
    bpy.context.scene.wiresculpt.live = False
    seen["off_timer"] = bpy.app.timers.is_registered(live.tick)
    seen["off_line"] = live.line()
    seen["off_preview"] = len(live.observed().preview)
    bpy.context.scene.wiresculpt.live = True  # on again, then a file is loaded
    plane().location.z = 0.05
    bpy.app.timers.register(guarded(seen, load), first_interval=0.25)
    return None


def load():
    seen["before_load_timer"] = bpy.app.timers.is_registered(live.tick)
    job = live.observed().job
    bpy.ops.wm.read_homefile()
    seen["load_timer"] = bpy.app.timers.is_registered(live.tick)
    seen["load_job_cancelled"] = job is None or job.cancel_event.is_set()
    seen["load_line"] = live.line()
    report(seen)
    return None


setup()
bpy.app.timers.register(guarded(seen, start), first_interval=1.0)
start_watchdog(seen, 200.0)
