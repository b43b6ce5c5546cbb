"""Driven by test_optimize_modal.py in a Blender with a window (under Xvfb): Optimize as the
panel runs it (INVOKE: worker thread, modal timer): cancelled at once, cancelled while the worker
is inside the native layering and inside the native forces, once to the end (and undone), and
finally with the worker stuck in a native step while Blender removes the modal (a new file is
loaded). Prints one line `MODAL {json}` with what it saw, then quits."""
import json
import os
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [os.path.join(os.path.dirname(HERE), "addon"), HERE]

import bpy  # noqa: E402

import wiresculpt  # noqa: E402

wiresculpt.register()
from wiresculpt.blend import results as scene_results  # noqa: E402
from wiresculpt.ui import overlay  # noqa: E402
from wiresculpt.ui import results as results_ui  # noqa: E402
from wiresculpt.operators import optimize  # noqa: E402
from ui_steps import globe_scene as setup, guarded, report, start_watchdog  # noqa: E402
from wiresculpt.stages import forces as forces_stage  # noqa: E402
from wiresculpt.stages import layering as layering_stage  # noqa: E402

seen = {}


class Hold:
    """Wraps a stage's run (as the pipeline calls it) so that the worker waits inside the native
    call, in its progress callback at the first report of `native_stage`, until the cancel
    arrives; with `ignore` it first sleeps that long regardless (a long native step between two
    polls). Records the native stage whose poll saw the cancel."""

    def __init__(self, module, native_stage, ignore=0.0):
        self.module, self.native_stage, self.ignore = module, native_stage, ignore
        self.original = module.run
        self.inside = threading.Event()
        self.cancelled_in = None
        module.run = self.run

    def run(self, design, material, settings, native_progress=None, **options):
        def progress(stage, fraction):
            if stage == self.native_stage and not self.inside.is_set():
                self.inside.set()
                time.sleep(self.ignore)
                deadline = time.monotonic() + 30
                while native_progress(stage, fraction) and time.monotonic() < deadline:
                    time.sleep(0.01)
            go_on = native_progress(stage, fraction)
            if not go_on and self.cancelled_in is None:
                self.cancelled_in = stage
            return go_on
        return self.original(design, material, settings, progress, **options)

    def restore(self):
        self.module.run = self.original


def results_in_scene():
    return len([o for o in bpy.context.scene.objects if scene_results.WIRE_KEY in o])


def state():
    objects = {o.name: (o.type, tuple(round(x, 9) for x in o.location), o.hide_viewport) for o in bpy.data.objects}
    return json.dumps([objects, {t.name: t.as_string() for t in bpy.data.texts}], sort_keys=True)


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
    bpy.app.timers.register(guarded(seen, lambda: hold_and_cancel("layering", layering_stage, after_layering)),
                            first_interval=0.1)
    return None


def hold_and_cancel(name, module, then):
    """Optimize; when the worker is inside the native `name` stage, Cancel; once it has ended,
    the scene must be as before."""
    hold = Hold(module, name)
    before = state()
    seen[name + "_invoke"] = invoke()

    def wait_inside():
        if not hold.inside.is_set():
            if not optimize.running():
                raise RuntimeError(f"the Optimize ended before reaching the native {name} stage")
            return 0.05
        start = time.monotonic()
        seen[name + "_cancel_op"] = sorted(bpy.ops.wiresculpt.optimize_cancel())
        seen[name + "_cancel_seconds"] = time.monotonic() - start
        bpy.app.timers.register(guarded(seen, wait_ended), first_interval=0.1)
        return None

    def wait_ended():
        if optimize.running():
            return 0.1
        hold.restore()
        seen[name + "_cancelled_in"] = hold.cancelled_in
        seen[name + "_unchanged"] = state() == before
        bpy.app.timers.register(guarded(seen, then), first_interval=0.1)
        return None

    bpy.app.timers.register(guarded(seen, wait_inside), first_interval=0.05)


def after_layering():
    hold_and_cancel("forces", forces_stage, start_full)


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
    # the modal path records what it solved with: the Stability box reads the result as current
    seen["inputs_recorded"] = scene_results.stored_inputs() is not None
    with bpy.context.temp_override(window=win, area=area):
        seen["report_changes"] = results_ui.report_changes(bpy.context)
        bpy.ops.ed.undo()  # one step takes the whole result away
    after = state()
    seen["undo_restores"] = after == seen["before_full"]
    if not seen["undo_restores"]:
        seen["after_undo"] = after
    else:
        seen.pop("before_full")
    bpy.app.timers.register(guarded(seen, start_stuck), first_interval=0.1)
    return None


STUCK_SECONDS = 4.0


def start_stuck():
    """The worker sleeps STUCK_SECONDS inside the native forces (no poll meanwhile) when a new
    file is loaded, which makes Blender cancel the modal: that must not wait for the worker."""
    hold = Hold(forces_stage, "forces", ignore=STUCK_SECONDS)
    seen["stuck_invoke"] = invoke()
    ticks = [0]

    def wait_inside():
        if not hold.inside.is_set():
            if not optimize.running():
                raise RuntimeError("the Optimize ended before reaching the native forces stage")
            return 0.05
        start = time.monotonic()
        bpy.ops.wm.read_homefile()
        seen["stuck_load_seconds"] = time.monotonic() - start
        seen["stuck_running_after_load"] = optimize.running()
        seen["stuck_status"] = optimize.JOB.status() if optimize.JOB else ""
        bpy.app.timers.register(guarded(seen, wait_ended), first_interval=0.1)
        return None

    def wait_ended():
        if optimize.running():
            ticks[0] += 1  # the UI keeps running while the worker is stuck
            return 0.1
        hold.restore()
        seen["stuck_ticks"] = ticks[0]
        seen["stuck_cancelled_in"] = hold.cancelled_in
        seen["stuck_results_in_new_scene"] = results_in_scene()
        report(seen)
        return None

    bpy.app.timers.register(guarded(seen, wait_inside), first_interval=0.05)
    return None


setup()
bpy.app.timers.register(guarded(seen, start_cancelled), first_interval=1.0)
start_watchdog(seen, 150.0)
