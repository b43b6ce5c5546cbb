"""Optimize: the ticked contours become wires and the solver's stages run on them.

From the UI the solver runs in a worker thread (the native stages release the GIL) under a modal
operator with a timer: progress in the panel and the status bar, Esc or Cancel stops it and
leaves the scene exactly as before. Nothing is written to the scene until the solver is done,
and then in the modal's last step, so one Undo removes the whole result. In background mode
(batch, tests) there is no event loop and execute() solves inline.

Cancelling never freezes Blender: it signals the worker (every native stage polls the signal
between steps), waits at most JOIN_SECONDS, and if the worker is still inside a native step the
job stays "cancelling…" (the modal, or after Blender removed the modal a timer, polls it) until
the worker ends; its result is then dropped, so nothing of a cancelled run reaches the scene.
"""
import functools
import threading
import time

import bpy

from .. import native, pipeline
from ..blend import cut_handles, mesh, model_watch
from ..blend import results as scene_results
from ..blend.handles import plane_ids, model_name, model_problem, ticked_planes
from ..blend.machine import chosen_stock
from ..blend.view import redraw_3d_views
from ..blend.registration import classes_factory
from ..core.jobs import WorkerJob
from ..core import standing
from ..core.limits import OVER_LIMITS, STOCK_LENGTH, recorded_stock
from ..core.live_verdict import STABLE, of_design
from ..props import material_of, solver_settings
from .progress import JOIN_SECONDS, TIMER_SECONDS, WorkerModal, note_running

STAGE_LABELS = {"slicing": "Slicing", "layering": "Layering", "target_shape": "Target shape",
                "forces": "Forces", "rest_shape": "Rest shape", "writing": "Writing results"}


# --- small functions, no UI -------------------------------------------------------------------

def build_design(context):
    """(design, material, settings) from the scene: the evaluated model re-sliced by the handles,
    the ticked contours as wires. ValueError (naming the plane or contour) when that is not
    possible."""
    scene = context.scene
    ws = scene.wiresculpt
    problem = model_problem(scene, ws.model)
    if problem:
        raise ValueError(problem)
    if not native.available():
        raise RuntimeError(native.LOAD_ERROR)
    depsgraph = context.evaluated_depsgraph_get()
    planes = ticked_planes(scene, depsgraph)
    material, settings = material_of(ws), solver_settings(ws)
    V, F = mesh.object_triangles(ws.model, depsgraph)
    model_watch.remember(ws.model, V, F)  # solve_record's digest of the model as it is
    V, F, _closing = mesh.close_for_slicing(V, F, settings["min_segment"])  # open or many parts: closed (mesh_closing)
    try:
        design = pipeline.slice_and_pick(V, F, planes, material, settings)
    except ValueError as exc:  # a ticked contour the planes no longer cut
        raise ValueError(f"{exc}: Slice again") from None
    cut_handles.apply_to_design(scene, design)
    return design, material, settings


def solve_record(scene, material, settings):
    """What a solve reads besides the planes and ticks, as Optimize starts it, and the planes' ids
    (handles.plane_ids: gives those missing): kept beside the stored design
    (blend/results.store_inputs) so the Stability box can tell when the panel has changed since
    and which handle a renamed plane is (core/stale.py)."""
    record = {"target": model_name(scene.wiresculpt), "settings": dict(settings), "material": dict(material),
              "planes": plane_ids(scene), "stock": list(chosen_stock(scene))}
    digest = model_watch.kept_digest(scene.wiresculpt.model) if scene.wiresculpt.model is not None else None
    if digest is not None:  # the triangles build_design sliced (blend/model_watch.py)
        record["mesh"] = digest
    return record


def summary(design, stock_length=STOCK_LENGTH):
    """(report type, sentence) for the finished design, in the words of Live's verdict
    (core/live_verdict.of_design): stable, stable over its limits (never a plain "Stable" beside a
    broken limit), cannot solve (a setup problem) or not stable, with the limits or the reason."""
    kind, text = of_design(design, stock_length)
    if kind not in (STABLE, OVER_LIMITS):
        return {'WARNING'}, f"{kind.capitalize()}: {text}"
    names = [design["wires"][w]["name"] for w in design.get("assembly_order", [])]
    counts = f"{len(design['wires'])} wires, {len(design.get('crossings', []))} crossings; assemble {', '.join(names)}"
    if kind == OVER_LIMITS:
        return {'WARNING'}, f"{OVER_LIMITS.capitalize()}: {text}; {counts}"
    record = standing.checked(design)  # the 3D check's figures beside a plain "Stable"
    return {'INFO'}, f"Stable: {counts}" + (f". {standing.summary(record)}" if record is not None else "")


