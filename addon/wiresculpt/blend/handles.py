"""Slicing handles: ordinary plane objects, tagged, whose world position and Z axis are a slicing
plane; and the model mesh they cut."""
import uuid

import bpy

from ..core.scene import PlaneSpec
from .objects import scene_collection

HANDLE_KEY = "wiresculpt_handle"  # custom property that marks an object as a slicing handle
# custom property: a handle's persistent id (plane_ids), saved with the file (an object's
# session_uid is not); Optimize records it beside the design, so a renamed plane stays the same plane
HANDLE_ID_KEY = "wiresculpt_handle_id"
PLANES_COLLECTION = "Slicing Planes"
PLANE_MARGIN = 1.2  # a new handle is this much wider than the model's largest extent


def is_handle(obj):
    return bool(obj.get(HANDLE_KEY))


def handles(scene):
    """The scene's slicing handles, by name."""
    return sorted((o for o in scene.objects if is_handle(o)), key=lambda o: o.name)


def next_handle_name():
    """"Slice A", "Slice B", ... "Slice Z", "Slice AA", ...: the first unused one."""
    k = 0
    while True:
        letters, n = "", k
        while True:
            letters = chr(ord("A") + n % 26) + letters
            n = n // 26 - 1
            if n < 0:
                break
        name = f"Slice {letters}"
        if name not in bpy.data.objects:
            return name
        k += 1


def handle_plane(handle, depsgraph):
    """(name, origin, unit normal) of a handle: its world location and world Z axis;
    ValueError when the handle is flattened along Z and has no normal."""
    M = handle.evaluated_get(depsgraph).matrix_world
    normal = M.col[2].xyz
    if normal.length < 1e-12:
        raise ValueError(f"slicing plane {handle.name} has zero scale along its Z axis, "
                         "so it has no normal; give it a non-zero scale")
    return handle.name, tuple(M.translation), tuple(normal.normalized())


def contour_plane(scene, item):
    """The slicing handle that cut contour list item `item`, or None when that plane is gone.
    Items follow the plane object itself (item.plane_object), so a renamed plane keeps its
    contours and a new plane that takes a deleted one's name does not; the object is gone when
    it was deleted (the pointer reads None), unlinked from `scene` (an object deleted in the
    viewport lingers outside every scene until contours.release_deleted lets it go) or no longer
    tagged as a handle. Items of files saved
    before the pointer existed (has_plane_object False) resolve by their stored plane name.
    (has_plane_object, not is_property_set: reading an unset ID PointerProperty adds an empty
    property in Blender 3.4, so is_property_set changes under a mere read.)"""
    if item.has_plane_object:
        obj = item.plane_object
    else:
        obj = scene.objects.get(item.plane)
    if obj is None or not is_handle(obj) or scene.objects.get(obj.name) != obj:
        return None
    return obj


def contour_plane_name(item):
    """The current name of the plane of contour list item `item`, for messages and wire names:
    its object's name while the item points at one, else the name stored at the Slice."""
    obj = item.plane_object if item.has_plane_object else None
    return item.plane if obj is None else obj.name


def contour_planes(scene):
    """{name: handle} of the contour list's planes still in `scene` (contour_plane), each looked
    up once (a lookup in the scene's objects walks them)."""
    found = {}
    for item in scene.wiresculpt.contours:
        key = item.plane_object if item.has_plane_object else item.plane
        if key not in found:
            found[key] = contour_plane(scene, item)
    return {handle.name: handle for handle in found.values() if handle is not None}


def handle_id(obj):
    """The handle's persistent id (plane_ids), or None when it has none."""
    uid = obj.get(HANDLE_ID_KEY)
    return uid if isinstance(uid, str) and uid else None


def plane_ids(scene):
    """{name: persistent id} of the ticked contours' planes, those an Optimize solves with, each
    given a new id first where it has none or shares it with another of them. Writes to the
    handles: call it from an operator. A linked (library) handle cannot be written and goes by
    its name."""
    ids = {}
    for item in scene.wiresculpt.contours:
        handle = contour_plane(scene, item) if item.use else None
        if handle is None or handle.name in ids or handle.library is not None:
            continue
        uid = handle_id(handle)
        if uid is None or uid in ids.values():
            uid = handle[HANDLE_ID_KEY] = uuid.uuid4().hex
        ids[handle.name] = uid
    return ids


def drop_copied_ids(planes, known):
    """Takes the id from each handle of `planes` that is not in `known` (the contour list's planes
    before this Slice) and shares it with one that is: a copy (Shift+D copies custom
    properties), which is another plane. Writes to the handles: call it from an operator."""
    held = {handle_id(h) for h in planes if h in known} - {None}
    for handle in planes:
        if handle not in known and handle.library is None and handle_id(handle) in held:
            del handle[HANDLE_ID_KEY]


def ticked_planes(scene, depsgraph):
    """The slicing planes of the ticked contours, as PlaneSpecs whose contour rule is the ticked
    indices (in the list's order): what Optimize and Live slice with. ValueError when no contour
    is ticked or the plane of one is gone."""
    ticked = [item for item in scene.wiresculpt.contours if item.use]
    if not ticked:
        raise ValueError("No contour is ticked: Slice, then tick the contours that become wires")
    rules = {}  # handle object -> its ticked contour indices, in the list's order
    for item in ticked:
        handle = contour_plane(scene, item)
        if handle is None:
            raise ValueError(f"slicing plane {contour_plane_name(item)} of a ticked contour is gone: "
                             "Slice again")
        rules.setdefault(handle, []).append(item.index)
    return [PlaneSpec(*handle_plane(handle, depsgraph), contours=indices) for handle, indices in rules.items()]


def add_handle(context, low, high):
    """A new handle through the centre of the box (low, high) (world, metres), wider than its
    largest side, selected and active when its collection is visible. Returns the object."""
    scene = context.scene
    half = max(0.5 * PLANE_MARGIN * float((high - low).max()), 1e-3)
    name = next_handle_name()
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(-half, -half, 0), (half, -half, 0), (half, half, 0), (-half, half, 0)],
                     [], [(0, 1, 2, 3)])
    obj = bpy.data.objects.new(name, mesh)
    obj[HANDLE_KEY] = True
    obj.location = tuple(0.5 * (low + high))
    obj.display_type = 'WIRE'
    obj.show_in_front = True
    obj.hide_render = True
    scene_collection(scene, PLANES_COLLECTION).objects.link(obj)
    context.view_layer.update()  # Blender 3.4 adds new objects to the view layer lazily
    if context.view_layer.objects.get(name) == obj:  # not when its collection is excluded
        for other in context.selected_objects:
            other.select_set(False)
        obj.select_set(True)
        context.view_layer.objects.active = obj
    return obj


def model_name(settings):
    """The name of the model picked in the Wire panel (`settings`: a scene's wiresculpt), "" when
    none is: what a solve's record, Live's snapshot and the stale check compare."""
    model = settings.model
    return model.name if model is not None else ""


def model_problem(scene, model):
    """Why `model` cannot be sliced, or None."""
    if model is None:
        return "No model mesh: pick one in the Wire panel (Model)"
    if model.type != 'MESH':
        return f"Model {model.name} is not a mesh"
    if is_handle(model):
        return f"Model {model.name} is a slicing plane; pick the mesh to slice"
    if scene.objects.get(model.name) != model:
        return (f"Model '{model.name}' is not in scene '{scene.name}' (deleted or unlinked): put it back, "
                f"or pick the mesh to slice in the Wire panel (Model)")
    return None
