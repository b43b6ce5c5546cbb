"""Driven by test_plane_assistant_modal.py in a Blender with a window (under Xvfb): Find Stable
Planes as the panel runs it (INVOKE: worker thread, modal timer) on the hinged globe
(helpers.HINGE), cancelled mid-search, then to the end, then a candidate previewed (no
undo step, drawn), then Apply and one Undo. Prints
one line `MODAL {json}` with what it saw, then quits."""
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [os.path.join(os.path.dirname(HERE), "addon"), HERE]

import bpy  # noqa: E402

import wiresculpt  # noqa: E402

wiresculpt.register()
from wiresculpt.blend.mesh import import_mesh  # noqa: E402
from wiresculpt import plane_search  # noqa: E402
from wiresculpt.operators import plane_search as ops  # noqa: E402
from helpers import GLOBE_OBJ, GLOBE_RADIUS as R, HINGE  # noqa: E402
from ui_steps import Held, guarded, report, start_watchdog  # noqa: E402

seen = {}
HELD = []  # the Held search of the cancel step, while it runs


def state():
    objects = {o.name: (o.type, tuple(round(x, 9) for x in o.matrix_world.col[3]),
                        tuple(round(x, 9) for x in o.matrix_world.col[2]), o.hide_viewport) for o in bpy.data.objects}
    ticks = [(i.plane, i.index, i.use) for i in bpy.context.scene.wiresculpt.contours]
    return json.dumps([objects, {t.name: t.as_string() for t in bpy.data.texts}, ticks], sort_keys=True)


def setup():
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    _V, _F, objs = import_mesh(GLOBE_OBJ)
    objs[0].scale = (R,) * 3
    bpy.context.view_layer.update()
    bpy.context.scene.wiresculpt.model = objs[0]
    for rotation, location in HINGE:
        bpy.ops.wiresculpt.add_plane()
        handle = bpy.context.view_layer.objects.active
        handle.rotation_euler, handle.location = rotation, location
    bpy.context.view_layer.update()
    bpy.ops.wiresculpt.slice()


def override():
    win = bpy.context.window_manager.windows[0]
    return bpy.context.temp_override(window=win, area=next(a for a in win.screen.areas if a.type == 'VIEW_3D'))


def invoke():
    with override():
        return sorted(bpy.ops.wiresculpt.find_planes('INVOKE_DEFAULT'))


# The cancelled search waits (polling its cancel) up to this long before it searches, so the cancel
# surely lands mid-search: the hinged globe's whole search takes under a second, less than a few
# software-OpenGL redraws before the cancel's timer runs.
HOLD_SECONDS = 30.0


def start_cancelled():
    seen["before_cancel"] = state()
    HELD.append(Held(plane_search, "nearby", HOLD_SECONDS))
    seen["cancel_invoke"] = invoke()
    seen["cancel_running"] = ops.running()
    seen["status_while_running"] = ops.JOB.status() if ops.JOB else ""
    bpy.app.timers.register(guarded(seen, cancel_mid_search), first_interval=0.1)


def cancel_mid_search():
    seen["cancel_still_running"] = ops.running()  # held until the cancel: still at work
    seen["cancel_op"] = sorted(bpy.ops.wiresculpt.find_planes_cancel())
    bpy.app.timers.register(guarded(seen, check_cancelled), first_interval=0.2)


def check_cancelled():
    if ops.running():
        return 0.2
    HELD.pop().restore()
    seen["cancel_unchanged"] = state() == seen.pop("before_cancel")
    seen["cancel_no_candidates"] = ops.RESULT is None
    bpy.app.timers.register(guarded(seen, start_full), first_interval=0.1)
    return None


def start_full():
    seen["before_full"] = state()
    seen["invoke"] = invoke()
    bpy.app.timers.register(guarded(seen, check_full), first_interval=0.5)


def check_full():
    if ops.running():
        return 0.2
    seen["candidates"] = len(ops.RESULT["candidates"]) if ops.RESULT else 0
    seen["search_unchanged"] = state() == seen["before_full"]
    # A marker step the preview must not hide: the model moved 1 m and pushed as an undo step.
    # If clicking Preview pushed a step, the Undo below would undo that step and leave the model
    # moved; with no step, it undoes the move.
    model = bpy.context.scene.wiresculpt.model
    model.location.x += 1.0
    with override():
        bpy.ops.ed.undo_push(message="marker: model moved")
        marked = state()
        # undo=True: as a click on the panel's button runs it (an operator with UNDO pushes a step)
        seen["preview"] = sorted(bpy.ops.wiresculpt.preview_planes('INVOKE_DEFAULT', True, index=0))
    seen["preview_index"] = ops.PREVIEW["index"] if ops.PREVIEW else None
    seen["preview_wires"] = len(ops.PREVIEW["wires"]) if ops.PREVIEW else 0
    seen["design_wires"] = len(ops.RESULT["candidates"][0]["design"]["wires"])
    seen["drawn_before"] = ops.DRAWN[0]
    seen["preview_changes_nothing"] = state() == marked
    seen["moved_state"] = marked
    bpy.app.timers.register(guarded(seen, check_preview_drawn), first_interval=0.5)
    return None


def check_preview_drawn():
    waits = seen.get("draw_waits", 0)
    if ops.DRAWN[0] == seen["drawn_before"] and waits < 50:  # no redraw yet (a loaded machine): look again
        seen["draw_waits"] = waits + 1
        return 0.1
    seen.pop("draw_waits", None)
    seen["drawn_after"] = ops.DRAWN[0]  # the viewport redrew with the preview since the click
    seen["preview_no_data"] = state() == seen.pop("moved_state")
    with override():
        bpy.ops.ed.undo()
    model = bpy.context.scene.wiresculpt.model
    seen["undo_took_the_marker"] = abs(model.location.x) < 1e-9 and state() == seen["before_full"]
    seen["preview_kept_by_undo"] = ops.PREVIEW is not None
    with override():
        bpy.ops.ed.undo_push(message="before Apply")
        seen["apply"] = sorted(bpy.ops.wiresculpt.apply_planes('EXEC_DEFAULT', True, index=0))
    seen["apply_clears_preview"] = ops.PREVIEW is None
    seen["apply_changed"] = state() != seen["before_full"]
    with override():
        bpy.ops.ed.undo()  # one step takes the applied planes and design away
    seen["undo_restores"] = state() == seen.pop("before_full")
    report(seen)
    return None


def begin():
    setup()
    with override():
        bpy.ops.ed.undo_push(message="scene set up by the test")
    start_cancelled()


start_watchdog(seen, seconds=120.0)
bpy.app.timers.register(guarded(seen, begin), first_interval=0.5)
