"""Scene objects the add-on owns: collections, objects found by their tag, polyline curves,
removal."""
import bpy
import numpy as np


def scene_collection(scene, name):
    """The collection `name`, created and linked under the scene's collection when missing."""
    coll = bpy.data.collections.get(name)
    if coll is None:
        coll = bpy.data.collections.new(name)
    if coll not in scene.collection.children_recursive[:]:
        scene.collection.children.link(coll)
    return coll


def tagged(scene, key, value_of=None, kind=None):
    """{tag value: object} of the scene's objects carrying custom property `key` (and of type
    `kind` when given); `value_of(obj)` turns the tag into the dictionary key (None: not one of
    ours). A duplicate (Shift+D copies the tag) loses it and becomes the user's own object."""
    found = {}
    for obj in sorted(scene.objects, key=lambda o: o.name):
        if key not in obj or (kind is not None and obj.type != kind):
            continue
        value = obj[key] if value_of is None else value_of(obj)
        if value is None:
            continue
        if value in found:
            del obj[key]
        else:
            found[value] = obj
    return found


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


def remove_object(obj):
    data = obj.data
    bpy.data.objects.remove(obj, do_unlink=True)
    if data is not None and data.users == 0:
        bpy.data.curves.remove(data)
