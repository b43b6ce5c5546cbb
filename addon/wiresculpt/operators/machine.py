"""The Machine panel's operators (docs/user-guide.md, Machine): connect to the bender's GRBL and keep
the link open, its status line (GRBL's `?` report, polled by a timer), feed hold and resume, home
($H), unlock ($X), jogs of the feed and bend axes, one console line, and the spring-back test
piece. While a wire is being sent, Hold and Resume act on the stream (its feed hold), and the other
commands wait for it to end. In background mode (batch, tests) a command waits for its answer
inside execute(); with a window the timer reads the answers and the panel shows them.
"""
import bpy
from bpy.props import EnumProperty, FloatProperty, StringProperty

from .. import native
from ..blend.machine import chosen_profile
from ..blend.registration import classes_factory
from ..core import machine_words as words
from ..fab import grbl, streaming

POLL_EVERY = 0.2  # s between the timer's reads of the link
WAIT = {"$H": 120.0}  # s a background command waits for its answer (a homing cycle takes long)
WAIT_DEFAULT = 5.0


def _redraw():
    for window in getattr(bpy.context.window_manager, "windows", []):
        for area in window.screen.areas:
            if area.type == 'VIEW_3D':
                area.tag_redraw()


def _poll_session():
    """The timer: reads the session's link (not while a stream runs on it), redraws the panel."""
    session = grbl.SESSION
    if session is None:
        return None  # disconnected: the timer ends
    job = streaming.JOB
    if not (job is not None and job.link is session.link) and not session.lost:
        try:
            session.poll()
        except (RuntimeError, ValueError, OSError):
            session.lost = True
    _redraw()
    return POLL_EVERY


def _start_timer():
    if not bpy.app.timers.is_registered(_poll_session):
        bpy.app.timers.register(_poll_session, first_interval=POLL_EVERY, persistent=True)


def _session(op):
    """The connected session, or None after reporting why not."""
    session = grbl.SESSION
    if session is None or session.lost:
        op.report({'ERROR'}, words.refusal(words.NOT_CONNECTED))
        return None
    return session


def _send(op, session, line):
    """Sends one line; in background mode waits for its answer. The Command, or None (reported)."""
    job = streaming.JOB
    if job is not None:
        op.report({'ERROR'}, words.refusal(words.STREAMING))
        return None
    try:
        command = session.send(line)
    except ValueError as exc:
        op.report({'ERROR'}, f"Not sent: {words.line_fault(exc.args[0])}")
        return None
    if bpy.app.background:
        session.wait(command, WAIT.get(line.upper(), WAIT_DEFAULT))
        text = f"{line}: {words.answer_line(command.answer, command.code, command.info)}"
        op.report({'INFO'} if command.answer == grbl.OK else {'ERROR'}, text)
    return command


class WIRESCULPT_OT_machine_connect(bpy.types.Operator):
    """Open the link to the bender's GRBL on the Fabrication panel's port and keep it open (status,
    jogs, console; Send then streams on it, so GRBL is not restarted between them)"""
    bl_idname = "wiresculpt.machine_connect"
    bl_label = "Connect"
    bl_options = {'REGISTER'}

    port: StringProperty(name="Port", default="", description="Serial port (empty: the Fabrication panel's)")
    settle: FloatProperty(name="Settle", default=2.0, min=0.0, max=30.0,
                          description="Seconds GRBL gets to restart after the port opens (seconds)")

    def execute(self, context):
        if not native.available():
            self.report({'ERROR'}, native.LOAD_ERROR)
            return {'CANCELLED'}
        port = (self.port or context.scene.wiresculpt.fab_port).strip()
        if not port:
            self.report({'ERROR'}, "Cannot connect: no serial port chosen: pick one or type its path")
            return {'CANCELLED'}
        if streaming.running():
            self.report({'ERROR'}, words.refusal(words.STREAMING))
            return {'CANCELLED'}
        try:
            grbl.connect(port, chosen_profile(context.scene), self.settle)
        except (ValueError, RuntimeError) as exc:
            self.report({'ERROR'}, f"Cannot connect: {exc}")
            return {'CANCELLED'}
        if not bpy.app.background:
            _start_timer()
        self.report({'INFO'}, f"Connected to {port}")
        return {'FINISHED'}


class WIRESCULPT_OT_machine_disconnect(bpy.types.Operator):
    """Close the link to the bender"""
    bl_idname = "wiresculpt.machine_disconnect"
    bl_label = "Disconnect"
    bl_options = {'REGISTER'}

    @classmethod
    def poll(cls, context):
        return grbl.SESSION is not None and not streaming.running()

    def execute(self, context):
        grbl.disconnect()
        return {'FINISHED'}


REALTIME = (("HOLD", "Hold", "Feed hold (!): the machine stops its moves, decelerating; Resume goes on"),
            ("RESUME", "Resume", "Cycle start (~): the held moves go on"),
            ("STATUS", "Status", "Ask GRBL for its status report (?) now"))
BYTES = {"HOLD": b"!", "RESUME": b"~", "STATUS": b"?"}


class _CommandDescribed:
    """An operator whose `command` is one of CHOICES: its tooltip is the chosen item's description."""
    CHOICES = ()

    @classmethod
    def description(cls, context, properties):
        return dict((k, d) for k, _n, d in cls.CHOICES)[properties.command]


