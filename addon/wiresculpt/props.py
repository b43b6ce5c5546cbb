"""The add-on's settings: one PropertyGroup on the scene, `scene.wiresculpt`."""
import bpy
from bpy.props import (BoolProperty, CollectionProperty, FloatProperty, IntProperty,
                       PointerProperty, StringProperty)

HANDLE_KEY = "wiresculpt_handle"  # custom property that marks an object as a slicing handle


def is_handle(obj):
    return bool(obj.get(HANDLE_KEY))


def _poll_target(_settings, obj):
    return obj.type == 'MESH' and not is_handle(obj)


class WiresculptContour(bpy.types.PropertyGroup):
    plane: StringProperty(
        name="Plane", description="Name of the slicing plane that cut this contour")
    index: IntProperty(
        name="Index", min=0,
        description="Position of this contour among its plane's contours, longest first (0)")
    length: FloatProperty(
        name="Length", unit='LENGTH', subtype='DISTANCE', min=0.0,
        description="Length of the contour in world space, closing edge included")
    closed: BoolProperty(
        name="Closed", description="The contour is a closed loop (open where the mesh has a hole)")
    use: BoolProperty(
        name="Use as wire", default=False,
        description="Make this contour one of the sculpture's wires")
    curve: PointerProperty(
        name="Curve", type=bpy.types.Object,
        description="Curve object that shows this contour in the viewport")


class WiresculptSettings(bpy.types.PropertyGroup):
    target: PointerProperty(
        name="Target", type=bpy.types.Object, poll=_poll_target,
        description="Mesh to turn into a wire sculpture (evaluated: modifiers and transform "
                    "applied)")
    contours: CollectionProperty(
        name="Contours", type=WiresculptContour,
        description="Contours cut by the slicing planes at the last Slice")
    active_contour: IntProperty(
        name="Active Contour", min=0, default=0,
        description="Contour highlighted in the list")


_classes = (WiresculptContour, WiresculptSettings)


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.wiresculpt = PointerProperty(
        type=WiresculptSettings, name="Wire Sculpture",
        description="Settings and results of the wiresculpt add-on")


def unregister():
    del bpy.types.Scene.wiresculpt
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
