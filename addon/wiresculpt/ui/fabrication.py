"""The Fabrication sub-panel of the Wire tab: machine profile, Export, and Send to Machine with its
port, wire, progress, Cancel and Resume."""
import bpy

from .. import native
from ..blend import preview
from ..blend import results as scene_results
from ..blend.registration import classes_factory
from ..core import machine_words as words
from ..fab import streaming
from ..operators import fabrication as ops
from .results import _Child, _wrap
from .stale import report_changes

# above Export and Send when the Stability box says "From an earlier Optimize: …"
EARLIER_DESIGN = "These files follow the earlier Optimize the Stability box shows, not the scene now: Optimize again first"


class VIEW3D_PT_wiresculpt_fabrication(_Child, bpy.types.Panel):
    bl_label = "Fabrication"

    @classmethod
    def poll(cls, context):
        return scene_results.stored_design() is not None

    def draw(self, context):
        layout = self.layout
        layout.enabled = native.available()
        ws = context.scene.wiresculpt
        layout.prop(ws, "machine_profile", text="Profile")
        if report_changes(context):  # the files would follow a design the scene no longer matches
            _wrap(layout, context, EARLIER_DESIGN, icon='ERROR')
        layout.operator(ops.WIRESCULPT_OT_export_fabrication.bl_idname, text="Export…", icon='EXPORT')
        rows, model = preview.figures(context.scene)
        if rows:  # the last export's machine preview: how far each predicted wire is from its rest shape
            box = layout.box()
            box.label(text="Machine preview", icon='HIDE_OFF')
            col = box.column(align=True)
            for name, mm in rows:
                col.label(text=f"{name}: {mm:.1f} mm off")
            if model is not None:
                col.label(text="Spring-back fit used:")
                col.label(text=f"a {model[0]:.4f}, b {model[1]:+.2f}°")

        box = layout.box()
        box.label(text="Send to Machine", icon='PLUGIN')
        row = box.row(align=True)
        row.prop(ws, "fab_port", text="")
        row.operator_menu_enum(ops.WIRESCULPT_OT_pick_port.bl_idname, "port", text="", icon='DOWNARROW_HLT')
        box.prop(ws, "fab_wire", text="Wire")
        box.prop(ws, "fab_dry_run")
        job = streaming.JOB
        if job is not None:
            status = box.box()
            _wrap(status, context, job.status().replace("wiresculpt: ", ""), icon='SORTTIME')
            row = status.row(align=True)
            paused = job.control.paused
            row.operator(ops_machine_realtime, text="Resume" if paused else "Hold",
                         icon='PLAY' if paused else 'PAUSE').command = "RESUME" if paused else "HOLD"
            row.operator(ops.WIRESCULPT_OT_send_cancel.bl_idname, icon='CANCEL')
            return
        load = streaming.LOAD
        if load is not None:  # the "load the wire" step: Continue sends it
            draw_load(box, context, load)
            return
        stopped = streaming.PENDING.get(ws.fab_wire)
        col = box.column(align=True)
        row = col.row(align=True)
        send = row.operator(ops.WIRESCULPT_OT_send_to_machine.bl_idname,
                            text="Send from Start" if stopped else "Send", icon='PLAY')
        send.resume = False
        row.operator(ops.WIRESCULPT_OT_send_all.bl_idname, text="Send All", icon='SEQ_STRIP_DUPLICATE')
        if stopped is not None and stopped.facts is not None:
            draw_stop(box, context, stopped.facts)
            return
        if stopped is not None:
            resume = col.operator(ops.WIRESCULPT_OT_send_to_machine.bl_idname,
                                  text=f"Resume at Line {stopped.next_line + 1}", icon='FORWARD')
            resume.resume = True
        last = streaming.LAST.get(ws.fab_wire)
        if last is not None:
            kind, message = last
            status = box.box()
            status.alert = kind == {'ERROR'}
            _wrap(status, context, message, icon='INFO' if kind == {'INFO'} else 'ERROR')


ops_machine_realtime = "wiresculpt.machine_realtime"  # the Machine panel's Hold / Resume (operators/machine.py)


def draw_stop(layout, context, facts):
    """A stopped stream as a box of short lines (each wrapped to the sidebar) and its Resume button."""
    box = layout.box()
    box.alert = facts["status"] != "aborted"
    col = box.column(align=True)
    for k, line in enumerate(words.stop_lines(facts)):
        _wrap(col, context, line, icon='ERROR' if k == 0 else 'BLANK1')
    resume = box.operator(ops.WIRESCULPT_OT_send_to_machine.bl_idname, text=words.resume_button(facts),
                          icon='FORWARD')
    resume.resume = True
    resume.wire = facts["wire"]
    resume.test = facts.get("test", False)


def draw_load(layout, context, load):
    """The "load the wire" step: which wire, stock and length; Continue sends it, Skip does not."""
    box = layout.box()
    col = box.column(align=True)
    lines = words.test_piece_lines(load.facts) if load.kind == "test" else words.load_lines(load.facts)
    for k, line in enumerate(lines):
        _wrap(col, context, line, icon='IMPORT' if k == 0 else 'BLANK1')
    row = box.row(align=True)
    go = row.operator(ops.WIRESCULPT_OT_send_to_machine.bl_idname, text="Continue", icon='PLAY')
    go.wire, go.loaded, go.resume, go.test = load.wire, True, False, load.kind == "test"
    row.operator(ops.WIRESCULPT_OT_load_cancel.bl_idname, text="Skip", icon='X')


register, unregister = classes_factory((VIEW3D_PT_wiresculpt_fabrication,))
