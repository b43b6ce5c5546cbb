"""The Machine sub-panel of the Wire tab (docs/user-guide.md, Machine): connect to the bender's GRBL,
its status line, Hold / Resume / Home / Unlock, jogs of the feed and bend axes, a console line
and its answer, and the spring-back test piece."""
import bpy

from .. import native
from ..blend.registration import classes_factory
from ..core import machine_words as words
from ..fab import grbl, streaming
from ..operators import machine as ops
from .fabrication import draw_load, draw_stop
from .results import _Child, _wrap


def status_text(session):
    """The status line of a session (its last report, in the profile's units)."""
    if session.lost:
        return "Link lost: Disconnect, then Connect again"
    status = session.status
    feed, bend = grbl.machine_position(status, session.profile) if status else (None, None)
    line = words.status_line(status, feed, bend)
    if session.alarm:
        line += f" · last {words.grbl_alarm(session.alarm)}"
    return line


class VIEW3D_PT_wiresculpt_machine(_Child, bpy.types.Panel):
    bl_label = "Machine"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.enabled = native.available()
        ws = context.scene.wiresculpt
        session = grbl.SESSION
        job = streaming.JOB
        if session is None:
            row = layout.row(align=True)
            row.prop(ws, "fab_port", text="")
            row.operator(ops.WIRESCULPT_OT_machine_connect.bl_idname, icon='LINKED')
        else:
            row = layout.row(align=True)
            row.label(text=session.port, icon='LINKED')
            row.operator(ops.WIRESCULPT_OT_machine_disconnect.bl_idname, text="", icon='UNLINKED')
            box = layout.box()
            streaming_here = job is not None and job.link is session.link
            text = job.status().replace("wiresculpt: ", "") if streaming_here else status_text(session)
            box.alert = session.lost or (session.status or {}).get("state") == "Alarm"
            _wrap(box, context, text, icon='INFO')
        row = layout.row(align=True)
        for command, icon in (("HOLD", 'PAUSE'), ("RESUME", 'PLAY')):
            row.operator(ops.WIRESCULPT_OT_machine_realtime.bl_idname, text=command.title(),
                         icon=icon).command = command
        row = layout.row(align=True)
        row.enabled = session is not None and job is None
        row.operator(ops.WIRESCULPT_OT_machine_command.bl_idname, text="Home", icon='HOME').command = "HOME"
        row.operator(ops.WIRESCULPT_OT_machine_command.bl_idname, text="Unlock", icon='UNLOCKED').command = "UNLOCK"

        col = layout.column(align=True)
        col.enabled = session is not None and job is None
        for axis, prop, unit in ((grbl.FEED, "machine_jog_feed", "mm"), (grbl.BEND, "machine_jog_bend", "°")):
            row = col.row(align=True)
            back = row.operator(ops.WIRESCULPT_OT_machine_jog.bl_idname, text="", icon='TRIA_LEFT')
            back.axis, back.direction = axis, -1.0
            row.prop(ws, prop, text=f"{axis.title()} ({unit})")
            on = row.operator(ops.WIRESCULPT_OT_machine_jog.bl_idname, text="", icon='TRIA_RIGHT')
            on.axis, on.direction = axis, 1.0

        col = layout.column(align=True)
        col.enabled = session is not None and job is None
        row = col.row(align=True)
        row.prop(ws, "machine_console", text="")
        row.operator(ops.WIRESCULPT_OT_machine_console.bl_idname, text="", icon='CONSOLE')
        if session is not None:
            for command in session.log[-3:]:
                _wrap(col, context, f"{command.line}  →  {words.answer_line(command.answer, command.code, command.info)}")

        load = streaming.LOAD
        stopped = streaming.PENDING.get(grbl.TEST_NAME)
        last = streaming.LAST.get(grbl.TEST_NAME)
        if job is None and stopped is not None and stopped.facts is not None:
            draw_stop(layout, context, stopped.facts)  # the test piece's stop: its Resume is here
        elif job is None and last is not None and last[0] == {'INFO'}:
            _wrap(layout.box(), context, last[1], icon='INFO')
        if load is not None and load.kind == "test" and job is None:
            draw_load(layout, context, load)  # the test piece needs no design: its Continue is here too
        else:
            layout.operator(ops.WIRESCULPT_OT_machine_test_bends.bl_idname, icon='DRIVER_ROTATIONAL_DIFFERENCE')


register, unregister = classes_factory((VIEW3D_PT_wiresculpt_machine,))
