"""Slicing: drop plane handles through the target, cut it, show the contours as curves."""
import bpy
import numpy as np
from mathutils import Matrix

from .. import mesh_data, native
from ..core.contours import pick
from ..props import HANDLE_KEY, is_handle

CONTOUR_KEY = "wiresculpt_contour"  # custom property {"plane": name, "index": k} on curve objects
PLANES_COLLECTION = "Slicing Planes"
CONTOURS_COLLECTION = "Contours"
PLANE_MARGIN = 1.2  # a new handle is this much wider than the target's largest extent


# --- small functions, no UI -----------------------------------------------------------------

def scene_collection(scene, name):
    """The collection `name`, created and linked under the scene's collection when missing."""
    coll = bpy.data.collections.get(name)
    if coll is None:
        coll = bpy.data.collections.new(name)
    if coll not in scene.collection.children_recursive[:]:
        scene.collection.children.link(coll)
    return coll


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


def contour_key(obj):
    """(plane, index) of a contour curve object, or None when it is not one of ours."""
    tag = obj.get(CONTOUR_KEY)
    try:
        return str(tag["plane"]), int(tag["index"])
    except (TypeError, KeyError, ValueError):
        return None


def write_polyline(curve, points, closed):
    """Replace the splines of `curve` by one POLY spline through `points` (n, 3)."""
    curve.splines.clear()
    if len(points) == 0:
        return
    spline = curve.splines.new('POLY')
    spline.points.add(len(points) - 1)
    co = np.ones((len(points), 4), dtype=np.float32)
    co[:, :3] = points
    spline.points.foreach_set("co", co.ravel())
    spline.use_cyclic_u = bool(closed)


def existing_curves(scene):
    """{(plane, index): object} of the scene's contour curves. A copy of one (Shift+D copies
    the tag) loses the tag and becomes the user's own curve."""
    found = {}
    for obj in sorted(scene.objects, key=lambda o: o.name):
        key = contour_key(obj) if obj.type == 'CURVE' else None
        if key is None:
            continue
        if key in found:
            del obj[CONTOUR_KEY]
        else:
            found[key] = obj
    return found


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


def remove_object(obj):
    data = obj.data
    bpy.data.objects.remove(obj, do_unlink=True)
    if data is not None and data.users == 0:
        bpy.data.curves.remove(data)


def apply_slice(scene, settings, names, per_plane):
    """Make the scene's curves and the settings' list match the sliced `per_plane` contours,
    keeping the user's ticks. Returns (contour count, ticked count, removed curve count)."""
    ticks = {(item.plane, item.index): item.use for item in settings.contours}
    existing = existing_curves(scene)
    settings.contours.clear()
    for plane, contours in zip(names, per_plane):
        longest = set(pick(contours, "largest", plane))
        for index, contour in enumerate(contours):
            obj = contour_curve(scene, existing, plane, index)
            existing.pop((plane, index), None)
            write_polyline(obj.data, contour["points"], contour["closed"])
            obj.matrix_world = Matrix.Identity(4)
            item = settings.contours.add()
            item.name = f"{plane} #{index}"
            item.plane, item.index, item.curve = plane, index, obj
            item.length, item.closed = contour["length"], contour["closed"]
            item.use = ticks.get((plane, index), index in longest)
    for obj in existing.values():  # contours that disappeared
        remove_object(obj)
    count = len(settings.contours)
    settings.active_contour = min(settings.active_contour, max(count - 1, 0))
    return count, sum(item.use for item in settings.contours), len(existing)


def target_problem(scene, target):
    """Why `target` cannot be sliced, or None."""
    if target is None:
        return "No target mesh: pick one in the Wire panel (Target)"
    if target.type != 'MESH':
        return f"Target {target.name} is not a mesh"
    if is_handle(target):
        return f"Target {target.name} is a slicing plane; pick the mesh to slice"
    if scene.objects.get(target.name) != target:
        return f"Target {target.name} is not in scene {scene.name}"
    return None


# --- operators ------------------------------------------------------------------------------

class WIRESCULPT_OT_add_plane(bpy.types.Operator):
    """Add a slicing plane through the centre of the target; move and rotate it, then Slice"""
    bl_idname = "wiresculpt.add_plane"
    bl_label = "Add Slicing Plane"
    bl_options = {'REGISTER', 'UNDO'}

    def execute(self, context):
        scene = context.scene
        target = scene.wiresculpt.target
        problem = target_problem(scene, target)
        if problem:
            self.report({'ERROR'}, problem)
            return {'CANCELLED'}
        try:
            V, _F = mesh_data.object_triangles(target, context.evaluated_depsgraph_get())
        except RuntimeError as exc:
            self.report({'ERROR'}, f"Cannot read {target.name}: {exc}")
            return {'CANCELLED'}
        if len(V) == 0:
            self.report({'ERROR'}, f"Target {target.name} has no vertices to slice")
            return {'CANCELLED'}
        low, high = V.min(axis=0), V.max(axis=0)
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
        self.report({'INFO'}, f"Added {name} through the centre of {target.name}")
        return {'FINISHED'}


class WIRESCULPT_OT_slice(bpy.types.Operator):
    """Cut the target with every slicing plane; the contours become curves and list items"""
    bl_idname = "wiresculpt.slice"
    bl_label = "Slice"
    bl_options = {'REGISTER', 'UNDO'}

    def execute(self, context):
        scene = context.scene
        settings = scene.wiresculpt
        target = settings.target
        problem = target_problem(scene, target)
        if problem is None and not native.available():
            problem = native.LOAD_ERROR
        planes = handles(scene)
        if problem is None and not planes:
            problem = "No slicing planes: add one with Add Slicing Plane"
        if problem:
            self.report({'ERROR'}, problem)
            return {'CANCELLED'}
        depsgraph = context.evaluated_depsgraph_get()
        try:
            specs = [handle_plane(h, depsgraph) for h in planes]
            V, F = mesh_data.object_triangles(target, depsgraph)
            result = native.slice_mesh(V, F, specs)
        except (ValueError, RuntimeError) as exc:
            self.report({'ERROR'}, f"Cannot slice {target.name}: {exc}")
            return {'CANCELLED'}
        names = [name for name, _o, _n in specs]
        count, ticked, removed = apply_slice(scene, settings, names, result["contours"])
        missed = [name for name, contours in zip(names, result["contours"]) if not contours]
        message = (f"Sliced {target.name} with {len(names)} plane{'s' * (len(names) != 1)}: "
                   f"{count} contour{'s' * (count != 1)}, {ticked} used as wires")
        if removed:
            message += f", {removed} old curve{'s' * (removed != 1)} removed"
        if missed:
            self.report({'WARNING'}, message + f"; {', '.join(missed)} cut nothing")
        else:
            self.report({'INFO'}, message)
        return {'FINISHED'}


register, unregister = bpy.utils.register_classes_factory(
    (WIRESCULPT_OT_add_plane, WIRESCULPT_OT_slice))
