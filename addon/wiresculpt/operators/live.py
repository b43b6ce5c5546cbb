"""Live's operator: copying the whole reason behind the live verdict. The engine (the timer that
re-solves while a plane moves, its job, its handlers) is live/engine.py; registering this module
installs it."""
import bpy

from ..blend.registration import classes_factory
from ..live import engine


class WIRESCULPT_OT_live_reason(bpy.types.Operator):
    """Copy the live verdict's whole reason to the clipboard (the line shows its first clause)"""

    bl_idname = "wiresculpt.live_reason"
    bl_label = "Copy Whole Reason"
    bl_options = {'INTERNAL'}  # writes nothing to the scene: no undo step

    @classmethod
    def description(cls, context, properties):
        """The tooltip: the whole reason, which the panel's line shortens."""
        return engine.reason() or cls.__doc__

    @classmethod
    def poll(cls, context):
        return bool(engine.running() and engine.reason())

    def execute(self, context):
        reason = engine.reason()
        context.window_manager.clipboard = reason
        self.report({'INFO'}, reason)  # the Info editor keeps it too
        return {'FINISHED'}


_register_classes, _unregister_classes = classes_factory((WIRESCULPT_OT_live_reason,))


def register():
    _register_classes()
    engine.install()


def unregister():
    engine.uninstall()
    _unregister_classes()
