"""Slicing handles: ordinary plane objects, tagged, whose world position and Z axis are a slicing
plane; and the target mesh they cut."""
import bpy

from ..core.scene import PlaneSpec
from .objects import scene_collection

HANDLE_KEY = "wiresculpt_handle"  # custom property that marks an object as a slicing handle
PLANES_COLLECTION = "Slicing Planes"
PLANE_MARGIN = 1.2  # a new handle is this much wider than the target's largest extent


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


def ticked_planes(scene, depsgraph):
    """The slicing planes of the ticked contours, as PlaneSpecs whose contour rule is the ticked
    indices (in the list's order): what Optimize and Live slice with. ValueError when no contour
    is ticked or the plane of one is gone."""
    ticked = [(item.plane, item.index) for item in scene.wiresculpt.contours if item.use]
    if not ticked:
        raise ValueError("No contour is ticked: Slice, then tick the contours that become wires")
    by_name = {h.name: h for h in handles(scene)}
    rules = {}  # plane name -> its ticked contour indices, in the list's order
    for plane, index in ticked:
        if plane not in by_name:
            raise ValueError(f"slicing plane {plane} of a ticked contour is gone: Slice again")
        rules.setdefault(plane, []).append(index)
    return [PlaneSpec(*handle_plane(by_name[name], depsgraph), contours=indices) for name, indices in rules.items()]


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


def target_problem(scene, target):
    """Why `target` cannot be sliced, or None."""
    if target is None:
        return "No target mesh: pick one in the Wire panel (Target)"
    if target.type != 'MESH':
        return f"Target {target.name} is not a mesh"
    if is_handle(target):
        return f"Target {target.name} is a slicing plane; pick the mesh to slice"
    if scene.objects.get(target.name) != target:
        return (f"Target '{target.name}' is not in scene '{scene.name}' (deleted or unlinked): put it back, "
                f"or pick the mesh to slice in the Wire panel (Target)")
    return None
