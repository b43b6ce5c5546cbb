"""The plane assistant's panel, under the Wire panel: Find Stable Planes, Suggest
Planes, and up to three candidates with what changes, their figures, Preview (an eye, pressed while
shown) and Apply."""
import bpy

from .. import native
from ..blend.registration import classes_factory
from ..operators import plane_search as ops
from .panel import VIEW3D_PT_wiresculpt, wrap_labels


def candidate_lines(candidate):
    """What the panel says of a candidate: its changes (or the planes' families), its figures and how
    it looks like the model (fidelity beside coverage)."""
    return ((candidate["changes"] or ["the planes as they are"]) + [ops.describe(candidate)]
            + [line for line in (ops.looks(candidate),) if line])


class VIEW3D_PT_wiresculpt_planes(bpy.types.Panel):
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "Wire"
    bl_parent_id = VIEW3D_PT_wiresculpt.__name__
    bl_label = "Plane Assistant"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        col = layout.column(align=True)
        col.enabled = native.available() and not ops.running()
        col.operator(ops.WIRESCULPT_OT_find_planes.bl_idname, icon='VIEWZOOM')
        row = col.row(align=True)
        row.operator(ops.WIRESCULPT_OT_suggest_planes.bl_idname, icon='LIGHTPROBE_PLANAR')
        row.prop(context.scene.wiresculpt, "plane_count")  # how many planes Suggest Planes proposes
        job = ops.JOB
        if job is not None:
            box = layout.box()
            box.label(text=job.status().replace("wiresculpt: ", ""), icon='SORTTIME')
            for line in job.messages[-2:]:
                wrap_labels(box, context, line)
            box.operator(ops.WIRESCULPT_OT_find_planes_cancel.bl_idname, icon='CANCEL')
            return
        result = ops.current(context)  # another file's or scene's result is not shown
        if result is None:
            return
        wrap_labels(layout, context, result["message"], icon='INFO')
        shown = ops.previewed(context)
        for k, candidate in enumerate(result["candidates"]):
            box = layout.box()
            for i, line in enumerate(candidate_lines(candidate)):
                wrap_labels(box, context, line, icon='CHECKMARK' if i == 0 else 'NONE')
            row = box.row(align=True)
            # the eye alone (its tooltip says what it does): "Preview" beside "Apply candidate k"
            # would cut both labels in a sidebar of the default width
            row.operator(ops.WIRESCULPT_OT_preview_planes.bl_idname, text="", icon='HIDE_OFF',
                         depress=shown == k).index = k
            row.operator(ops.WIRESCULPT_OT_apply_planes.bl_idname, text=f"Apply candidate {k + 1}").index = k
        if shown is not None:
            layout.operator(ops.WIRESCULPT_OT_preview_planes_clear.bl_idname, icon='X')


register, unregister = classes_factory((VIEW3D_PT_wiresculpt_planes,))
