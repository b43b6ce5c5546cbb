"""Calibration (Sec. 5.1-5.2): load the cantilever, tilt and spring-back captures (CSV), show each
fit as a small plot, save the calibrated material (JSON in the user's config folder, listed with
the presets) and the machine profile with its spring-back line (JSON). Formats: docs/calibration.md.
"""
import json
import os

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from .. import native
from ..blend.calibration import (PLOT_IMAGE, config_folder, load_plot, results, springback_table, store,
                                 use_material)
from ..blend.registration import classes_factory
from ..core import calibration as cal
from ..props import KINDS, material_items, material_of, solver_settings



def base_material(scene):
    """The material in the Material & Machine panel (diameter and density for the weight)."""
    return material_of(scene.wiresculpt)


class WIRESCULPT_OT_calibration_load(bpy.types.Operator, ImportHelper):
    """Load a calibration capture (CSV) and fit it"""
    bl_idname = "wiresculpt.calibration_load"
    bl_label = "Load Capture"
    bl_options = {'REGISTER'}

    filename_ext = ".csv"
    filter_glob: StringProperty(default="*.csv;*.txt", options={'HIDDEN'})
    kind: EnumProperty(name="Capture", items=KINDS, default="CANTILEVER")

    def execute(self, context):
        if not native.available():
            self.report({'ERROR'}, native.LOAD_ERROR)
            return {'CANCELLED'}
        scene = context.scene
        settings = scene.wiresculpt_calibration
        path = self.filepath
        name = os.path.basename(path)
        try:
            if self.kind == 'CANTILEVER':
                fit = cal.fit_cantilever(path, settings.overhang, plastic_tolerance=settings.plastic_tolerance,
                                         material=base_material(scene), include_weight=settings.include_weight)
                png = cal.plot_cantilever(fit)
                text = (f"k_b {fit['bending_stiffness']:.4g} N m², position RMS {fit['position_rms'] * 1000:.2f} mm"
                        + (f", plastic torque {fit['max_torque']:.3g} N m at {fit['plastic_load_g']:g} g"
                           if fit["plastic_found"] else ", no unloaded rows: plastic limit not measured"))
            elif self.kind == 'TILT':
                table = cal.read_tilt(path)
                fit = cal.fit_friction(path)
                png = cal.plot_friction(table, fit)
                text = f"friction {fit['friction']:.3f} ± {fit['spread']:.3f} over {fit['repeats']} repeats"
            else:
                table = cal.read_springback(path)
                fit = cal.fit_springback(path)
                png = cal.plot_springback(table, fit)
                text = (f"measured = {fit['springback_a']:.4f} × commanded {fit['springback_b_deg']:+.3f}°, "
                        f"RMS {fit['rms_deg']:.3f}°, max {fit['max_residual_deg']:.3f}°")
        except (ValueError, OSError) as exc:
            self.report({'ERROR'}, f"{name}: {exc}")
            return {'CANCELLED'}
        fit["source"] = path
        store(scene, self.kind.lower(), fit)
        try:
            load_plot(self.kind, png)
        except (OSError, RuntimeError) as exc:
            self.report({'WARNING'}, f"Cannot show the plot: {exc}")
        settings.plot = self.kind
        warnings = fit.get("warnings") or []
        self.report({'WARNING'} if warnings else {'INFO'}, "; ".join([f"{name}: {text}"] + warnings))
        return {'FINISHED'}


class WIRESCULPT_OT_calibration_fit_rows(bpy.types.Operator):
    """Fit the spring-back line to the rows' commanded and measured angles (the test piece's bends;
    rows whose measured angle is 0 are left out)"""
    bl_idname = "wiresculpt.calibration_fit_rows"
    bl_label = "Fit Spring-back from Rows"
    bl_options = {'REGISTER'}

    def execute(self, context):
        if not native.available():
            self.report({'ERROR'}, native.LOAD_ERROR)
            return {'CANCELLED'}
        scene = context.scene
        table = springback_table(scene)
        try:
            fit = native.fit_springback(table["commanded_deg"], table["measured_deg"], table["lines"])
        except ValueError as exc:
            self.report({'ERROR'}, f"Spring-back rows: {exc}")
            return {'CANCELLED'}
        fit["warnings"] = cal.springback_warnings(table["commanded_deg"])
        fit["source"] = "the test bends' rows"
        store(scene, "springback", fit)
        try:
            load_plot("SPRINGBACK", cal.plot_springback(table, fit))
        except (OSError, RuntimeError) as exc:
            self.report({'WARNING'}, f"Cannot show the plot: {exc}")
        scene.wiresculpt_calibration.plot = "SPRINGBACK"
        text = (f"rows: measured = {fit['springback_a']:.4f} × commanded {fit['springback_b_deg']:+.3f}°, "
                f"RMS {fit['rms_deg']:.3f}° over {fit['samples']} bends")
        self.report({'WARNING'} if fit["warnings"] else {'INFO'}, "; ".join([text] + fit["warnings"]))
        return {'FINISHED'}


