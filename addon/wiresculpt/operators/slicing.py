"""Slicing: drop plane handles through the model, cut it, show the contours as curves."""
import bpy

from ..blend import mesh
from ..blend.contours import release_deleted, slice_scene
from ..blend.handles import add_handle, model_problem
from ..blend.registration import classes_factory, handlers_factory


# --- operators ------------------------------------------------------------------------------

class WIRESCULPT_OT_add_plane(bpy.types.Operator):
    """Add a slicing plane through the centre of the model; move and rotate it, then Slice"""
    bl_idname = "wiresculpt.add_plane"
    bl_label = "Add Slicing Plane"
    bl_options = {'REGISTER', 'UNDO'}

    def execute(self, context):
        scene = context.scene
        model = scene.wiresculpt.model
        problem = model_problem(scene, model)
        if problem:
            self.report({'ERROR'}, problem)
            return {'CANCELLED'}
        try:
            V, _F = mesh.object_triangles(model, context.evaluated_depsgraph_get())
        except RuntimeError as exc:
            self.report({'ERROR'}, f"Cannot read {model.name}: {exc}")
            return {'CANCELLED'}
        if len(V) == 0:
            self.report({'ERROR'}, f"Model {model.name} has no vertices to slice")
            return {'CANCELLED'}
        name = add_handle(context, V.min(axis=0), V.max(axis=0)).name
        self.report({'INFO'}, f"Added {name} through the centre of {model.name}")
        return {'FINISHED'}


class WIRESCULPT_OT_slice(bpy.types.Operator):
    """Cut the model with every slicing plane; the contours become curves and list items"""
    bl_idname = "wiresculpt.slice"
    bl_label = "Slice"
    bl_options = {'REGISTER', 'UNDO'}

    def execute(self, context):
        level, message = slice_scene(context)
        self.report(level, message)
        return {'CANCELLED'} if 'ERROR' in level else {'FINISHED'}


_register, _unregister = classes_factory((WIRESCULPT_OT_add_plane, WIRESCULPT_OT_slice))


@bpy.app.handlers.persistent
def _release_deleted(*_args):
    """After every depsgraph update (a delete is one) and on loading a file (one saved before
    this): a plane or contour curve deleted in the viewport is not kept in the file by the contour
    list (contours.release_deleted). Not from a panel's draw, which may not write ID data; undo
    brings a deleted plane back with its pointer, as the undo step saved it."""
    try:
        release_deleted(bpy.data.scenes)
    except (AttributeError, ReferenceError):  # the add-on half unregistered, a scene being freed
        pass


_add_handlers, _remove_handlers = handlers_factory((("depsgraph_update_post", _release_deleted),
                                                    ("load_post", _release_deleted)))


def register():
    _register()
    _add_handlers()


def unregister():
    _remove_handlers()
    _unregister()