def run_optimize(context, progress=None, cancel=None):
    """Builds, solves and writes the design into the scene (the synchronous path). Raises
    pipeline.Cancelled (the scene untouched), ValueError or RuntimeError (untouched too)."""
    design, material, settings = build_design(context)
    inputs = solve_record(context.scene, material, settings)
    # a new dict after re-layering
    design = pipeline.solve(design, material, settings, progress, cancel, stock=tuple(inputs["stock"]))
    scene_results.write_results(context.scene, design, inputs)
    return design


class Job(WorkerJob):
    """The running optimisation: the worker thread and what the panel shows of it."""

    name = "wiresculpt solve"

    def __init__(self, design, material, settings):
        super().__init__()
        self.design, self.material, self.settings = design, material, settings
        self.stage = pipeline.ALL_STAGES[0]
        self.done = 0
        self.messages = []
        self.cancelled = False
        self.cancel_event = threading.Event()
        self.scene_name = ""  # set by the operator: the scene the results go to
        self.inputs = None  # set by the operator: solve_record of the scene as the solve started
        self.stock = None  # set by the operator: (m, profile name) the size warnings name (blend/machine.chosen_stock)
        self.started = time.perf_counter()

    def _progress(self, stage, message):
        self.messages.append(f"{stage}: {message}")
        if stage == "relayering":  # another round starts from the layering
            self.done, self.stage = 0, pipeline.ALL_STAGES[0]
        elif stage in pipeline.ALL_STAGES:
            k = pipeline.ALL_STAGES.index(stage) + 1
            self.done = max(self.done, k)
            if k < len(pipeline.ALL_STAGES):
                self.stage = pipeline.ALL_STAGES[k]

    def work(self):
        try:
            self.design = pipeline.solve(self.design, self.material, self.settings, self._progress,
                                         self.cancel_event.is_set, stock=self.stock)
        except pipeline.Cancelled:
            self.cancelled = True

    def stop(self, timeout=JOIN_SECONDS):
        """Asks the worker to stop and waits at most `timeout` seconds; True when it has ended."""
        self.cancel_event.set()
        self.thread.join(timeout)
        return not self.thread.is_alive()

    def status(self):
        label = STAGE_LABELS.get(self.stage, self.stage)
        if self.cancel_event.is_set():
            return "wiresculpt: cancelling…"
        if self.done >= len(pipeline.ALL_STAGES):  # the other hook patterns, the coupling rounds
            return (f"wiresculpt: comparing hook patterns… stage {len(pipeline.ALL_STAGES)} of "
                    f"{len(pipeline.ALL_STAGES)}, {time.perf_counter() - self.started:.0f} s (Esc to cancel)")
        return (f"wiresculpt: {label}… stage {self.done + 1} of {len(pipeline.ALL_STAGES)}, "
                f"{time.perf_counter() - self.started:.0f} s (Esc to cancel)")


JOB = None  # the Job while an Optimize runs in the UI, else None


def running():
    return JOB is not None


note_running("optimize", running)


def _wait_for_worker(job):
    """A timer after the modal is gone: polls the cancelled job until its worker ends, then
    drops it (its result is never written)."""
    global JOB
    if job.thread.is_alive():
        return TIMER_SECONDS
    if JOB is job:
        JOB = None
    try:
        redraw_3d_views()
    except (AttributeError, ReferenceError):  # no window (closing, background)
        pass
    return None


def _abandon(job):
    """Cancels `job` without waiting for it: the worker is left to end on its own (the panel
    says cancelling… meanwhile) and is then dropped by a timer."""
    global JOB
    if job.stop():
        if JOB is job:
            JOB = None
        return
    bpy.app.timers.register(functools.partial(_wait_for_worker, job), first_interval=TIMER_SECONDS,
                            persistent=True)


# --- operators --------------------------------------------------------------------------------

