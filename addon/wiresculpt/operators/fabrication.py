"""Fabrication (Sec. 5.1): Export writes every wire's SVG, DXF, G-code and bend table into a
folder; Send to Machine streams one wire's G-code to a GRBL bender over a serial port, in a worker
thread under a modal operator (progress in the status bar and the panel, Esc cancels), and Resume
continues a stopped stream where its state says (after a stop that may have lost queued moves, the
first line of the step in doubt). Both use the machine profile chosen in the panel
(docs/user-guide.md, Fabrication). In background mode (batch, tests) there is no event loop and
Send runs to its end inside execute().
"""
import os

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, StringProperty

from .. import native
from ..blend import calibration as scene_calibration
from ..blend import preview as scene_preview
from ..blend import ownership
from ..blend import results as scene_results
from ..blend.machine import chosen_profile
from ..blend.registration import classes_factory
from ..fab import export, grbl, streaming
from ..core import calibration as cal
from ..core import machine_words as words
from ..props import NO_WIRE
from .progress import WorkerModal


def preview_machine(scene, profile):
    """The spring-back model of the machine preview: the export profile with the spring-back line
    the Calibration panel loaded last (the machine as measured), else None (the export profile
    itself: the preview then shows only what the small-bend rule changes)."""
    fit = scene_calibration.results(scene).get("springback")
    if not fit:
        return None
    return dict(cal.with_springback(profile or cal.default_profile(), fit, fit.get("source", "")),
                name="the loaded spring-back fit")


def _link(port):
    """The Machine panel's open link to `port` for a stream, None when it has none; ValueError
    with the sentence when its link is busy."""
    try:
        return grbl.link_for(port)
    except ValueError:
        raise ValueError(words.refusal(words.BUSY)) from None


def _design_or_error(op):
    design = scene_results.stored_design()
    if design is None:
        op.report({'ERROR'}, "No design yet: press Optimize first")
    return design


class WIRESCULPT_OT_export_fabrication(bpy.types.Operator):
    """Write every wire's 1:1 SVG template, G-code and bend table, an SVG sheet and a DXF into a
    folder (svg/, dxf/, gcode/, bends/), using the chosen machine profile; show the wire the machine
    is predicted to make as a ghost curve per wire"""
    bl_idname = "wiresculpt.export_fabrication"
    bl_label = "Export Fabrication Files"
    bl_options = {'REGISTER'}

    directory: StringProperty(name="Folder", subtype='DIR_PATH',
                              description="Folder that gets svg/, dxf/, gcode/ and bends/")
    filter_folder: BoolProperty(default=True, options={'HIDDEN'})

    @classmethod
    def poll(cls, context):
        return scene_results.stored_design() is not None

    def invoke(self, context, event):
        if not self.directory and bpy.data.filepath:
            self.directory = os.path.join(os.path.dirname(bpy.data.filepath), "fabrication") + os.sep
        context.window_manager.fileselect_add(self)
        return {'RUNNING_MODAL'}

    def execute(self, context):
        if not native.available():
            self.report({'ERROR'}, native.LOAD_ERROR)
            return {'CANCELLED'}
        design = _design_or_error(self)
        if design is None:
            return {'CANCELLED'}
        if not self.directory:
            self.report({'ERROR'}, "Choose a folder to export into")
            return {'CANCELLED'}
        folder = os.path.normpath(bpy.path.abspath(self.directory))
        try:
            profile = chosen_profile(context.scene)
            os.makedirs(folder, exist_ok=True)
            result = export.export(design, folder, profile, machine=preview_machine(context.scene, profile))
        except (ValueError, RuntimeError, OSError) as exc:
            self.report({'ERROR'}, f"Cannot export: {exc}")
            return {'CANCELLED'}
        scene_preview.write_ghosts(context.scene, design, result)
        scene_results.apply_assembly_step(context.scene)  # ghosts of wires not yet added stay hidden
        level, text = export.summary(result, folder)
        self.report({level}, text)
        return {'CANCELLED'} if level == "ERROR" else {'FINISHED'}


def _port_items(_self, _context):
    ports = native.list_ports() if native.available() else []
    items = [(p["name"], p["name"], p["description"] or p["name"]) for p in ports]
    _port_items.cache = items or [("", "(no serial port found)", "Type the port's path instead")]
    return _port_items.cache


class WIRESCULPT_OT_pick_port(bpy.types.Operator):
    """Choose one of the serial ports found on this computer"""
    bl_idname = "wiresculpt.pick_port"
    bl_label = "Pick Port"
    bl_options = {'REGISTER', 'INTERNAL'}
    bl_property = "port"

    port: EnumProperty(name="Port", items=_port_items)

    def execute(self, context):
        if not self.port:
            self.report({'WARNING'}, "No serial port found: type the port's path")
            return {'CANCELLED'}
        context.scene.wiresculpt.fab_port = self.port
        return {'FINISHED'}


