"""Driven by test_fabrication_ops.py in a Blender with a window (under Xvfb): Send to Machine as
the panel runs it (INVOKE: worker thread, modal timer) to a GRBL emulator on a pseudo-terminal,
cancelled mid-program, then Resume (also modal) to the end on a new link. Prints one line
`MODAL {json}` with what it saw, then quits."""
import atexit
import math
import os
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [os.path.join(os.path.dirname(HERE), "addon"), HERE]

import bpy  # noqa: E402

import wiresculpt  # noqa: E402

wiresculpt.register()
from helpers import GrblEmulator, gcode_lines, step_start  # noqa: E402
from ui_steps import guarded, report, start_watchdog  # noqa: E402
from wiresculpt.blend import results as scene_results  # noqa: E402
from wiresculpt.fab import streaming  # noqa: E402

WIRE = "Ring/0"
MODES = ("G21", "G91", "G94")
seen = {}
links = {}
tmp = tempfile.mkdtemp(prefix="wiresculpt_modal_")
atexit.register(shutil.rmtree, tmp, True)  # no run leaves its export folder in /tmp


def ring(n=12, side=0.04):
    """A regular n-gon walked from the cut, closed (the cut at both ends): n bends of 360/n deg."""
    pts, x, y = [[0.0, 0.0]], 0.0, 0.0
    for k in range(n):
        x += side * math.cos(2 * math.pi * k / n)
        y += side * math.sin(2 * math.pi * k / n)
        pts.append([x, y])
    return pts


def setup():
    rest = ring()
    design = {"format": "wiresculpt-design", "version": 1, "units": "m",
              "material": {"name": "steel", "wire_diameter": 0.003, "bending_stiffness": 0.73,
                           "max_torque": 1.77, "friction": 0.32},
              "machine": {"min_segment": 0.015, "max_bend_deg": 120.0, "min_bend_deg": 1.0},
              "wires": [{"id": 0, "name": WIRE, "closed": True, "target": [p + [0.0] for p in rest[:-1]],
                         "cut": 0, "rest": rest, "length": 0.48}],
              "crossings": [], "stable": True, "reason": "", "stages": {}}
    scene_results.store_design(design)
    assert sorted(bpy.ops.wiresculpt.export_fabrication(directory=tmp)) == ["FINISHED"]
    seen["program"] = gcode_lines(os.path.join(tmp, "gcode", "00-Ring-0.gcode"))
    seen["lines"] = len(seen["program"])


def invoke(**kw):
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    with bpy.context.temp_override(window=win, area=area):
        return sorted(bpy.ops.wiresculpt.send_to_machine('INVOKE_DEFAULT', wire=WIRE, settle=0.05,
                                                         response_timeout=2.0, loaded=True, **kw))


def start_send():
    links["first"] = GrblEmulator(delay=0.15)
    seen["invoke"] = invoke(port=links["first"].port)
    seen["running"] = streaming.running()
    bpy.app.timers.register(guarded(seen, cancel_when_busy), first_interval=0.05)


def cancel_when_busy():
    first = links["first"]
    if len(first.received) < 5 or len(first.received) == len(first.acknowledged):
        return 0.01  # cancel while a line waits for its answer
    seen["in_flight_at_cancel"] = len(first.received) - len(first.acknowledged)
    seen["status"] = streaming.JOB.status() if streaming.JOB else ""
    seen["cancel_op"] = sorted(bpy.ops.wiresculpt.send_cancel())
    bpy.app.timers.register(guarded(seen, check_cancelled), first_interval=0.1)
    return None


def check_cancelled():
    if streaming.running():
        return 0.05
    first = links["first"]
    seen["acknowledged_at_cancel"] = len(first.acknowledged)
    seen["step_start_at_cancel"] = step_start(seen["program"], len(first.acknowledged))
    stopped = streaming.PENDING.get(WIRE)
    seen["pending_next_line"] = stopped.next_line if stopped else None
    seen["realtime"] = list(first.realtime)
    first.close()
    links["second"] = GrblEmulator()
    seen["resume_invoke"] = invoke(port=links["second"].port, resume=True)
    bpy.app.timers.register(guarded(seen, check_resumed), first_interval=0.1)
    return None


def check_resumed():
    if streaming.running():
        return 0.05
    first, second = links["first"], links["second"]
    second.close()
    program = seen.pop("program")
    modes = [line for line in program[:len(first.acknowledged)] if line in MODES]
    # the lines acknowledged before the cancel, then from the first line of the step in doubt
    start = step_start(program, len(first.acknowledged))
    seen["once"] = first.acknowledged + second.acknowledged[len(modes):] == program[:len(first.acknowledged)] + \
        program[start:]
    seen["pending_after"] = WIRE in streaming.PENDING
    seen["running_after"] = streaming.running()
    report(seen)
    return None


setup()
bpy.app.timers.register(guarded(seen, start_send), first_interval=1.0)
start_watchdog(seen)
