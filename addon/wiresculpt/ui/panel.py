"""The "Wire" tab of the 3D view's sidebar: target, slicing planes, the contour list."""
import textwrap

import bpy

from .. import native
from ..blend.registration import classes_factory
from ..operators.slicing import WIRESCULPT_OT_add_plane, WIRESCULPT_OT_slice

CHARS_PER_PIXEL = 1 / 7  # rough width of a label character, for wrapping long messages
BOX_MARGIN = 30  # pixels of a box not available to its text


def length_text(scene, value):
    """`value` (scene units) as the scene displays lengths, e.g. "1.235 m"."""
    units = scene.unit_settings
    if units.system == 'NONE':
        return f"{value:.4g}"
    return bpy.utils.units.to_string(units.system, 'LENGTH', value * units.scale_length,
                                     precision=4)


def draw_load_error(layout, context):
    box = layout.box()
    box.alert = True
    box.label(text="Solver not loaded", icon='ERROR')
    width = context.region.width if context.region else 280
    for line in textwrap.wrap(native.LOAD_ERROR, max(20, int((width - BOX_MARGIN) * CHARS_PER_PIXEL))):
        box.label(text=line)


class WIRESCULPT_UL_contours(bpy.types.UIList):
    """Contours of the last Slice: tick the ones that become wires."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname,
                  index=0, flt_flag=0):
        split = layout.split(factor=0.55)
        row = split.row(align=True)
        row.prop(item, "use", text="")
        row.label(text=f"{item.plane} #{item.index}",
                  icon='MESH_CIRCLE' if item.closed else 'IPO_LINEAR')
        right = split.row()
        right.alignment = 'RIGHT'
        right.label(text=length_text(context.scene, item.length))


class VIEW3D_PT_wiresculpt(bpy.types.Panel):
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "Wire"
    bl_label = "Wire Sculpture"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.wiresculpt
        if not native.available():
            draw_load_error(layout, context)
        layout.prop(settings, "target")
        col = layout.column(align=True)
        col.operator(WIRESCULPT_OT_add_plane.bl_idname, icon='MESH_PLANE')
        col.operator(WIRESCULPT_OT_slice.bl_idname, icon='MOD_BOOLEAN')
        layout.label(text="Contours (ticked: wires)")
        layout.template_list(WIRESCULPT_UL_contours.__name__, "", settings, "contours",
                             settings, "active_contour", rows=4)


register, unregister = classes_factory(
    (WIRESCULPT_UL_contours, VIEW3D_PT_wiresculpt))