class WIRESCULPT_OT_send_to_machine(WorkerModal, bpy.types.Operator):
    """Stream a wire's bend program (G-code) to the bender on the chosen serial port; Esc cancels,
    and Resume continues a stopped stream without skipping a line (from the first line of a step
    whose moves a stop may have lost)"""
    bl_idname = "wiresculpt.send_to_machine"
    bl_label = "Send to Machine"
    bl_options = {'REGISTER'}

    wire: StringProperty(name="Wire", default="", description="Wire name (empty: the panel's wire)")
    port: StringProperty(name="Port", default="", description="Serial port (empty: the panel's port)")
    resume: BoolProperty(name="Resume", default=False,
                         description="Continue the wire's stopped stream from the line its stop message names: the "
                                     "first unacknowledged line, or the first line of the step in doubt")
    dry_run: BoolProperty(name="Dry Run", default=False,
                          description="Only check the program; also when the panel's Dry Run is ticked")
    settle: FloatProperty(name="Settle", default=2.0, min=0.0, max=30.0, unit='TIME_ABSOLUTE',
                          description="Seconds GRBL gets to restart after the port opens (seconds)")
    response_timeout: FloatProperty(name="Answer Timeout", default=30.0, min=0.1, max=600.0,
                                    unit='TIME_ABSOLUTE',
                                    description="Longest wait for GRBL's answer to one line (seconds)")
    loaded: BoolProperty(name="Loaded", default=False,
                         description="The wire is loaded (the Continue of the \"load the wire\" step); otherwise "
                                     "Send first asks to load it")
    test: BoolProperty(name="Test Bends", default=False, options={'HIDDEN'},
                       description="Send the spring-back test piece instead of a wire")

    @classmethod
    def description(cls, context, properties):
        if properties.resume:
            return ("Continue the wire's stopped stream from the line its stop message names: the first "
                    "unacknowledged line, or the first line of the step in doubt")
        return cls.__doc__

    @classmethod
    def poll(cls, context):
        return not streaming.running()

    def _job(self, context):
        """The StreamJob, or None after reporting why not (or after asking to load the wire first:
        then self.asked is True)."""
        self.asked = False
        if not native.available():
            self.report({'ERROR'}, native.LOAD_ERROR)
            return None
        ws = context.scene.wiresculpt
        port = (self.port or ws.fab_port).strip()
        if self.test:
            return self._test_job(context, port)
        design = _design_or_error(self)
        if design is None:
            return None
        wire = self.wire or ws.fab_wire
        dry_run = self.dry_run or ws.fab_dry_run
        try:
            if not wire or wire == NO_WIRE:
                raise ValueError("no wire chosen (optimize until the wires have rest shapes)")
            profile = chosen_profile(context.scene)
            load = streaming.LOAD
            if not (self.resume or dry_run or self.loaded):  # the "load the wire" step first
                if not port:
                    raise ValueError("no serial port chosen: pick one or type its path (e.g. /dev/ttyUSB0)")
                streaming.ask_load(design, [wire], profile)
                self.asked = True
                self.report({'INFO'}, " ".join(words.load_lines(streaming.LOAD.facts)))
                return None
            job = streaming.prepare(design, wire, port, profile, self.resume, dry_run,
                                    (self.settle, self.response_timeout), link=_link(port))
        except (ValueError, RuntimeError) as exc:
            self.report({'ERROR'}, f"Cannot send: {exc}")
            return None
        if self.loaded and load is not None and load.wire == wire:  # Send All's next wires follow this one
            job.queue, job.queue_count = list(load.queue), load.facts.get("count", 1)
            streaming.clear_load()
        return job

    def _test_job(self, context, port):
        try:
            profile = chosen_profile(context.scene)
            lines, machine, commanded, _length = grbl.test_bend_program(profile)
            job = streaming.prepare_program(grbl.TEST_NAME, lines, machine, port,
                                            timing=(self.settle, self.response_timeout), link=_link(port),
                                            resume=self.resume)
        except (ValueError, RuntimeError) as exc:
            self.report({'ERROR'}, f"Cannot send the test bends: {exc}")
            return None
        job.after = [c for c in commanded if c]  # the bends (the last step only feeds)
        streaming.clear_load()
        return job

    def _finish(self, job):
        kind, message = streaming.finish(job)
        self.report(kind, message)
        completed = job.result is not None and job.result.get("status") == "completed"
        if completed and job.after is not None:  # the test piece is bent: its rows wait for the measured angles
            scene_calibration.set_springback_rows(bpy.context.scene, job.after)
        if completed and job.queue:
            design = scene_results.stored_design()
            try:
                load = streaming.next_load(design, job, chosen_profile(bpy.context.scene))
                self.report({'INFO'}, " ".join(words.load_lines(load.facts)))
            except (ValueError, RuntimeError) as exc:
                self.report({'ERROR'}, f"Cannot send the next wire: {exc}")
        return {'FINISHED'} if kind == {'INFO'} else {'CANCELLED'}

    def execute(self, context):
        job = self._job(context)
        if job is None:
            return {'FINISHED'} if self.asked else {'CANCELLED'}
        streaming.JOB = job
        try:
            job.run()  # blocking: no event loop in background mode
        finally:
            streaming.JOB = None
        return self._finish(job)

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        job = self._job(context)
        if job is None:
            return {'FINISHED'} if self.asked else {'CANCELLED'}
        streaming.JOB = job
        job.thread.start()
        self.begin_watch(context, 100)
        self._show(context)
        return {'RUNNING_MODAL'}

    def _show(self, context):
        job = streaming.JOB
        if job is not None:
            self.show_progress(context, int(100 * job.fraction), job.status())

    def _cleanup(self, context):
        self.end_watch(context)
        streaming.JOB = None

    def modal(self, context, event):
        job = streaming.JOB
        if job is None:
            return {'CANCELLED'}
        try:
            answer = self.watch_event(context, event, job.thread, job.cancel)
            if answer is not None:
                return answer
            self._cleanup(context)
            return self._finish(job)
        except Exception as exc:  # never leave a half-finished modal behind in the UI
            job.cancel()
            job.thread.join()
            self._cleanup(context)
            self.report({'ERROR'}, f"Send to Machine failed: internal error ({type(exc).__name__}: {exc})")
            return {'CANCELLED'}

    def cancel(self, context):  # Blender closes the window or the file under the modal
        job = streaming.JOB
        if job is not None:
            job.cancel()
            job.thread.join()
            self._cleanup(context)
            streaming.finish(job)


