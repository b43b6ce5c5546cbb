"""The first view of a saved design: where the API allows it (Blender 4.x), a file saved with a
wiresculpt design opens with the sidebar shown on its Wire tab (blend.compat.show_wire_tab)."""
import bpy
from bpy.app.handlers import persistent

from ..blend import compat
from ..blend.registration import handlers_factory


def has_design(scene):
    settings = getattr(scene, "wiresculpt", None)
    return settings is not None and (settings.model is not None or len(settings.contours) > 0)


@persistent
def wire_tab_on_save(*_args):
    if any(has_design(scene) for scene in bpy.data.scenes):
        compat.show_wire_tab()


register, unregister = handlers_factory((("save_pre", wire_tab_on_save),))
