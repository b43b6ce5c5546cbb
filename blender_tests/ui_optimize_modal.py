"""Driven by test_optimize_modal.py in a Blender with a window (under Xvfb): Optimize as the
panel runs it (INVOKE: worker thread, modal timer), once to the end and once cancelled.
Prints one line `MODAL {json}` with what it saw, then quits."""
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [os.path.join(os.path.dirname(HERE), "addon"), HERE]

import bpy  # noqa: E402

import wiresculpt  # noqa: E402

wiresculpt.register()
from wiresculpt import overlay, scene_results  # noqa: E402
from wiresculpt.mesh_import import import_mesh  # noqa: E402
from wiresculpt.operators import optimize  # noqa: E402
from ui_steps import guarded, report, start_watchdog  # noqa: E402

seen = {}


def state():
    objects = {o.name: (o.type, tuple(round(x, 9) for x in o.location), o.hide_viewport) for o in bpy.data.objects}
    return json.dumps([objects, {t.name: t.as_string() for t in bpy.data.texts}], sort_keys=True)


def setup():
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    _V, _F, objs = import_mesh(os.path.join(os.path.dirname(HERE), "scripts", "examples", "globe", "globe.obj"))
    objs[0].scale = (0.125,) * 3
    bpy.context.view_layer.update()
    bpy.context.scene.wiresculpt.target = objs[0]
    for rotation in ((0, 0, 0), (0, math.pi / 2, 0), (math.pi / 2, 0, 0)):
        bpy.ops.wiresculpt.add_plane()
        bpy.context.view_layer.objects.active.rotation_euler = rotation
    bpy.context.view_layer.update()
    bpy.ops.wiresculpt.slice()


def invoke():
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    with bpy.context.temp_override(window=win, area=area):
        return sorted(bpy.ops.wiresculpt.optimize('INVOKE_DEFAULT'))


def start_cancelled():
    seen["before_cancel"] = state()
    seen["cancel_invoke"] = invoke()
    seen["cancel_running"] = optimize.running()
    seen["cancel_op"] = sorted(bpy.ops.wiresculpt.optimize_cancel())
    bpy.app.timers.register(guarded(seen, check_cancelled), first_interval=0.5)


def check_cancelled():
    if optimize.running():
        return 0.2
    seen["cancel_unchanged"] = state() == seen.pop("before_cancel")
    bpy.app.timers.register(guarded(seen, start_full), first_interval=0.1)
    return None


def start_full():
    win = bpy.context.window_manager.windows[0]
    with bpy.context.temp_override(window=win, area=next(a for a in win.screen.areas if a.type == 'VIEW_3D')):
        bpy.ops.ed.undo_push(message="scene set up by the test")  # the set-up ran before the undo stack existed
    seen["before_full"] = state()
    seen["invoke"] = invoke()
    seen["running"] = optimize.running()
    seen["status_while_running"] = optimize.JOB.status() if optimize.JOB else ""
    bpy.app.timers.register(guarded(seen, check_full), first_interval=0.5)


def check_full():
    if optimize.running():
        return 0.2
    design = scene_results.stored_design()
    seen["stable"] = bool(design and design["stable"])
    seen["shader"] = overlay.uniform_colour_shader() is not None  # 3.4 and 4.x names
    seen["wires"] = len([o for o in bpy.context.scene.objects if scene_results.WIRE_KEY in o])
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    with bpy.context.temp_override(window=win, area=area):
        bpy.ops.ed.undo()  # one step takes the whole result away
    after = state()
    seen["undo_restores"] = after == seen["before_full"]
    if not seen["undo_restores"]:
        seen["after_undo"] = after
    else:
        seen.pop("before_full")
    report(seen)
    return None


setup()
bpy.app.timers.register(guarded(seen, start_cancelled), first_interval=1.0)
start_watchdog(seen)
