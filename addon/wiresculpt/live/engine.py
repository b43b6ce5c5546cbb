"""Live: while a slicing plane (or the model) moves, re-slice and re-solve in the background and
show the verdict (docs/user-guide.md, Live).

A bpy.app.timers callback (tick, every TICK_SECONDS while nothing changes, every
ACTIVE_TICK_SECONDS while planes move or a job runs) compares a snapshot of what a solve depends on
(the slicing planes' and the model's matrix_world, the ticked contours, the material and machine
settings, whether the model is still in the scene, and how often its geometry changed: edits and
modifiers, counted by a depsgraph handler) with the last one it saw. A snapshot that
stayed the same for SETTLE_SECONDS and differs from the one solved (or being solved) starts a LiveJob on
a worker thread: slice_and_pick then pipeline.solve with the hook search limited to the
layering's own pattern (hook_patterns=1) and the user's relayer_rounds. Latest position wins: a
running job whose snapshot is no longer current is cancelled (its cancel event; it is never waited
for) and a new one starts; a result is shown only when its snapshot is still the current one.

The verdict's words are core/live_verdict's: "not stable — <reason>" only for a solve that ended
not stable, "cannot solve — <what to do>" when the scene as set up cannot be solved (no model, no
contour ticked, a panel value or plane the solver refuses, fewer than two wires), "error — …" for our
unexpected error; a long reason is shown to the end of its first clause, the whole one in
the tooltip of operators/live.py's WIRESCULPT_OT_live_reason.

Nothing is written to the scene or the .blend: the verdict and the wires' preview (STATE.preview,
line segments in each wire's colour, computed on the worker by blend/results.wire_shapes) live in
live/state.py's STATE, shown by the Wire panel and drawn by ui/overlay.py, so no live update touches the
undo history. The wire curves themselves are not rewritten (blend/results.write_results would also
replace the stored design of the last Optimize and its markers and cut handles); Optimize does.

Turning Live off, loading a file (load_pre) or unregistering stops the timer and cancels the job.
The timer follows the toggle also where Blender sets it without its update (undo, redo, another
scene in the window): the depsgraph, undo and redo handlers and a msgbus subscription to the
windows' scene start or stop it (_sync). (A scene switched to in C, such as from the Outliner,
publishes no msgbus change: Live there starts with that scene's next depsgraph update. Geometry
changed only by animation on a frame change is not counted.) Meshes over
MAX_TRIANGLES triangles, counted with their modifiers, are refused (the panel says why).
"""
import threading
import time
import traceback

import bpy

from .. import native, pipeline
from ..blend import cut_handles, mesh
from ..blend.mesh import triangle_count
from ..blend import results as scene_results
from ..blend.machine import chosen_stock
from ..blend.registration import handlers_factory
from ..blend.handles import contour_plane_name, handles, model_name, model_problem, ticked_planes
from ..blend.view import redraw_3d_views
from ..core.jobs import WorkerJob
from ..core import standing
from ..core.limits import limit_records
from ..core.live_verdict import CANNOT_SOLVE, ERROR, SOLVING, of_design, shortened, verdict
from ..props import LIVE_HOOKS, material_of, solve_inputs, solver_settings
from .state import STATE, observed  # noqa: F401 (observed: the tests' and the bench's reader)

TICK_SECONDS = 0.1  # while nothing changes
ACTIVE_TICK_SECONDS = 0.02  # while a plane moves or a job runs: the verdict is seen sooner
SETTLE_SECONDS = 0.05  # a position unchanged this long is solved (a drag's every frame is not)
# Live is refused on larger models (with their modifiers): it reads the mesh on Blender's thread
# when Live starts and whenever the model changes (blend/mesh.MAX_REREAD_TRIANGLES says why).
MAX_TRIANGLES = mesh.MAX_REREAD_TRIANGLES
LIVE_HOOK_PATTERNS = 1  # the layering's own hook pattern only: Optimize may pick other hooks
DURATIONS_KEPT = 10_000


