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

With SHOTS=planes (screen "-screen 0 1600x2050x24") it makes the plane assistant's loop,
docs/images/panel-planes-1-not-stable.png, -2-candidates.png, -2b-preview.png and -3-applied.png, each cropped to the
sidebar and a strip of the viewport: the globe with five slicing planes of which "Slice E"
(x = 0.8 R) crosses only the plane y = 0, on one line (the hinged scene of
blender_tests/test_plane_assistant.py), optimized (not stable); Find Stable Planes (run inline);
Preview of candidate 1 (its wires and moved plane drawn over the scene, which is unchanged);
Apply candidate 1 (the moved plane selected, the stable verdict in the panel).
"""
import math
import os
import sys
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, 'addon'))
import bpy
import wiresculpt
MODE = os.environ.get("SHOTS", "")
FABRICATION = MODE == "fabrication"
PLANES = MODE == "planes"
if PLANES:  # the Plane Assistant open, the long Result and Fabrication panels shut
    from wiresculpt.ui import fabrication as fabrication_ui, plane_search as planes_ui, results as results_ui
    planes_ui.VIEW3D_PT_wiresculpt_planes.bl_options = set()
    results_ui.VIEW3D_PT_wiresculpt_display.bl_options = {'DEFAULT_CLOSED'}
    fabrication_ui.VIEW3D_PT_wiresculpt_fabrication.bl_options = {'DEFAULT_CLOSED'}
wiresculpt.register()
from wiresculpt.blend.mesh import import_mesh
OUT = os.environ.get("SHOT_DIR", HERE)
for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
_V, _F, objs = import_mesh(os.path.join(ROOT, 'scripts', 'examples', 'globe', 'globe.obj'))
target = objs[0]
R = 0.125
target.scale = (R,) * 3
bpy.context.view_layer.update()
ws = bpy.context.scene.wiresculpt
ws.model = target
if PLANES:  # Slice A/B at z = +-0.7 R, C at x = -0.3 R, D at y = 0, E at x = 0.8 R (the hinge)
    PLANE_SET = ((None, (0, 0, 0), (0, 0, 0.7 * R)), (None, (0, 0, 0), (0, 0, -0.7 * R)),
                 (None, (0, math.pi / 2, 0), (-0.3 * R, 0, 0)), (None, (math.pi / 2, 0, 0), (0, 0, 0)),
                 (None, (0, math.pi / 2, 0), (0.8 * R, 0, 0)))
else:
    PLANE_SET = (("Equator", (0, 0, 0), (0, 0, 0)), ("Meridian0", (0, math.pi / 2, 0), (0, 0, 0)),
                 ("Meridian90", (math.pi / 2, 0, 0), (0, 0, 0)))
for name, rot, loc in PLANE_SET:
    bpy.ops.wiresculpt.add_plane()
    h = bpy.context.view_layer.objects.active
    if name:
        h.name = name
    h.rotation_euler, h.location = rot, loc
bpy.context.view_layer.update()
bpy.ops.wiresculpt.slice()
bpy.ops.wiresculpt.optimize()
if PLANES:
    from wiresculpt.blend import results as scene_results
    assert not scene_results.stored_design()["stable"], "the hinged scene is stable: no loop to show"
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
    # the planes shots show the slicing planes (the one Apply moves is selected)
    if (o.get("wiresculpt_handle") and not PLANES) or o.get("wiresculpt_contour"):
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


def win_override():
    return bpy.context.temp_override(window=win, area=area, region=ui)


def find_planes():
    with win_override():
        assert bpy.ops.wiresculpt.find_planes() == {'FINISHED'}


def preview_first():
    from wiresculpt.operators import plane_search as search
    with win_override():
        assert bpy.ops.wiresculpt.preview_planes(index=0) == {'FINISHED'}
    print("PREVIEW", search.RESULT["candidates"][0]["changes"])


def apply_first():
    from wiresculpt.operators import plane_search as search
    def placement(o):  # origin and normal
        return o.matrix_world.col[3].xyz, o.matrix_world.col[2].xyz.normalized()
    before = {o.name: placement(o) for o in bpy.context.scene.objects if o.get("wiresculpt_handle")}
    with win_override():
        assert bpy.ops.wiresculpt.apply_planes(index=0) == {'FINISHED'}
    print("APPLIED", search.RESULT["candidates"][0]["changes"])
    for o in bpy.context.scene.objects:
        if o.get("wiresculpt_contour"):  # Slice makes them anew
            o.hide_set(True)
        o.select_set(o.name in before and any((x - y).length > 1e-6 for x, y in zip(placement(o), before[o.name])))
    assert scene_results.stored_design()["stable"]


# (file, assembly step, what to do first, crop: (pixels of viewport left of the sidebar, pixels
# from the window's top: where the sidebar's content ends, found by eye; 0 for all))
VIEW = 560  # the viewport strip the planes shots keep, the sculpture framed at its top
if FABRICATION:
    shots = [("panel-fabrication.png", 0, None, None)]
elif PLANES:
    shots = [("panel-planes-1-not-stable.png", 0, None, (VIEW, 1230)),
             ("panel-planes-2-candidates.png", 0, find_planes, (VIEW, 1850)),
             ("panel-planes-2b-preview.png", 0, preview_first, (VIEW, 1850)),
             ("panel-planes-3-applied.png", 0, apply_first, (VIEW, 1590))]  # to the Stability panel's end
else:
    shots = [("panel.png", 0, None, None), ("panel-step1.png", 1, None, None)]


def frame_sculpture(size=VIEW - 100):
    """Puts the sculpture (wires and previews) `size` pixels across in the strip of viewport left
    of the sidebar, at its top. From the view as last drawn (the region's matrices update only on
    a redraw): the apparent size goes inversely with the distance from the eye."""
    from bpy_extras import view3d_utils
    from mathutils import Vector
    r3d = space.region_3d
    points = [o.matrix_world @ Vector(c) for o in bpy.context.scene.objects
              if "wiresculpt_wire" in o or "wiresculpt_preview" in o for c in o.bound_box]
    center = sum(points, Vector()) / len(points)
    radius = max((p - center).length for p in points) / 1.6  # ~ the sphere in the corners' box
    right = r3d.view_rotation @ Vector((1.0, 0.0, 0.0))
    up = r3d.view_rotation @ Vector((0.0, 1.0, 0.0))
    eye = r3d.view_location + r3d.view_rotation @ Vector((0.0, 0.0, r3d.view_distance))
    a = view3d_utils.location_3d_to_region_2d(region, r3d, center)
    b = view3d_utils.location_3d_to_region_2d(region, r3d, center + radius * right)
    r3d.view_distance = (eye - center).length * 2 * (b - a).length / size
    per_metre = size / (2 * radius)
    dx = (ui.x - region.x - VIEW // 2) - region.width / 2
    dy = (region.height - 90 - size // 2) - region.height / 2
    r3d.view_location = center - (dx * right + dy * up) / per_metre


def crop(path, box):
    """Cuts the screenshot at `path` to the sidebar and `box[0]` pixels of viewport left of it,
    from the window's top down to `box[1]` pixels (0: to the sidebar's bottom)."""
    import numpy as np
    image = bpy.data.images.load(path)
    w, h = image.size
    pixels = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    pixels = pixels.reshape(h, w, 4)  # rows bottom-up, window pixels
    x0, x1 = max(0, ui.x - box[0]), min(w, area.x + area.width)
    y0 = max(ui.y, h - box[1]) if box[1] else ui.y
    part = np.ascontiguousarray(pixels[y0:h, x0:x1])
    out = bpy.data.images.new("crop", part.shape[1], part.shape[0])
    out.pixels.foreach_set(part.ravel())
    out.filepath_raw = path
    out.file_format = 'PNG'
    out.save()
    bpy.data.images.remove(image)
    bpy.data.images.remove(out)

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
    name, step, action, box = shots.pop(0)
    ws.assembly_step = step
    if action:
        action()
    if PLANES:
        frame_sculpture()
    def take():
        path = os.path.join(OUT, name)
        with bpy.context.temp_override(window=win, area=area):
            bpy.ops.screen.screenshot(filepath=path, check_existing=False)
        if box:
            crop(path, box)
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
