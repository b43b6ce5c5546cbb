"""How a saved .blend opens: every 3D view framed on the sculpture, its sidebar open on
the Wire tab, the first wire selected and active; and redraw_3d_views, which the operators use to
show what changed in module state (Live's verdict, a previewed candidate, a dropped result).

Blender keeps each 3D view's camera (SpaceView3D.region_3d: view_location, view_distance,
view_rotation) and whether its sidebar shows (show_region_ui) in the screens it saves, so setting
them before saving is enough, also in a background run. The sidebar's tab is set through
blend.compat.show_wire_tab where the API allows it (Region.active_panel_category, 4.x, in a drawn
sidebar); where it does not (Blender 3.4's Python cannot set it; a background 4.x Blender's
sidebars are never drawn and have no tabs), the batch run writes it into the saved file
(core.blendfile.set_sidebar_tab).
"""
import bpy
from mathutils import Vector

from . import compat, results

# Distance from the view's centre to the eye, in model sizes (the largest side of the wires'
# bounding box): with the 3D view's default 50 mm lens the whole sculpture shows, with a margin.
DISTANCE_IN_SIZES = 1.6


def wire_objects(scene):
    """The scene's wire curves in the design's order (by wire id)."""
    wires = [o for o in scene.objects if results.WIRE_KEY in o]
    return sorted(wires, key=lambda o: (o.get(results.WIRE_ID_KEY, 1 << 30), o.name))


def points(obj):
    """World coordinates of a curve's control points (a wire curve's points are the wire's shape;
    no evaluation needed, unlike bound_box), or of its bounding box corners for other objects."""
    if obj.type == 'CURVE':
        return [obj.matrix_world @ Vector(p.co[:3]) for s in obj.data.splines for p in s.points]
    return [obj.matrix_world @ Vector(c) for c in obj.bound_box]


def bounds(objects):
    """(centre, size): the centre of the objects' world bounding box and its largest side."""
    corners = [p for o in objects for p in points(o)]
    if not corners:
        return Vector((0.0, 0.0, 0.0)), 0.0
    lo = Vector(tuple(min(c[i] for c in corners) for i in range(3)))
    hi = Vector(tuple(max(c[i] for c in corners) for i in range(3)))
    return (lo + hi) / 2, max(hi - lo)


def redraw_3d_views():
    """Asks every 3D view of every window to redraw (a verdict, an overlay or a result changed
    outside an operator's own area)."""
    wm = bpy.context.window_manager
    for window in (wm.windows if wm else []):
        for area in (window.screen.areas if window.screen else []):
            if area.type == 'VIEW_3D':
                area.tag_redraw()


def view3d_spaces():
    """Every 3D view of every screen in the file (each workspace has its own)."""
    for screen in bpy.data.screens:
        for area in screen.areas:
            if area.type == 'VIEW_3D':
                for space in area.spaces:
                    if space.type == 'VIEW_3D':
                        yield screen, area, space


def frame(objects, distance_in_sizes=DISTANCE_IN_SIZES):
    """Points every 3D view at the objects' bounding box, from `distance_in_sizes` times its
    largest side, with the clipping range to match. Returns (centre, size, views set)."""
    centre, size = bounds(objects)
    if size <= 0:
        return centre, size, 0
    count = 0
    for _screen, _area, space in view3d_spaces():
        r3d = space.region_3d
        if r3d is None:
            continue
        r3d.view_location = centre
        r3d.view_distance = distance_in_sizes * size
        if r3d.view_perspective == 'CAMERA':
            r3d.view_perspective = 'PERSP'
        space.clip_start = min(space.clip_start, size / 100)
        space.clip_end = max(space.clip_end, 100 * size)
        count += 1
    return centre, size, count


def open_sidebar():
    """Shows every 3D view's sidebar, on the Wire tab where Blender's Python can set it
    (compat.show_wire_tab). Returns True when the tab was set in every sidebar through the API
    (else core.blendfile.set_sidebar_tab does it in the saved file)."""
    sidebars = 0
    for _screen, area, space in view3d_spaces():
        space.show_region_ui = True
        sidebars += sum(1 for region in area.regions if region.type == 'UI')
    return compat.show_wire_tab() == sidebars


def select_first_wire(scene):
    """Selects the first wire (the design's wire 0) alone and makes it the active object; returns
    it (None when there are no wires)."""
    wires = wire_objects(scene)
    if not wires:
        return None
    view_layer = bpy.context.view_layer
    for obj in view_layer.objects:
        obj.select_set(False)
    wires[0].select_set(True)
    view_layer.objects.active = wires[0]
    return wires[0]


def open_ready(scene):
    """Everything above, for the scene's wires. Returns {"centre", "size", "views", "tab_set",
    "selected"} (tab_set False: write the tab into the saved file)."""
    wires = wire_objects(scene)
    centre, size, views = frame(wires)
    tab_set = open_sidebar()
    first = select_first_wire(scene)
    return {"centre": tuple(centre), "size": size, "views": views, "tab_set": tab_set,
            "selected": first.name if first else None}
