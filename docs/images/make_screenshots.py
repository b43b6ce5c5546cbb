"""The user guide's screenshots of the Wire tab (docs/images/panel*.png):

    xvfb-run -a -s "-screen 0 1600x1000x24" blender --factory-startup --enable-event-simulate \
        --python docs/images/make_screenshots.py

Sets up the globe example (three handles through the centre, normals z, x, y), slices, optimizes,
opens the sidebar's Wire tab (Blender 3.4 has no API for the tab: a simulated click), saves
screenshots after a timer and quits.

With SHOTS=fabrication (and a taller screen, "-screen 0 1600x2050x24", so the Fabrication panel
fits below the others) it makes docs/images/panel-fabrication.png instead: a spring-back fit 5 % softer than the
default profile is loaded (as Calibration > Load Capture would store it) and Export runs into a
temporary folder, so the machine preview's violet ghosts show how far an uncompensated bender
would miss.
"""
import math
import os
import sys
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, 'addon'))
import bpy
import wiresculpt
wiresculpt.register()
from wiresculpt.blend.mesh import import_mesh
OUT = os.environ.get("SHOT_DIR", HERE)
for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
_V, _F, objs = import_mesh(os.path.join(ROOT, 'scripts', 'examples', 'globe', 'globe.obj'))
target = objs[0]
target.scale = (0.125,) * 3
bpy.context.view_layer.update()
ws = bpy.context.scene.wiresculpt
ws.target = target
for name, rot in (("Equator", (0, 0, 0)), ("Meridian0", (0, math.pi / 2, 0)), ("Meridian90", (math.pi / 2, 0, 0))):
    bpy.ops.wiresculpt.add_plane()
    h = bpy.context.view_layer.objects.active
    h.name = name
    h.rotation_euler = rot
bpy.context.view_layer.update()
bpy.ops.wiresculpt.slice()
bpy.ops.wiresculpt.optimize()
FABRICATION = os.environ.get("SHOTS") == "fabrication"
if FABRICATION:
    import tempfile
    from wiresculpt.blend import calibration as calibration_store
    calibration_store.store(bpy.context.scene, "springback", {
        "springback_a": 0.95, "springback_b_deg": 0.0, "rms_deg": 0.1, "max_residual_deg": 0.2, "samples": 8})
    assert bpy.ops.wiresculpt.export_fabrication(directory=tempfile.mkdtemp(prefix="wiresculpt_shot_")) == {'FINISHED'}
win = bpy.context.window_manager.windows[0]
screen = win.screen
area = max((a for a in screen.areas if a.type == 'VIEW_3D'), key=lambda a: a.width * a.height)
space = area.spaces.active
space.show_region_ui = True
space.shading.color_type = 'MATERIAL'
space.overlay.show_floor = False
target.hide_set(True)
for o in bpy.context.scene.objects:
    if o.get("wiresculpt_handle") or o.get("wiresculpt_contour"):
        o.hide_set(True)
region = next(r for r in area.regions if r.type == 'WINDOW')
ui = next(r for r in area.regions if r.type == 'UI')
bpy.context.preferences.view.show_splash = False
for o in bpy.context.scene.objects:
    o.select_set("wiresculpt_wire" in o or "wiresculpt_preview" in o)
with bpy.context.temp_override(window=win, area=area, region=region):
    bpy.ops.view3d.view_axis(type='FRONT')
    bpy.ops.view3d.view_orbit(angle=0.5, type='ORBITRIGHT')
    bpy.ops.view3d.view_orbit(angle=0.35, type='ORBITUP')
    bpy.ops.view3d.view_selected()
    if FABRICATION:
        bpy.ops.view3d.zoom(delta=-1)  # room for the ghosts beside the sidebar
for o in bpy.context.scene.objects:
    o.select_set(False)
shots = [("panel-fabrication.png", 0)] if FABRICATION else [("panel.png", 0), ("panel-step1.png", 1)]

def close_splash():
    x, y = win.width // 2, 40
    win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=x, y=y)
    win.event_simulate(type='ESC', value='PRESS', x=x, y=y)
    win.event_simulate(type='ESC', value='RELEASE', x=x, y=y)
    return None


def click_tab():
    # Blender 3.4 has no API for the sidebar's active tab: click "Wire" (the 4th tab)
    x, y = ui.x + ui.width - 10, ui.y + ui.height - int(os.environ.get("TAB_OFFSET", "157"))
    win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=x, y=y)
    win.event_simulate(type='LEFTMOUSE', value='PRESS', x=x, y=y)
    win.event_simulate(type='LEFTMOUSE', value='RELEASE', x=x, y=y)
    win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=x - 600, y=y)
    return None


def shoot():
    name, step = shots.pop(0)
    ws.assembly_step = step
    def take():
        with bpy.context.temp_override(window=win, area=area):
            bpy.ops.screen.screenshot(filepath=os.path.join(OUT, name), check_existing=False)
        print("SHOT", name)
        if shots:
            return shoot()
        bpy.ops.wm.quit_blender()
        return None
    bpy.app.timers.register(take, first_interval=1.5)
    return None

bpy.app.timers.register(close_splash, first_interval=0.7)
bpy.app.timers.register(click_tab, first_interval=1.0)
bpy.app.timers.register(shoot, first_interval=3.0)