def refusal(model, depsgraph=None):
    """Why Live cannot run on `model` (its triangles counted as evaluated in `depsgraph`), or ""."""
    if model is not None and model.type == 'MESH':
        return too_large(model.name, triangle_count(model, depsgraph))
    return ""


def too_large(name, triangles):
    """The refusal of a model `name` of `triangles` triangles, or "" within MAX_TRIANGLES."""
    if triangles <= MAX_TRIANGLES:
        return ""
    return (f"Live is off: {name} has {triangles:,} triangles with its modifiers; Live takes at most "
            f"{MAX_TRIANGLES:,}, since it reads the mesh again whenever it changes. Use Optimize")


def refuse(settings, message):
    """Turns Live off with `message` for the panel (shown while the same model is picked)."""
    STATE.message, STATE.message_model = message, model_name(settings)
    settings.live = False  # its update stops the timer


def refused_message(settings):
    """Why Live was refused, while the model it speaks of is still the picked one, or ""."""
    model = settings.model
    return STATE.message if STATE.message and model is not None and model.name == STATE.message_model else ""


def _rounded(matrix):
    return tuple(round(x, 9) for row in matrix for x in row)


def snapshot(scene):
    """What a live solve depends on: the model's name and matrix_world, the planes' matrix_world,
    the ticked contours, the panel's material and machine values, whether the model is in the
    scene, the cut handles the user moved, and the count of its geometry's changes (STATE.geometry;
    last)."""
    ws = scene.wiresculpt
    model = ws.model
    return (model_name(ws), _rounded(model.matrix_world) if model else (),
            tuple((h.name, _rounded(h.matrix_world)) for h in handles(scene)),
            tuple((contour_plane_name(item), item.index) for item in ws.contours if item.use),
            solve_inputs(ws), model is not None and scene.objects.get(model.name) == model,
            tuple(sorted((name, tuple(round(x, 9) for x in point))
                         for name, point in cut_handles.user_cut_points(scene).items())),
            STATE.geometry)


def _show(kind, text="", limits=()):
    """Sets the verdict of `kind` (core/live_verdict) with its reason, problem or error `text`, and
    the codes of the `limits` it breaks (stable, over its limits)."""
    STATE.verdict, STATE.reason, STATE.kind, STATE.limits = verdict(kind, text), text, kind, tuple(limits)
    STATE.standing = ""  # a solved job's _step sets it after


def whole_reason():
    """The whole reason, problem or error of the shown verdict when the line shows only part of it, else ""."""
    return STATE.reason if STATE.running and shortened(STATE.reason) else ""


def preview_segments(design, ids=None):
    """[(RGBA, (2k, 3) float32 segment end points)] of each wire's shape (interlock offsets
    applied), in the wire's colour: what the overlay draws. `ids`: a list that gets each entry's
    wire id."""
    out = []
    for wire_id, points in scene_results.wire_shapes(design).items():
        if len(points) < 2:
            continue
        wire = next(w for w in design["wires"] if w["id"] == wire_id)
        out.append((scene_results.wire_colour(wire_id), scene_results.polyline_segments(points, wire["closed"])))
        if ids is not None:
            ids.append(wire_id)
    return out


