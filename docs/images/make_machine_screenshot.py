"""The user guide's screenshot of the Machine panel (docs/images/panel-machine.png):

    xvfb-run -a -s "-screen 0 1600x1400x24" blender --factory-startup --enable-event-simulate \
        --python docs/images/make_machine_screenshot.py

Opens the Machine panel (the other sub-panels shut), connects it to the suite's GRBL emulator on a
pseudo-terminal (blender_tests/helpers.GrblEmulator), jogs the feed 12.5 mm and the head 30° right,
sends the console line `$G`, then takes the screenshot cropped to the sidebar. Then
docs/images/panel-stop.png: a two-wire design of 12-gons is stored, its first wire sent to an
emulator that pulls the cable when line 22 arrives (in step 5), and the Fabrication panel shows the
stop's box with its Resume button.
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path[:0] = [os.path.join(ROOT, "addon"), os.path.join(ROOT, "blender_tests"), HERE]
import bpy  # noqa: E402

from wiresculpt.ui import calibration as calibration_ui  # noqa: E402
from wiresculpt.ui import machine as machine_ui  # noqa: E402

machine_ui.VIEW3D_PT_wiresculpt_machine.bl_options = set()
calibration_ui.VIEW3D_PT_wiresculpt_calibration.bl_options = {'DEFAULT_CLOSED'}
import wiresculpt  # noqa: E402

wiresculpt.register()
from helpers import GrblEmulator  # noqa: E402
from sidebar_events import click_tab, close_splash  # noqa: E402
from wiresculpt.fab import grbl  # noqa: E402

OUT = os.environ.get("SHOT_DIR", HERE)
emulator = GrblEmulator(move_time=0.2)
ws = bpy.context.scene.wiresculpt
ws.fab_port = emulator.port
win = bpy.context.window_manager.windows[0]
area = max((a for a in win.screen.areas if a.type == 'VIEW_3D'), key=lambda a: a.width * a.height)
area.spaces.active.show_region_ui = True
ui = next(r for r in area.regions if r.type == 'UI')
bpy.context.preferences.view.show_splash = False


def drive():
    with bpy.context.temp_override(window=win, area=area):
        assert bpy.ops.wiresculpt.machine_connect(settle=0.0) == {'FINISHED'}
        ws.machine_jog_feed, ws.machine_jog_bend = 12.5, 30.0
        bpy.ops.wiresculpt.machine_jog(axis=grbl.FEED, direction=1.0)
        bpy.ops.wiresculpt.machine_jog(axis=grbl.BEND, direction=-1.0)
        ws.machine_console = "$G"
        bpy.ops.wiresculpt.machine_console()


def crop(path):
    import numpy as np
    image = bpy.data.images.load(path)
    w, h = image.size
    pixels = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    part = np.ascontiguousarray(pixels.reshape(h, w, 4)[ui.y:h, ui.x:area.x + area.width])
    out = bpy.data.images.new("crop", part.shape[1], part.shape[0])
    out.pixels.foreach_set(part.ravel())
    out.filepath_raw, out.file_format = path, 'PNG'
    out.save()


def shot(name):
    path = os.path.join(OUT, name)
    with bpy.context.temp_override(window=win, area=area):
        bpy.ops.screen.screenshot(filepath=path, check_existing=False)
    crop(path)
    print("SHOT", name, flush=True)


def take():
    session = grbl.SESSION
    if session.busy() or (session.status or {}).get("state") != "Idle" or not session.log[-1].done:
        return 0.5  # the panel's timer has not read every answer yet (slow under load): later
    if not getattr(take, "settled", False):
        take.settled = True  # one more redraw of the panel with the last answers
        return 0.5
    shot("panel-machine.png")
    grbl.disconnect()
    emulator.close()
    from test_machine_panel import ring_design
    from wiresculpt.blend import results as scene_results
    scene_results.store_design(ring_design())
    ws.fab_wire = "Ring/0"
    dropping = GrblEmulator(drop_on=22)
    try:
        bpy.ops.wiresculpt.send_to_machine(wire="Ring/0", port=dropping.port, loaded=True, settle=0.05,
                                           response_timeout=2.0)
    except RuntimeError:
        pass  # the stop is reported as an error: the panel shows it
    dropping.close()
    bpy.app.timers.register(take_stop, first_interval=1.0)
    return None


def take_stop():
    shot("panel-stop.png")
    bpy.ops.wm.quit_blender()


bpy.app.timers.register(lambda: close_splash(win), first_interval=0.7)
bpy.app.timers.register(lambda: click_tab(win, ui), first_interval=1.0)
bpy.app.timers.register(lambda: drive(), first_interval=1.5)
bpy.app.timers.register(take, first_interval=3.5)
