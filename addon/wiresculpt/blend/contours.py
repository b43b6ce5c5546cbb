"""The sliced contours in the scene: one curve object per contour, tagged with its plane and
index, and the settings' contour list that the user ticks."""
import bpy
from mathutils import Matrix

from .. import native
from ..core import mesh_faults
from ..core.contours import pick
from . import mesh
from .handles import contour_plane, drop_copied_ids, handle_plane, handles, model_problem
from .objects import remove_object, scene_collection, tagged, write_polyline

CONTOUR_KEY = "wiresculpt_contour"  # custom property {"plane": name, "index": k} on curve objects
CONTOURS_COLLECTION = "Contours"


def contour_key(obj):
    """(plane, index) of a contour curve object, or None when it is not one of ours."""
    tag = obj.get(CONTOUR_KEY)
    try:
        return str(tag["plane"]), int(tag["index"])
    except (TypeError, KeyError, ValueError):
        return None


def existing_curves(scene):
    """{(plane, index): object} of the scene's contour curves. A copy of one (Shift+D copies
    the tag) loses the tag and becomes the user's own curve."""
    return tagged(scene, CONTOUR_KEY, contour_key, kind='CURVE')


def contour_curve(scene, existing, plane, index):
    """The curve object of contour (plane, index): the existing one, or a new one."""
    obj = existing.get((plane, index))
    if obj is None:
        name = f"Contour {plane} #{index}"
        curve = bpy.data.curves.new(name, 'CURVE')
        curve.dimensions = '3D'
        obj = bpy.data.objects.new(name, curve)
        obj[CONTOUR_KEY] = {"plane": plane, "index": index}
        scene_collection(scene, CONTOURS_COLLECTION).objects.link(obj)
    return obj


def release_deleted(scenes):
    """Clears the contour lists' pointers (plane_object, curve) to objects that nothing else holds:
    an object deleted in the viewport leaves every scene but stays in the file while a pointer
    is a user of it, and would be saved and reloaded for ever. Each pointer is a user, so an
    object with no more users than the lists' pointers to it is in no collection, hence in no
    scene. A cleared plane's items keep its last name (plane) and stay gone (has_plane_object,
    handles.contour_plane). Returns how many pointers were cleared. Writes ID data: call it from
    an operator or a handler, never from a draw."""
    items = [item for scene in scenes for item in scene.wiresculpt.contours]
    pointers = {}  # object -> how many of the lists' pointers hold it
    for item in items:
        # (has_plane_object first: reading an unset ID pointer adds an empty property in Blender 3.4)
        for obj in (item.plane_object if item.has_plane_object else None, item.curve):
            if obj is not None:
                pointers[obj] = pointers.get(obj, 0) + 1
    gone = {obj for obj, count in pointers.items() if obj.users <= count}
    cleared = 0
    for item in items:
        if item.has_plane_object and item.plane_object in gone:
            item.plane, item.plane_object = item.plane_object.name, None
            cleared += 1
        if item.curve in gone:
            item.curve = None
            cleared += 1
    return cleared


def contour_counts(settings):
    """(contours listed, contours ticked: those that become wires): the one count every message
    gives."""
    return len(settings.contours), sum(bool(item.use) for item in settings.contours)


def apply_slice(scene, settings, planes, per_plane, picked=None):
    """Make the scene's curves and the settings' list match the contours `per_plane` cut by the
    handle objects `planes`, keeping the user's ticks: a tick stays with its plane object (renamed
    or not) and its index; the ticks of a plane that is gone are dropped, even when a new plane
    has taken its name. A copy of a listed plane loses the id it copied (handles.drop_copied_ids).
    `picked`: the contours to tick ("plane/index" names) instead of the kept ticks.
    Returns (contour count, ticked count, removed curve count)."""
    ticks = {}  # (handle object, index) -> tick
    for item in settings.contours:
        handle = contour_plane(scene, item)
        if handle is not None:
            ticks[handle, item.index] = item.use
    drop_copied_ids(planes, {handle for handle, _index in ticks})
    existing = existing_curves(scene)
    settings.contours.clear()
    for handle, contours in zip(planes, per_plane):
        plane = handle.name
        longest = set(pick(contours, "largest", plane))
        for index, contour in enumerate(contours):
            obj = contour_curve(scene, existing, plane, index)
            existing.pop((plane, index), None)
            write_polyline(obj.data, contour["points"], contour["closed"])
            obj.matrix_world = Matrix.Identity(4)
            item = settings.contours.add()
            item.name = f"{plane} #{index}"
            item.plane, item.index, item.curve = plane, index, obj
            item.plane_object, item.has_plane_object = handle, True
            item.length, item.closed = contour["length"], contour["closed"]
            item.use = (f"{plane}/{index}" in picked if picked is not None
                        else ticks.get((handle, index), index in longest))
    for obj in existing.values():  # contours that disappeared
        remove_object(obj)
    count, ticked = contour_counts(settings)
    settings.active_contour = min(settings.active_contour, max(count - 1, 0))
    return count, ticked, len(existing)


def slice_scene(context, picked=None):
    """Cuts the model with every slicing plane into the contour list and curves. `picked`: the
    contours ("plane/index") to tick, instead of keeping the user's ticks (Apply of a plane
    candidate). Returns (report type, sentence): the counts said are the list's own (contour_counts)."""
    scene = context.scene
    settings = scene.wiresculpt
    model = settings.model
    problem = model_problem(scene, model)
    if problem is None and not native.available():
        problem = native.LOAD_ERROR
    planes = handles(scene)
    if problem is None and not planes:
        problem = "No slicing planes: add one with Add Slicing Plane"
    if problem:
        return {'ERROR'}, problem
    depsgraph = context.evaluated_depsgraph_get()
    try:
        specs = [handle_plane(h, depsgraph) for h in planes]
        V, F, closing = mesh.model_triangles(model, depsgraph, settings.min_segment)
        result = native.slice_mesh(V, F, specs)
    except (ValueError, RuntimeError) as exc:
        return {'ERROR'}, f"Cannot slice {model.name}: {exc}"
    names = [name for name, _o, _n in specs]
    _count, _ticked, removed = apply_slice(scene, settings, planes, result["contours"], picked)
    count, ticked = contour_counts(settings)
    missed = [name for name, contours in zip(names, result["contours"]) if not contours]
    message = (f"Sliced {model.name} with {len(names)} plane{'s' * (len(names) != 1)}: "
               f"{count} contour{'s' * (count != 1)}, {ticked} used as wires")
    if removed:
        message += f", {removed} old curve{'s' * (removed != 1)} removed"
    if closing is not None:  # an open or many-part mesh: what was done to slice it
        message += f"; {mesh_faults.closing_sentence(closing)}"
    if missed:
        return {'WARNING'}, message + f"; {', '.join(missed)} cut nothing"
    return {'INFO'}, message