class LiveJob(WorkerJob):
    """One live solve of one snapshot: slice the cached triangles, solve with the layering's own hooks."""

    name = "wiresculpt live"

    def __init__(self, key, vertices, faces, planes, cuts, material, settings, stock=None):
        super().__init__()
        self.stock = stock  # (m, profile name) the size warnings and limits name (blend/machine.chosen_stock)
        self.key = key
        self.vertices, self.faces, self.planes, self.cuts = vertices, faces, planes, cuts
        self.material, self.settings = material, settings
        self.cancel_event = threading.Event()
        self.cancelled = False
        self.design = None
        self.preview, self.preview_ids, self.preview_steps = [], [], []
        self.seconds = None  # the work's wall time (slicing, solve, preview), when it ended

    def work(self):
        began = time.monotonic()
        try:
            design = pipeline.slice_and_pick(self.vertices, self.faces, self.planes, self.material, self.settings)
            cut_handles.set_cut_points(design, self.cuts)  # the user's moved cut handles, as build_design gives them
            self.design = pipeline.solve(design, self.material, self.settings, cancel=self.cancel_event.is_set,
                                         stock=self.stock, hook_patterns=LIVE_HOOK_PATTERNS)
            self.preview = preview_segments(self.design, self.preview_ids)
            self.preview_steps = self.design.get("assembly_steps") or []
        except pipeline.Cancelled:
            self.cancelled = True
        finally:
            self.seconds = time.monotonic() - began

    def verdict(self):
        """(kind, text) of core/live_verdict: the design's verdict (of_design: fewer than two wires
        cannot solve); an error with the user's sentence (the solver refusing the input, a ticked
        contour the plane no longer cuts, the time budget) cannot solve, any other is our error."""
        if self.error is not None:
            return (ERROR if self.unexpected else CANNOT_SOLVE), self.error
        return of_design(self.design, *(self.stock[:1] if self.stock else ()))

    def standing(self):
        """The design's 3D check in one line (core/standing.summary), "" when it did not run (an
        error, or a design the planar stages call not stable)."""
        record = standing.checked(self.design) if self.error is None and self.design else None
        return standing.summary(record) if record is not None else ""

    def limit_codes(self):
        """The codes of the limits the design breaks when it is stable (core/limits.limit_records,
        the phrases verdict() says), () otherwise."""
        if self.error is not None or not self.design or not self.design.get("stable"):
            return ()
        return tuple(code for code, _phrase in limit_records(self.design, *(self.stock[:1] if self.stock else ())))


class Refused(str):
    """_start's answer when the model turned out too large to read at every change."""


def _start(scene, key):
    """A LiveJob for snapshot `key` (the scene read here, on Blender's thread); (CANNOT_SOLVE, why)
    when the scene as set up cannot be solved at all."""
    ws = scene.wiresculpt
    problem = model_problem(scene, ws.model)
    if problem:
        return CANNOT_SOLVE, problem
    if not native.available():
        return CANNOT_SOLVE, "the solver is not loaded (the panel's first box says why)"
    depsgraph = bpy.context.evaluated_depsgraph_get()
    try:
        planes = ticked_planes(scene, depsgraph)
        material, settings = material_of(ws), solver_settings(ws)  # the panel's values, checked
    except ValueError as exc:
        return CANNOT_SOLVE, str(exc)
    mesh_key = (key[0], key[1], key[-1])  # the model's name, matrix and geometry changes
    if STATE.mesh_key != mesh_key:
        V, F = mesh.object_triangles(ws.model, depsgraph)
        message = too_large(ws.model.name, len(F))  # more than refusal counted (GPU subdivision)
        if message:
            return Refused(message)
        try:  # an open or many-part model is closed for slicing (blend/mesh.py), once per change
            STATE.mesh = mesh.close_for_slicing(V, F, settings["min_segment"])[:2]
        except RuntimeError as exc:
            return CANNOT_SOLVE, str(exc)
        STATE.mesh_key = mesh_key
    job = LiveJob(key, *STATE.mesh, planes, cut_handles.user_cut_points(scene), material, settings,
                  chosen_stock(scene))
    job.thread.start()
    return job


