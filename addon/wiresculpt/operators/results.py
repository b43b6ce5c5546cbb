"""Results: the assembly guide of the design stored in the scene, and clearing the results."""
import os

import bpy

from ..blend import guide as assembly_guide
from ..blend import results as scene_results
from ..blend.machine import chosen_profile
from ..blend.registration import classes_factory
from ..core import calibration as cal


class WIRESCULPT_OT_assembly_guide(bpy.types.Operator):
    """Write a printable assembly guide (index.html, one picture per step) to the guide folder"""
    bl_idname = "wiresculpt.assembly_guide"
    bl_label = "Write Assembly Guide"
    bl_options = {'REGISTER'}

    def execute(self, context):
        scene = context.scene
        design = scene_results.stored_design()
        if design is None:
            self.report({'ERROR'}, "No design yet: press Optimize first")
            return {'CANCELLED'}
        folder = scene.wiresculpt.guide_folder
        if folder.startswith("//") and not bpy.data.filepath:
            self.report({'ERROR'}, "Save the .blend first, or give the guide folder as a full path")
            return {'CANCELLED'}
        folder = os.path.normpath(bpy.path.abspath(folder))
        try:
            overlap = cal.closed_overlap(chosen_profile(scene))  # the profile Export uses
            path = assembly_guide.write_guide(scene, design, folder, overlap=overlap)
        except (ValueError, RuntimeError, OSError) as exc:
            self.report({'ERROR'}, f"Cannot write the assembly guide: {exc}")
            return {'CANCELLED'}
        self.report({'INFO'}, f"Assembly guide written: {path}")
        return {'FINISHED'}


class WIRESCULPT_OT_clear_results(bpy.types.Operator):
    """Remove the wire curves, crossing markers and the stored design"""
    bl_idname = "wiresculpt.clear_results"
    bl_label = "Clear Results"
    bl_options = {'REGISTER', 'UNDO'}

    def execute(self, context):
        if scene_results.stored_design() is None and not scene_results.tagged(context.scene,
                                                                               scene_results.WIRE_KEY):
            self.report({'INFO'}, "Nothing to clear")
            return {'CANCELLED'}
        scene_results.clear_results(context.scene)
        self.report({'INFO'}, "Removed the wires, markers and the stored design")
        return {'FINISHED'}


register, unregister = classes_factory(
    (WIRESCULPT_OT_assembly_guide, WIRESCULPT_OT_clear_results))