class WIRESCULPT_OT_calibration_save_material(bpy.types.Operator):
    """Save the calibrated material (stiffness and plastic torque from the cantilever, friction from the
    tilt) to the user's config folder; it is listed with the presets"""
    bl_idname = "wiresculpt.calibration_save_material"
    bl_label = "Save Material"
    bl_options = {'REGISTER'}

    def execute(self, context):
        scene = context.scene
        r = results(scene)
        if "cantilever" not in r and "tilt" not in r:
            self.report({'ERROR'}, "Load a cantilever or tilt capture first")
            return {'CANCELLED'}
        try:
            m = cal.calibrated_material(scene.wiresculpt_calibration.material_name, base_material(scene),
                                        r.get("cantilever"), r.get("tilt"))
            path = cal.save_material(m, config_folder())
        except (ValueError, OSError) as exc:
            self.report({'ERROR'}, f"Cannot save the material: {exc}")
            return {'CANCELLED'}
        self.report({'INFO'}, f"Material '{m['name']}' saved: {path}")
        return {'FINISHED'}


class WIRESCULPT_OT_calibration_use_material(bpy.types.Operator):
    """Use a material: a Table 1 preset or one you calibrated"""
    bl_idname = "wiresculpt.calibration_use_material"
    bl_label = "Use Material"
    bl_options = {'REGISTER', 'UNDO'}
    bl_property = "material"

    material: EnumProperty(name="Material", items=material_items)

    def execute(self, context):
        found, _errors = cal.list_materials(config_folder())
        m = found.get(self.material)
        if m is None:
            self.report({'ERROR'}, f"No material '{self.material}'")
            return {'CANCELLED'}
        use_material(context.scene, m)
        self.report({'INFO'}, f"Material: {m['name']}")
        return {'FINISHED'}


class WIRESCULPT_OT_calibration_save_profile(bpy.types.Operator, ExportHelper):
    """Save a machine profile (limits, axes, serial settings and the spring-back fit) as JSON"""
    bl_idname = "wiresculpt.calibration_save_profile"
    bl_label = "Save Machine Profile"
    bl_options = {'REGISTER'}

    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={'HIDDEN'})

    def execute(self, context):
        if not native.available():
            self.report({'ERROR'}, native.LOAD_ERROR)
            return {'CANCELLED'}
        scene = context.scene
        try:
            profile = cal.default_profile()
            limits = solver_settings(scene.wiresculpt)
            profile.update({k: limits[k] for k in ("min_segment", "max_bend_deg", "min_bend_deg")})
            fit = results(scene).get("springback")
            if fit:
                profile = cal.with_springback(profile, fit, fit.get("source", ""))
            cal.save_profile(profile, self.filepath)
        except (ValueError, OSError) as exc:
            self.report({'ERROR'}, f"Cannot save the machine profile: {exc}")
            return {'CANCELLED'}
        # the profile just saved is the one Export and Send to Machine use from now on
        scene.wiresculpt.machine_profile = self.filepath
        note = "with the spring-back fit" if fit else "without a spring-back fit (load one first)"
        self.report({'INFO'}, f"Machine profile saved {note} and selected for fabrication: {self.filepath}")
        return {'FINISHED'}


class WIRESCULPT_OT_calibration_show_plot(bpy.types.Operator):
    """Open the fit's plot in an Image Editor"""
    bl_idname = "wiresculpt.calibration_show_plot"
    bl_label = "Open Plot"
    bl_options = {'REGISTER'}

    kind: EnumProperty(name="Capture", items=KINDS, default="CANTILEVER")

    def execute(self, context):
        image = bpy.data.images.get(PLOT_IMAGE[self.kind])
        if image is None:
            self.report({'ERROR'}, "No plot yet: load the capture first")
            return {'CANCELLED'}
        screen = context.window.screen if context.window else None
        areas = [a for a in screen.areas if a.type == 'IMAGE_EDITOR'] if screen else []
        if not areas and screen is not None:
            try:
                bpy.ops.wm.window_new()
                areas = [context.window_manager.windows[-1].screen.areas[0]]
                areas[0].ui_type = 'IMAGE_EDITOR'
            except (RuntimeError, IndexError):
                areas = []
        if not areas:
            self.report({'WARNING'}, f"Open an Image Editor and pick '{image.name}'")
            return {'FINISHED'}
        areas[0].spaces.active.image = image
        self.report({'INFO'}, f"Showing '{image.name}'")
        return {'FINISHED'}


register, unregister = classes_factory(
    (WIRESCULPT_OT_calibration_load, WIRESCULPT_OT_calibration_fit_rows, WIRESCULPT_OT_calibration_save_material, WIRESCULPT_OT_calibration_use_material,
     WIRESCULPT_OT_calibration_save_profile, WIRESCULPT_OT_calibration_show_plot))