class WIRESCULPT_OT_optimize(WorkerModal, bpy.types.Operator):
    """Turn the ticked contours into a stable wire sculpture: layering, target shape and the
    later stages; the wires appear as curves (Esc cancels)"""
    bl_idname = "wiresculpt.optimize"
    bl_label = "Optimize"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        return not running()

    def _finish(self, context, design, scene=None, inputs=None):
        scene_results.write_results(scene or context.scene, design, inputs)
        kind, message = summary(design, recorded_stock(inputs))
        self.report(kind, message)
        return {'FINISHED'}

    def execute(self, context):
        try:
            design, material, settings = build_design(context)
            inputs = solve_record(context.scene, material, settings)
            design = pipeline.solve(design, material, settings, stock=tuple(inputs["stock"]))
        except pipeline.Cancelled:
            self.report({'WARNING'}, "Optimize cancelled; the scene is unchanged")
            return {'CANCELLED'}
        except (ValueError, RuntimeError) as exc:
            self.report({'ERROR'}, f"Cannot optimize: {exc}")
            return {'CANCELLED'}
        return self._finish(context, design, inputs=inputs)

    def invoke(self, context, event):
        global JOB
        if bpy.app.background or context.window is None:
            return self.execute(context)
        try:
            design, material, settings = build_design(context)
        except (ValueError, RuntimeError) as exc:
            self.report({'ERROR'}, f"Cannot optimize: {exc}")
            return {'CANCELLED'}
        JOB = Job(design, material, settings)
        JOB.scene_name = context.scene.name  # the results belong to the scene that was optimized
        JOB.inputs = solve_record(context.scene, material, settings)
        JOB.stock = tuple(JOB.inputs["stock"])
        JOB.thread.start()
        self.begin_watch(context, len(pipeline.ALL_STAGES))
        self._show(context)
        return {'RUNNING_MODAL'}

    def _show(self, context):
        if JOB is not None:
            self.show_progress(context, JOB.done, JOB.status())

    def _cleanup(self, context):
        global JOB
        self.end_watch(context)
        job, JOB = JOB, None
        return job

    def modal(self, context, event):
        try:
            return self._modal(context, event)
        except Exception as exc:  # never leave a half-finished modal behind in the UI
            if JOB is not None:
                self.end_watch(context)
                _abandon(JOB)
            self.report({'ERROR'}, f"Optimize failed: internal error ({type(exc).__name__}: {exc}); "
                                   "the scene is unchanged")
            return {'CANCELLED'}

    def _modal(self, context, event):
        job = JOB
        if job is None:  # cancelled from outside and already cleaned up
            return {'CANCELLED'}
        if event.type == 'Z' and (event.ctrl or event.oskey):
            return {'RUNNING_MODAL'}  # no undo under a running solve
        # Esc: stop; the next timer tick finishes the modal once the worker has ended
        answer = self.watch_event(context, event, job.thread, job.stop)
        if answer is not None:
            return answer
        self._cleanup(context)
        if job.cancelled or job.cancel_event.is_set():
            self.report({'WARNING'}, "Optimize cancelled; the scene is unchanged")
            return {'CANCELLED'}
        if job.error is not None:
            self.report({'ERROR'}, f"Cannot optimize: {job.error}")
            return {'CANCELLED'}
        scene = bpy.data.scenes.get(job.scene_name)
        if scene is None:
            self.report({'WARNING'}, f"The scene '{job.scene_name}' was removed while optimizing; "
                                     "nothing was written")
            return {'CANCELLED'}
        return self._finish(context, job.design, scene, job.inputs)

    def cancel(self, context):  # Blender closes the window or the file under the modal
        job = JOB
        if job is not None:
            try:
                self.end_watch(context)
            except (AttributeError, ReferenceError, RuntimeError):  # the window is going away
                pass
            _abandon(job)


class WIRESCULPT_OT_optimize_cancel(bpy.types.Operator):
    """Stop the running Optimize at the next safe point; the scene stays as it was"""
    bl_idname = "wiresculpt.optimize_cancel"
    bl_label = "Cancel"
    bl_options = {'INTERNAL'}

    def execute(self, context):
        if JOB is None:
            self.report({'INFO'}, "Nothing to cancel: no Optimize is running")
            return {'CANCELLED'}
        JOB.stop()  # the Optimize modal finishes once the worker has ended
        self.report({'INFO'}, "Cancelling Optimize…")
        return {'FINISHED'}


register, unregister = classes_factory((WIRESCULPT_OT_optimize, WIRESCULPT_OT_optimize_cancel))
