"""The "Wire" tab of the 3D view's sidebar: model, slicing planes, the contour list."""
import textwrap

import bpy

from .. import native
from ..blend.handles import contour_plane_name
from ..blend.registration import classes_factory
from ..core import live_verdict
from ..live import engine as live
from ..operators.live import WIRESCULPT_OT_live_reason
from ..operators.slicing import WIRESCULPT_OT_add_plane, WIRESCULPT_OT_slice
from .stale import live_hint

CHARS_PER_PIXEL = 1 / 7.5  # rough width of a label character, for wrapping long messages
BOX_MARGIN = 30  # pixels of a box not available to its text
ICON_WIDTH = 22  # pixels an icon takes from a label's text
WIDE_LIST = 280  # pixels of sidebar from which a contour row has room for its length too
# The live verdict's icon by its kind (core/live_verdict): a setup problem (cannot solve) reads as
# something to do, not as a verdict on the design; our error stands out in red (live_look).
LIVE_ICONS = {live_verdict.STABLE: 'CHECKMARK', live_verdict.SOLVING: 'SORTTIME', live_verdict.NOT_STABLE: 'ERROR',
              live_verdict.CANNOT_SOLVE: 'INFO', live_verdict.ERROR: 'CANCEL', live_verdict.OVER_LIMITS: 'ERROR'}


def length_text(scene, value, precision=4):
    """`value` (scene units) as the scene displays lengths, e.g. "1.235 m"."""
    units = scene.unit_settings
    if units.system == 'NONE':
        return f"{value:.{precision}g}"
    return bpy.utils.units.to_string(units.system, 'LENGTH', value * units.scale_length,
                                     precision=precision)


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
        # The name comes first: in a sidebar too narrow for name and length (Blender's default
        # width) the row shows the name alone; the details box below the list shows the active
        # row in full, length included, however narrow the sidebar is.
        icon = 'MESH_CIRCLE' if item.closed else 'IPO_LINEAR'
        width = context.region.width if context.region else WIDE_LIST
        if width < WIDE_LIST:
            row = layout.row(align=True)
            row.prop(item, "use", text="")
            row.label(text=contour_name(item), icon=icon)
            return
        split = layout.split(factor=0.62)
        row = split.row(align=True)
        row.prop(item, "use", text="")
        row.label(text=contour_name(item), icon=icon)
        right = split.row()
        right.alignment = 'RIGHT'
        right.label(text=length_text(context.scene, item.length, precision=3))


def contour_name(item):
    """The plane's current name (renaming the plane renames its contours' lines) and the index."""
    return f"{contour_plane_name(item)} #{item.index}"


def contour_details(scene, item):
    """The active contour in full, one sentence (wrapped by the panel)."""
    shape = "closed loop" if item.closed else "open curve (the mesh has a hole there)"
    role = "ticked: it becomes a wire" if item.use else "not ticked: not a wire"
    return (f"Plane \"{contour_plane_name(item)}\", contour {item.index} (longest first): a {shape}, "
            f"{length_text(scene, item.length)}; {role}")


def line_chars(context, icon='NONE'):
    """How many characters of label text fit the region's width in a box (an icon takes some)."""
    width = context.region.width if context.region else 280
    return max(20, int((width - BOX_MARGIN - (ICON_WIDTH if icon != 'NONE' else 0)) * CHARS_PER_PIXEL))


def wrap_labels(layout, context, text, icon='NONE'):
    """`text` as labels that fit the region's width (the sidebar cuts a long label short)."""
    lines = textwrap.wrap(text, line_chars(context, icon)) or [""]
    for i, line in enumerate(lines):
        layout.label(text=line, icon=icon if i == 0 else 'BLANK1' if icon != 'NONE' else 'NONE')


def live_look(kind):
    """(icon, alert) of the live line showing a verdict of `kind` (live.kind_shown())."""
    return LIVE_ICONS.get(kind, 'NONE'), kind == live_verdict.ERROR


def draw_live(layout, context):
    """The live verdict, wrapped; under it, when the line shows part of the reason, a button whose
    tooltip is the whole reason (a click copies it)."""
    icon, alert = live_look(live.kind_shown())
    col = layout.column()
    col.alert = alert
    wrap_labels(col, context, live.line(), icon=icon)
    if live.standing_shown():  # the 3D check of the live design (core/standing.summary)
        wrap_labels(col, context, live.standing_shown(), icon='BLANK1')
    hint = live_hint(context, live.kind_shown(), live.limits_shown())
    if hint:  # Live keeps the layering's own hooks; a current Optimize that says otherwise wins
        wrap_labels(layout, context, hint, icon='INFO')
    if live.whole_reason():
        layout.operator(WIRESCULPT_OT_live_reason.bl_idname, icon='COPYDOWN')


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
        layout.prop(settings, "model")
        col = layout.column(align=True)
        col.operator(WIRESCULPT_OT_add_plane.bl_idname, icon='MESH_PLANE')
        col.operator(WIRESCULPT_OT_slice.bl_idname, icon='MOD_BOOLEAN')
        row = layout.row()
        row.enabled = native.available()
        row.prop(settings, "live", toggle=True, icon='REC' if settings.live else 'PLAY')
        if live.line():
            draw_live(layout, context)
        elif live.refused_message(settings) and not settings.live:
            wrap_labels(layout.box(), context, live.refused_message(settings), icon='INFO')
        layout.label(text="Contours (ticked: wires)")
        layout.template_list(WIRESCULPT_UL_contours.__name__, "", settings, "contours",
                             settings, "active_contour", rows=4)
        if 0 <= settings.active_contour < len(settings.contours):
            wrap_labels(layout.box(), context,
                        contour_details(context.scene, settings.contours[settings.active_contour]), icon='INFO')


register, unregister = classes_factory(
    (WIRESCULPT_UL_contours, VIEW3D_PT_wiresculpt))