def _step():
    scene = bpy.context.scene
    if scene is None or not scene.wiresculpt.live:
        stop()
        return None
    key = snapshot(scene)
    shown = STATE.verdict
    job = STATE.job
    if job is not None and not job.thread.is_alive():  # finished: shown only if still current
        STATE.job = None
        if job.key == key and not job.cancelled and not job.cancel_event.is_set():
            _show(*job.verdict(), limits=job.limit_codes())
            STATE.standing = job.standing()
            STATE.solved = job.key
            STATE.preview = job.preview if job.error is None else []
            STATE.preview_ids, STATE.preview_steps = job.preview_ids, job.preview_steps
            STATE.record.results.append(STATE.verdict)
            STATE.record.shown_at, STATE.record.job_seconds = time.monotonic(), job.seconds
        job = None
    if job is not None and job.key != key:  # the planes moved on: latest position wins
        job.cancel_event.set()  # never waited for: it ends at its next checkpoint, its result dropped
        STATE.job = job = None
    now = time.monotonic()
    if key != STATE.seen:
        STATE.seen, STATE.seen_since = key, now
    settled = now - STATE.seen_since >= SETTLE_SECONDS
    if job is None and settled and key != STATE.solved:
        message = refusal(scene.wiresculpt.model, bpy.context.evaluated_depsgraph_get())
        if message:
            refuse(scene.wiresculpt, message)
            return None
        started = _start(scene, key)
        if isinstance(started, Refused):
            refuse(scene.wiresculpt, str(started))
            return None
        if isinstance(started, tuple):
            _show(*started)
            STATE.solved, STATE.preview = key, []
            STATE.record.results.append(STATE.verdict)
            STATE.record.shown_at = time.monotonic()
        else:
            STATE.job = started
            _show(SOLVING)
    elif not settled and key != STATE.solved:
        _show(SOLVING)
    if STATE.verdict != shown:
        redraw_3d_views()
    return ACTIVE_TICK_SECONDS if STATE.job is not None or key != STATE.solved else TICK_SECONDS


_TICKING = []  # non-empty while tick runs: stop() then leaves the timer to end by returning None


def tick():
    """The timer callback: one _step, its duration recorded."""
    began = time.perf_counter()
    _TICKING.append(True)
    try:
        return _step()
    except (AttributeError, ReferenceError):  # no scene or window (closing, loading)
        stop()
        return None
    except Exception as exc:  # noqa: BLE001 - a timer that raises is gone for good, leaving the toggle on
        text = f"{type(exc).__name__}: {exc}"
        if text != STATE.failed:  # once, not at every tick
            traceback.print_exc()
        if not STATE.running:  # stopped within the step: no timer may outlive it
            return None
        STATE.failed, STATE.preview = text, []
        _show(ERROR, text)
        STATE.solved = STATE.seen  # tried again once something changes
        return TICK_SECONDS
    finally:
        _TICKING.clear()
        STATE.record.durations.append(time.perf_counter() - began)
        del STATE.record.durations[:-DURATIONS_KEPT]


def start():
    if not STATE.running:
        STATE.reset()
        STATE.running = True
        _show(SOLVING)
        bpy.app.timers.register(tick, first_interval=TICK_SECONDS)


def stop():
    """Stops the timer and cancels the running job (not waited for); the verdict is cleared."""
    if not _TICKING and bpy.app.timers.is_registered(tick):
        bpy.app.timers.unregister(tick)
    if STATE.job is not None:
        STATE.job.cancel_event.set()
    durations, drawn = STATE.record.durations, STATE.preview
    STATE.reset()
    STATE.record.durations = durations  # what the last run's ticks took, for the test
    if drawn:  # the preview goes from the viewport
        try:
            redraw_3d_views()
        except (AttributeError, ReferenceError):  # no window (closing, background)
            pass


def line():
    """The panel's line, or "" when Live is off."""
    return f"Live: {STATE.verdict}" if STATE.running else ""


def standing_shown():
    """The shown verdict's 3D check in one line (core/standing.summary), "" when it did not run or
    Live is off."""
    return STATE.standing if STATE.running else ""


def verdict_shown():
    """The verdict the panel shows (core/live_verdict), "" before the first."""
    return STATE.verdict


def kind_shown():
    """The kind of the verdict the panel shows (core/live_verdict), "" before the first."""
    return STATE.kind


def limits_shown():
    """The codes of the limits the shown verdict breaks (core/limits), () unless over its limits."""
    return STATE.limits


def reason():
    """The whole text behind the shown verdict (its reason, problem or error), "" for a word alone."""
    return STATE.reason


def running():
    """Whether Live's timer runs."""
    return STATE.running


def preview_shown():
    """The preview segments the overlay draws while Live runs (preview_segments), else []."""
    return STATE.preview if STATE.running else []