class WIRESCULPT_OT_machine_realtime(_CommandDescribed, bpy.types.Operator):
    """Feed hold, resume or a status query: sent at once, also while a wire is being sent"""
    bl_idname = "wiresculpt.machine_realtime"
    bl_label = "Machine Command"
    bl_options = {'REGISTER'}

    CHOICES = REALTIME
    command: EnumProperty(name="Command", items=REALTIME, default="STATUS")

    def execute(self, context):
        job = streaming.JOB
        if job is not None and self.command in ("HOLD", "RESUME"):  # the stream's own feed hold
            if self.command == "HOLD":
                streaming.hold(job)
            else:
                streaming.go_on(job)
            return {'FINISHED'}
        session = _session(self)
        if session is None:
            return {'CANCELLED'}
        if job is not None and job.link is session.link:
            self.report({'ERROR'}, words.refusal(words.STREAMING))
            return {'CANCELLED'}
        if self.command == "STATUS" and bpy.app.background:
            status = session.query()
            self.report({'INFO'}, words.status_line(status, *(grbl.machine_position(status, session.profile)
                                                              if status else (None, None))))
            return {'FINISHED'}
        if not session.realtime(BYTES[self.command]):
            self.report({'ERROR'}, words.ANSWERS[grbl.LOST])
            return {'CANCELLED'}
        return {'FINISHED'}


LINES = (("HOME", "Home", "Home the machine ($H): the axes run to their switches"),
         ("UNLOCK", "Unlock", "Clear GRBL's alarm lock ($X), after checking the machine"))
COMMAND_LINES = {"HOME": "$H", "UNLOCK": "$X"}


class WIRESCULPT_OT_machine_command(_CommandDescribed, bpy.types.Operator):
    """Home ($H) or unlock ($X) the machine"""
    bl_idname = "wiresculpt.machine_command"
    bl_label = "Machine Command"
    bl_options = {'REGISTER'}

    CHOICES = LINES
    command: EnumProperty(name="Command", items=LINES, default="HOME")

    def execute(self, context):
        session = _session(self)
        if session is None:
            return {'CANCELLED'}
        command = _send(self, session, COMMAND_LINES[self.command])
        return {'CANCELLED'} if command is None or command.answer not in (None, grbl.OK) else {'FINISHED'}


class WIRESCULPT_OT_machine_jog(bpy.types.Operator):
    """Jog the feed (millimetres of wire) or the bend head (degrees, left positive) by the panel's step"""
    bl_idname = "wiresculpt.machine_jog"
    bl_label = "Jog"
    bl_options = {'REGISTER'}

    axis: EnumProperty(name="Axis", items=((grbl.FEED, "Feed", "The feed rollers"),
                                           (grbl.BEND, "Bend", "The bend head")), default=grbl.FEED)
    direction: FloatProperty(name="Direction", default=1.0, min=-1.0, max=1.0,
                             description="+1 forward or left, -1 back or right")

    def execute(self, context):
        session = _session(self)
        if session is None:
            return {'CANCELLED'}
        ws = context.scene.wiresculpt
        step = ws.machine_jog_feed if self.axis == grbl.FEED else ws.machine_jog_bend
        try:
            line = grbl.jog_line(self.axis, self.direction * step, session.profile)
        except ValueError as exc:
            self.report({'ERROR'}, f"Cannot jog: {exc}")
            return {'CANCELLED'}
        command = _send(self, session, line)
        return {'CANCELLED'} if command is None or command.answer not in (None, grbl.OK) else {'FINISHED'}


class WIRESCULPT_OT_machine_console(bpy.types.Operator):
    """Send the console line to GRBL; its answer shows under it"""
    bl_idname = "wiresculpt.machine_console"
    bl_label = "Send Line"
    bl_options = {'REGISTER'}

    def execute(self, context):
        session = _session(self)
        if session is None:
            return {'CANCELLED'}
        command = _send(self, session, context.scene.wiresculpt.machine_console.strip())
        return {'CANCELLED'} if command is None or command.answer not in (None, grbl.OK) else {'FINISHED'}


class WIRESCULPT_OT_machine_test_bends(bpy.types.Operator):
    """Bend the spring-back test piece: a straight wire with bends of known commanded angles; measure
    them and type the angles into the Calibration panel's rows"""
    bl_idname = "wiresculpt.machine_test_bends"
    bl_label = "Test Bends"
    bl_options = {'REGISTER'}

    @classmethod
    def poll(cls, context):
        return not streaming.running()

    def execute(self, context):
        if not native.available():
            self.report({'ERROR'}, native.LOAD_ERROR)
            return {'CANCELLED'}
        scene = context.scene
        try:
            profile = chosen_profile(scene)
            _lines, _machine, commanded, length = grbl.test_bend_program(profile)
        except (ValueError, RuntimeError) as exc:
            self.report({'ERROR'}, f"Cannot make the test bends: {exc}")
            return {'CANCELLED'}
        ws = scene.wiresculpt
        material = ws.material_preset if ws.material_preset != 'CUSTOM' else "wire"
        facts = {"length_mm": 1000.0 * length, "diameter_mm": 1000.0 * ws.wire_diameter, "material": material,
                 "angles": [round(a, 3) for a in commanded if a]}
        streaming.LOAD = streaming.Load(grbl.TEST_NAME, facts, kind="test")
        self.report({'INFO'}, " ".join(words.test_piece_lines(facts)))
        return {'FINISHED'}


_register, _unregister = classes_factory(
    (WIRESCULPT_OT_machine_connect, WIRESCULPT_OT_machine_disconnect, WIRESCULPT_OT_machine_realtime,
     WIRESCULPT_OT_machine_command, WIRESCULPT_OT_machine_jog, WIRESCULPT_OT_machine_console,
     WIRESCULPT_OT_machine_test_bends))


def register():
    _register()


def unregister():
    if bpy.app.timers.is_registered(_poll_session):
        bpy.app.timers.unregister(_poll_session)
    grbl.disconnect()
    _unregister()
