"""Driven by test_batch_outputs.py in a Blender with a window (under Xvfb): opens a saved
sculpture.blend as a user does (the add-on enabled), lets the window draw, then saves a copy
(uncompressed) and prints `MODAL {json}` with what the screen shows: per 3D view of the window's
screen its distance, centre and whether its sidebar is open; the active and selected objects.

The sidebar's tab has no Python API in Blender 3.4; the region keeps it in its tab stack, which
drawing updates (a tab that is not there is replaced by the first tab there is) and the saved copy
holds: the test reads it from the copy.

    blender --factory-startup --python blender_tests/ui_open_blend.py -- SCULPTURE.blend COPY.blend
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [os.path.join(os.path.dirname(HERE), "addon"), HERE]

import bpy  # noqa: E402

import wiresculpt  # noqa: E402
from ui_steps import guarded, report, start_watchdog  # noqa: E402

wiresculpt.register()
path, copy = sys.argv[sys.argv.index("--") + 1:][:2]
bpy.ops.wm.open_mainfile(filepath=path)
seen = {"draws": 0}


def step():
    window = bpy.context.window_manager.windows[0]
    if seen["draws"] < 4:  # a few redraws: the sidebar has drawn its tabs
        seen["draws"] += 1
        for area in window.screen.areas:
            area.tag_redraw()
        return 0.5
    views = []
    for area in window.screen.areas:
        if area.type == 'VIEW_3D':
            space = area.spaces.active
            r3d = space.region_3d
            views.append({"distance": r3d.view_distance, "centre": list(r3d.view_location),
                          "sidebar": space.show_region_ui, "perspective": r3d.view_perspective})
    view_layer = window.view_layer
    seen.update(screen=window.screen.name, views=views,
                active=view_layer.objects.active.name if view_layer.objects.active else None,
                selected=sorted(o.name for o in view_layer.objects if o.select_get(view_layer=view_layer)))
    with bpy.context.temp_override(window=window):
        bpy.ops.wm.save_as_mainfile(filepath=copy, copy=True, compress=False)
    report(seen)
    return None


start_watchdog(seen, 90.0)
bpy.app.timers.register(guarded(seen, step), first_interval=1.0)
