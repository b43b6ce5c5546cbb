"""Cut handles: one empty per closed wire, at the point where the wire is cut open to be bent
(Sec. 4.4). Optimize places each handle at the cut it chose; the user drags a handle along (or near)
its wire and the next Optimize cuts the wire at its target point nearest the handle that is not a
crossing. Deleting a handle gives the wire back its automatic cut (the middle of its longest
stretch between crossings).

Handles are matched to wires by name (custom property CUT_KEY), like the wire curves.
"""
import bpy
from mathutils import Vector

from .objects import scene_collection, tagged

CUT_KEY = "wiresculpt_cut"  # custom property on cut handles: the wire's name
PLACED_KEY = "wiresculpt_cut_placed"  # where Optimize last put the handle (world, metres)
USER_KEY = "wiresculpt_cut_user"  # the user has moved the handle: the cut follows it from now on
CUTS_COLLECTION = "Cuts"
MOVED = 1e-6  # metres: a handle further than this from where Optimize put it has been moved
HANDLE_SIZE = 4.0  # the empty's display size in wire diameters


def _tagged(scene):
    return tagged(scene, CUT_KEY)


def _where(obj):
    """The handle's world position. Its location when it has no parent: matrix_world lags behind a
    location set from Python until the next depsgraph update."""
    return obj.matrix_world.translation if obj.parent else obj.location


def is_moved(obj):
    """True when the user has moved the handle, now or since an earlier Optimize."""
    if obj.get(USER_KEY):
        return True
    placed = obj.get(PLACED_KEY)
    if placed is None:
        return True  # a handle the add-on never placed: the user's own
    return (_where(obj) - Vector(placed)).length > MOVED


def user_cut_points(scene):
    """{wire name: (x, y, z)} of the handles the user has moved (world, metres)."""
    return {name: tuple(_where(obj)) for name, obj in _tagged(scene).items()
            if is_moved(obj)}


def apply_to_design(scene, design):
    """Gives each closed wire of `design` whose handle was moved a `cut_point` (the forces stage
    snaps it to the target). Returns the names of the wires that got one."""
    return set_cut_points(design, user_cut_points(scene))


def set_cut_points(design, points):
    """apply_to_design with the moved handles' points ({wire name: (x, y, z)}, user_cut_points)
    read earlier: no scene is touched, so a worker thread may call it."""
    named = []
    for wire in design["wires"]:
        if wire["closed"] and wire["name"] in points:
            wire["cut_point"] = list(points[wire["name"]])
            named.append(wire["name"])
    return named


def write(scene, design):
    """One handle per closed wire with a cut, at its cut point; handles of wires that are gone or
    open are removed. A moved handle is snapped to the cut it gave and stays the user's."""
    existing = _tagged(scene)
    coll = scene_collection(scene, CUTS_COLLECTION)
    size = HANDLE_SIZE * design["material"]["wire_diameter"]
    for wire in design["wires"]:
        cut = wire.get("cut", -1)
        if not wire["closed"] or cut is None or cut < 0 or not wire.get("target"):
            continue
        obj = existing.pop(wire["name"], None)
        user = bool(obj is not None and (is_moved(obj) or "cut_point" in wire))
        if obj is None:
            obj = bpy.data.objects.new(f"Cut {wire['name']}", None)
            obj[CUT_KEY] = wire["name"]
            coll.objects.link(obj)
        obj.empty_display_type = 'SPHERE'
        obj.empty_display_size = size
        obj.hide_render = True
        point = tuple(float(x) for x in wire["target"][cut])
        obj.parent = None
        obj.location = point
        obj[PLACED_KEY] = point
        obj[USER_KEY] = user
    for obj in existing.values():
        bpy.data.objects.remove(obj, do_unlink=True)


def remove(scene):
    for obj in _tagged(scene).values():
        bpy.data.objects.remove(obj, do_unlink=True)