class WIRESCULPT_OT_send_all(bpy.types.Operator):
    """Send every wire with a rest shape, one after the other: before each, the panel says which wire,
    stock and length to load, and Continue sends it"""
    bl_idname = "wiresculpt.send_all"
    bl_label = "Send All Wires"
    bl_options = {'REGISTER'}

    @classmethod
    def poll(cls, context):
        return not streaming.running()

    def execute(self, context):
        design = _design_or_error(self)
        if design is None:
            return {'CANCELLED'}
        if not context.scene.wiresculpt.fab_port.strip():
            self.report({'ERROR'}, "Cannot send: no serial port chosen: pick one or type its path (e.g. /dev/ttyUSB0)")
            return {'CANCELLED'}
        try:
            load = streaming.ask_load(design, [w["name"] for w in streaming.rest_wires(design)],
                                      chosen_profile(context.scene))
        except (ValueError, RuntimeError) as exc:
            self.report({'ERROR'}, f"Cannot send: {exc}")
            return {'CANCELLED'}
        self.report({'INFO'}, " ".join(words.load_lines(load.facts)))
        return {'FINISHED'}


class WIRESCULPT_OT_load_cancel(bpy.types.Operator):
    """Do not send the wire the panel asks to load (nor the ones after it)"""
    bl_idname = "wiresculpt.load_cancel"
    bl_label = "Skip"
    bl_options = {'INTERNAL'}

    def execute(self, context):
        streaming.clear_load()
        return {'FINISHED'}


class WIRESCULPT_OT_send_cancel(bpy.types.Operator):
    """Stop sending: the machine gets a feed hold and a soft reset; Resume continues later"""
    bl_idname = "wiresculpt.send_cancel"
    bl_label = "Cancel Sending"
    bl_options = {'INTERNAL'}

    def execute(self, context):
        if not streaming.cancel():
            self.report({'INFO'}, "Nothing to cancel: no wire is being sent")
            return {'CANCELLED'}
        self.report({'INFO'}, "Cancelling the stream…")
        return {'FINISHED'}


_register, unregister = classes_factory(
    (WIRESCULPT_OT_export_fabrication, WIRESCULPT_OT_pick_port, WIRESCULPT_OT_send_to_machine,
     WIRESCULPT_OT_send_all, WIRESCULPT_OT_load_cancel, WIRESCULPT_OT_send_cancel))


def register():
    _register()
    ownership.on_load(streaming.forget)  # a stream's stop is its file's (blend/ownership registers the handlers)