def preview_order():
    """The wire id of each preview_shown entry and the shown verdict's assembly_steps (the
    assembly slider's filter, core/assembly_view.shown_lines), else ([], [])."""
    return (STATE.preview_ids, STATE.preview_steps) if STATE.running else ([], [])


def note_drawn():
    """The overlay drew the preview: counted, with its time, for the tests and the bench."""
    STATE.record.drawn += 1
    STATE.record.drawn_at = time.monotonic()


def live_changed(settings, context):
    """The toggle's update (props.LIVE_HOOKS): start, refuse or stop."""
    if not settings.live:
        stop()
        return
    _turn_on(settings, context.evaluated_depsgraph_get() if context is not None else None)


def _turn_on(settings, depsgraph):
    message = refusal(settings.model, depsgraph)
    if message:
        refuse(settings, message)
        return
    STATE.message = ""
    start()


_SYNCING = []  # non-empty while _sync runs: the depsgraph it evaluates calls the handler again


def _sync(scene, depsgraph=None):
    """Starts or stops the timer where the toggle changed without its update (undo, redo, a scene
    switch); `depsgraph`: the evaluated one at hand (a handler's), else the context's."""
    if scene is None or _SYNCING:
        return
    _SYNCING.append(True)
    try:
        on = bool(scene.wiresculpt.live)
        if on and not STATE.running:
            _turn_on(scene.wiresculpt, depsgraph if depsgraph is not None else bpy.context.evaluated_depsgraph_get())
        elif not on and STATE.running:
            stop()
    finally:
        _SYNCING.clear()


@bpy.app.handlers.persistent
def _depsgraph_post(scene=None, depsgraph=None, *_args):
    """Keeps the timer in step with the toggle, and counts changes of the model's geometry (edits,
    modifiers) into STATE.geometry, which the snapshot holds."""
    try:
        current = bpy.context.scene or scene
        _sync(current, depsgraph if current == scene else None)
        if not STATE.running or depsgraph is None or current is None:
            return
        model = current.wiresculpt.model
        if model is None:
            return
        watched = (model, model.data)
        for update in depsgraph.updates:
            if update.is_updated_geometry and update.id.original in watched:
                STATE.geometry += 1
                return
    except (AttributeError, ReferenceError):  # no scene or window (closing, loading)
        pass


@bpy.app.handlers.persistent
def _sync_shown(*_args):
    """_sync of the window's scene: after undo, redo, loading a file (a file saved with Live on
    resumes it), and a window switching scenes (a scene evaluated before fires no depsgraph update
    when it is shown again)."""
    try:
        _sync(bpy.context.scene)
    except (AttributeError, ReferenceError):
        pass


_SCENE_SWITCH = object()  # the msgbus owner of the window-scene subscription


def _watch_scene_switch():
    """Subscribes _sync_shown to windows switching scenes (load_post again: a load clears msgbus)."""
    bpy.msgbus.clear_by_owner(_SCENE_SWITCH)
    bpy.msgbus.subscribe_rna(key=(bpy.types.Window, "scene"), owner=_SCENE_SWITCH, args=(),
                             notify=_sync_shown)


@bpy.app.handlers.persistent
def _load_pre(*_args):
    stop()
    STATE.message = STATE.message_model = ""  # a refusal speaks of the closed file's model


@bpy.app.handlers.persistent
def _load_post(*_args):
    _watch_scene_switch()
    _sync_shown()


_add_handlers, _remove_handlers = handlers_factory((
    ("load_pre", _load_pre), ("load_post", _load_post), ("depsgraph_update_post", _depsgraph_post),
    ("undo_post", _sync_shown), ("redo_post", _sync_shown)))


def install():
    """The toggle's update and the handlers that keep Live in step with the scene."""
    LIVE_HOOKS.append(live_changed)
    _add_handlers()
    _watch_scene_switch()


def uninstall():
    """Stops Live and removes what install added."""
    stop()
    bpy.msgbus.clear_by_owner(_SCENE_SWITCH)
    _remove_handlers()
    if live_changed in LIVE_HOOKS:
        LIVE_HOOKS.remove(live_changed)
