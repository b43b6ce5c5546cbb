"""The Calibration sub-panel of the Wire tab: load the three captures, read the fits and their
plot, save the material and the machine profile, pick a material (presets and calibrated ones)."""
import bpy

from .. import native
from ..blend.calibration import MATERIAL_NAME_KEY
from ..blend.registration import classes_factory
from ..operators import calibration as ops
from .panel import VIEW3D_PT_wiresculpt


def summary_lines(r):
    """Short text lines of the stored fits (no UI)."""
    lines = []
    c = r.get("cantilever")
    if c:
        lines.append(f"k_b {c['bending_stiffness']:.4g} N m²  (RMS {c['position_rms'] * 1000:.2f} mm, "
                     f"{c['frames_used']} loads)")
        if c.get("plastic_found"):
            bound = "" if c.get("plastic_reached") else " (at least)"
            lines.append(f"Plastic torque {c['max_torque']:.3g} N m{bound} at {c['plastic_load_g']:g} g")
        else:
            lines.append("Plastic limit: no unloaded rows")
    t = r.get("tilt")
    if t:
        lines.append(f"Friction {t['friction']:.3f} ± {t['spread']:.3f} ({t['repeats']} repeats)")
    s = r.get("springback")
    if s:
        lines.append(f"Spring-back a {s['springback_a']:.4f}, b {s['springback_b_deg']:+.3f}°")
        lines.append(f"   RMS {s['rms_deg']:.3f}°, max {s['max_residual_deg']:.3f}° ({s['samples']} bends)")
    return lines


class VIEW3D_PT_wiresculpt_calibration(bpy.types.Panel):
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "Wire"
    bl_parent_id = VIEW3D_PT_wiresculpt.__name__
    bl_label = "Calibration"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        scene = context.scene
        settings = scene.wiresculpt_calibration
        col = layout.column(align=True)
        col.use_property_split = True
        col.use_property_decorate = False
        col.prop(settings, "overhang")
        col.prop(settings, "plastic_tolerance")
        col.prop(settings, "include_weight")
        col = layout.column(align=True)
        col.enabled = native.available()
        for kind, label, _text in ops.KINDS:
            col.operator(ops.WIRESCULPT_OT_calibration_load.bl_idname, text=f"Load {label} CSV",
                         icon='IMPORT').kind = kind
        rows = settings.springback_rows
        if len(rows):  # the test piece's bends: type each measured angle, then fit
            box = layout.box()
            box.label(text="Spring-back rows (commanded → measured)")
            col = box.column(align=True)
            for row in rows:
                line = col.row(align=True)
                line.label(text=f"{row.commanded_deg:g}°")
                line.prop(row, "measured_deg", text="")
            box.operator(ops.WIRESCULPT_OT_calibration_fit_rows.bl_idname, icon='CHECKMARK')
        r = ops.results(scene)
        lines = summary_lines(r)
        if lines:
            box = layout.box()
            for line in lines:
                box.label(text=line)
        kinds = [k for k, _label, _t in ops.KINDS if k.lower() in r]
        if kinds:
            row = layout.row(align=True)
            row.prop(settings, "plot", expand=True)
            image = bpy.data.images.get(ops.PLOT_IMAGE[settings.plot])
            if image is not None:
                try:
                    image.preview_ensure()
                    layout.template_icon(icon_value=image.preview.icon_id, scale=10.0)
                except (AttributeError, RuntimeError):
                    pass
                layout.operator(ops.WIRESCULPT_OT_calibration_show_plot.bl_idname, icon='IMAGE').kind = settings.plot
        col = layout.column(align=True)
        col.prop(settings, "material_name")
        col.operator(ops.WIRESCULPT_OT_calibration_save_material.bl_idname, icon='FILE_TICK')
        layout.operator_menu_enum(ops.WIRESCULPT_OT_calibration_use_material.bl_idname, "material",
                                  text=f"Material: {scene.get(MATERIAL_NAME_KEY, 'choose')}", icon='MATERIAL')
        layout.operator(ops.WIRESCULPT_OT_calibration_save_profile.bl_idname, icon='EXPORT')


register, unregister = classes_factory((VIEW3D_PT_wiresculpt_calibration,))
