"""Find Stable Planes and Suggest Planes: the plane assistant (plane_search/) on a
worker thread under a modal like Optimize's (progress, Esc cancels, the scene untouched until the
user applies a candidate), and Apply: the candidate's planes become the slicing handles' placement
(Find) or new slicing handles (Suggest), with the candidate's design as the result, in one undo
step. In background mode (tests, scripts) the search runs inline.

Preview: clicking a candidate's Preview shows its wires and the planes it moves (or adds) as a
viewport overlay (ui/overlay.py draws PREVIEW), like Live's: module state only, no scene data and
no undo step. It lasts until Apply, a click on the same Preview (or another candidate's), Clear,
a new search or loading a file. The segments are made on the worker with the candidates
(candidate["preview"]), so a click only points at them.

Whose: a result belongs to the file and scene it was made for (blend/ownership.py: a token written
into the scene with the result, the scene's name and the file's generation), checked before the
panel lists it, the overlay draws its preview or Apply writes it; loading a file (File > New, Open,
Revert) forgets both. The search is an undo step of its own (it writes the token and nothing else),
so undoing later steps keeps its candidates, and undoing the search hides them.
"""
import copy
import threading
import time

import bpy
import numpy as np
from mathutils import Matrix, Vector

from .. import native, pipeline, plane_search
from ..blend import mesh, ownership
from ..blend import results as scene_results
from ..blend.handles import (PLANE_MARGIN, add_handle, contour_plane, handle_plane, handles,
                             model_problem)
from ..blend.contours import slice_scene
from ..blend.registration import classes_factory
from ..blend.view import redraw_3d_views
from ..core import session
from ..core.jobs import WorkerJob
from ..core.scene import PlaneSpec
from ..core import mesh_faults, standing
from ..core.sizes import mesh_size
from ..core.solve_context import SolveContext
from ..props import material_of, solver_settings
from .progress import JOIN_SECONDS, WorkerModal, busy

MAX_CANDIDATES = 3
UI_BUDGET_SECONDS = 60.0  # the panel's search may take longer than the batch's: Esc stops it
PLANE_COLOUR = (1.0, 0.85, 0.2, 1.0)  # the outline of a plane the previewed candidate moves or adds
OWNER_KIND = "plane_search"  # blend/ownership's kind of the assistant's result
# Refusals of Apply and Preview (causes as codes; the sentence is made in refusal())
NO_RESULT = "no_result"  # no search in this file yet
NOT_THIS_SCENE = "not_this_scene"  # the last search was another scene's
NO_CANDIDATE = "no_candidate"  # the index is not one of the candidates
# What the panel shows: {"owner", "scene", "mode", "candidates": [...], "message"} of the last
# search, or None; shown and applied only in the scene its owner names (current()).
RESULT = None
# The previewed candidate: {"scene", "index", "wires": [(RGBA, (2k, 3) float32)], "planes": [...]}, or None.
PREVIEW = None
DRAWN = [0]  # overlay draws of a preview (the tests read it)


def gather(context, need_planes=True):
    """(V, F, planes, material, settings) from the scene: the model's evaluated triangles, the
    handles as planes (each taking its ticked contours, else its largest). ValueError when not
    possible, naming what is missing."""
    scene = context.scene
    ws = scene.wiresculpt
    problem = model_problem(scene, ws.model)
    if problem:
        raise ValueError(problem)
    if not native.available():
        raise RuntimeError(native.LOAD_ERROR)
    depsgraph = context.evaluated_depsgraph_get()
    ticked = {}  # handle object -> its ticked contour indices (the ticks of a gone plane: none)
    for item in ws.contours:
        if item.use:
            ticked.setdefault(contour_plane(scene, item), []).append(item.index)
    planes = [PlaneSpec(*handle_plane(h, depsgraph), contours=ticked.get(h, "largest")) for h in handles(scene)]
    if need_planes and not planes:
        raise ValueError("No slicing plane: add planes first, or use Suggest Planes")
    settings = solver_settings(ws)
    V, F, _closing = mesh.model_triangles(ws.model, depsgraph, settings["min_segment"])  # closed for slicing
    return V, F, planes, material_of(ws), settings


def describe(candidate):
    """The candidate's figures as one line for the panel."""
    f = candidate["figures"]
    load = "n/a" if f["load_capacity"] is None else f"{f['load_capacity']:.1f}x weight"
    line = (f"holds {load}, deviation {f['max_deviation'] * 1000:.1f} mm, "
            f"closure gap {f['closure_gap'] * 1000:.1f} mm")
    if f.get("cause_3d") == standing.NO_EQUILIBRIUM:
        line += f", {standing.CANDIDATE_WORDS[f['cause_3d']]} in 3D"
    elif f.get("cause_3d") is not None:
        line += f", {standing.CANDIDATE_WORDS[f['cause_3d']]} in 3D (sag {f['sag'] * 1000:.1f} mm)"
    return line


def looks(candidate):
    """How the candidate looks like the model, as one line for the panel: the share of the outline
    its wires trace (its fidelity, core/fidelity.py; by view) and its coverage; None when its
    figures have neither."""
    f = candidate["figures"]
    if f.get("fidelity") is None:
        return None
    views = ", ".join(f"{name} {share:.0%}" for name, share in (f.get("views") or {}).items() if share is not None)
    line = f"traces {f['fidelity']:.0%} of the outline ({views})" if views else f"traces {f['fidelity']:.0%} of the outline"
    return line + (f", covers {f['coverage']:.0%} of the mesh" if f.get("coverage") is not None else "")


def plane_outline(origin, normal, half):
    """(8, 3) float32 segment end points of the square of side 2 * half centred at `origin` in the
    plane with unit `normal`."""
    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n)
    u = np.cross(n, [0.0, 0.0, 1.0] if abs(n[2]) < 0.9 else [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    corners = [np.asarray(origin, dtype=float) + half * (a * u + b * v) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    return scene_results.polyline_segments(corners, True)


def candidate_preview(candidate, mode, size):
    """What the overlay draws for a candidate: each design wire's shape (its target polyline, the
    contour where there is none; blend/results.wire_points) in the wire's colour, and the outline of
    every plane it moves (nearby) or adds (auto), PLANE_MARGIN times the model's `size` across."""
    wires = [(scene_results.wire_colour(w["id"]), scene_results.polyline_segments(scene_results.wire_points(w),
                                                                                   w["closed"]))
             for w in candidate["design"]["wires"]]
    planes = [(PLANE_COLOUR, plane_outline(p.origin, p.normal, 0.5 * PLANE_MARGIN * size))
              for p in candidate["planes"] if mode == "auto" or p.changes]
    return {"wires": wires, "planes": planes}


class SearchJob(WorkerJob):
    name = "wiresculpt plane search"

    def __init__(self, mode, V, F, planes, material, settings, count):
        super().__init__()
        self.mode, self.V, self.F, self.planes = mode, V, F, planes
        self.material, self.settings, self.count = material, settings, count
        self.found, self.searched = [], None
        self.mesh_faults = []  # core/mesh_faults.failures of the mesh when nothing was found
        self.cancel_event = threading.Event()
        self.cancelled = False
        self.messages = []
        self.scene_name = ""
        self.generation = session.generation()  # the file the search started in
        self.started = time.perf_counter()

    def _progress(self, stage, message):
        self.messages.append(message)

    def work(self):
        context = SolveContext(self._progress, self.cancel_event.is_set)
        try:
            if self.mode == "nearby":
                self.found, self.searched, _ = plane_search.nearby(
                    (self.V, self.F), self.planes, self.material, self.settings, MAX_CANDIDATES, UI_BUDGET_SECONDS,
                    context=context)
            else:
                self.found, self.searched, _ = plane_search.auto(
                    (self.V, self.F), self.count, self.material, self.settings, MAX_CANDIDATES, UI_BUDGET_SECONDS,
                    context=context)
        except pipeline.Cancelled:
            self.cancelled = True
            return
        if not self.found:  # what is wrong with the mesh, said before what the search tried
            self.mesh_faults = mesh_faults.failures(self.V, self.F)
        size = mesh_size(self.V)
        for candidate in self.found:
            candidate["preview"] = candidate_preview(candidate, self.mode, size)

    def stop(self, timeout=JOIN_SECONDS):
        self.cancel_event.set()
        self.thread.join(timeout)
        return not self.thread.is_alive()

    def status(self):
        if self.cancel_event.is_set():
            return "wiresculpt: cancelling…"
        return (f"wiresculpt: searching planes… {len(self.found)} found, "
                f"{time.perf_counter() - self.started:.0f} s (Esc to cancel)")


JOB = None


def running():
    return JOB is not None or busy("optimize")


class Refused(ValueError):
    """Apply or Preview has nothing to act on: `code` is NO_RESULT, NOT_THIS_SCENE or NO_CANDIDATE."""

    def __init__(self, code):
        super().__init__(refusal(code))
        self.code = code


def refusal(code):
    """The sentence of a refusal code."""
    return {NO_RESULT: "no candidates: run Find Stable Planes or Suggest Planes first",
            NOT_THIS_SCENE: ("the plane assistant's candidates belong to another scene or file: run Find Stable "
                             "Planes or Suggest Planes in this scene"),
            NO_CANDIDATE: "no such candidate: run Find Stable Planes or Suggest Planes again"}[code]


def current(context):
    """The last search's result when it was made for this scene of this file, else None."""
    if RESULT is None or context.scene is None or not ownership.owns(RESULT["owner"], context.scene):
        return None
    return RESULT


def _candidate(context, index):
    """(result, candidate `index`) of this scene's result; Refused otherwise."""
    result = current(context)
    if result is None:
        raise Refused(NO_RESULT if RESULT is None else NOT_THIS_SCENE)
    if not 0 <= index < len(result["candidates"]):
        raise Refused(NO_CANDIDATE)
    return result, result["candidates"][index]


def forget():
    """No result and no preview any more (a file is being loaded)."""
    global RESULT
    RESULT = None
    clear_preview()


def _store(job):
    """The finished search as RESULT, stamped for its scene; None when its file or scene is gone."""
    global RESULT
    clear_preview()
    scene = bpy.data.scenes.get(job.scene_name)
    owner = None if scene is None else ownership.stamp(scene, OWNER_KIND, job.generation)
    if owner is None:
        return None
    RESULT = {"owner": owner, "scene": job.scene_name, "mode": job.mode, "candidates": job.found,
              "message": (f"{len(job.found)} stable candidate{'s' if len(job.found) != 1 else ''} "
                          f"({job.searched.screened} screened, {job.searched.full_solves} solved, "
                          f"{time.perf_counter() - job.started:.1f} s)" if job.found else
                          f"No stable placement found: {mesh_faults.words(job.mesh_faults)} "
                          f"({job.searched.screened} screened, {job.searched.full_solves} solved)"
                          if job.mesh_faults else
                          f"No stable placement found: {plane_search.nearby_reason(job.searched)}"
                          if job.mode == "nearby" else
                          f"No stable placement found ({job.searched.screened} screened, "
                          f"{job.searched.full_solves} solved)")}
    return RESULT


class _SearchOperator(WorkerModal):
    mode = "nearby"
    verb = "Find Stable Planes"

    @classmethod
    def poll(cls, context):
        return not running()

    def _count(self, context):
        return 5

    def _finish(self, job):
        if job.cancelled or job.cancel_event.is_set():
            self.report({'WARNING'}, f"{self.verb} cancelled; the scene is unchanged")
            return {'CANCELLED'}
        if job.error is not None:
            self.report({'ERROR'}, f"{self.verb}: {job.error}")
            return {'CANCELLED'}
        result = _store(job)
        if result is None:
            self.report({'WARNING'}, f"{self.verb}: the file or scene searched was closed meanwhile; nothing to show")
            return {'CANCELLED'}
        self.report({'INFO'} if job.found else {'WARNING'}, f"{self.verb}: {result['message']}")
        return {'FINISHED'}

    def _job(self, context):
        V, F, planes, material, settings = gather(context, self.mode == "nearby")
        count = self._count(context)
        settings["plane_count"] = count  # the search's own key (core/settings.py), as the batch gives it
        job = SearchJob(self.mode, V, F, planes, material, settings, count)
        job.scene_name = context.scene.name
        return job

    def execute(self, context):
        try:
            job = self._job(context)
        except (ValueError, RuntimeError) as exc:
            self.report({'ERROR'}, f"{self.verb}: {exc}")
            return {'CANCELLED'}
        job.run()
        return self._finish(job)

    def invoke(self, context, event):
        global JOB
        if bpy.app.background or context.window is None:
            return self.execute(context)
        try:
            JOB = self._job(context)
        except (ValueError, RuntimeError) as exc:
            self.report({'ERROR'}, f"{self.verb}: {exc}")
            return {'CANCELLED'}
        JOB.thread.start()
        self.begin_watch(context, 1)
        self._show(context)
        return {'RUNNING_MODAL'}

    def _show(self, context):
        if JOB is not None:
            self.show_progress(context, 0, JOB.status())

    def modal(self, context, event):
        global JOB
        job = JOB
        if job is None:
            return {'CANCELLED'}
        answer = self.watch_event(context, event, job.thread, job.stop)
        if answer is not None:
            return answer
        self.end_watch(context)
        JOB = None
        return self._finish(job)

    def cancel(self, context):
        global JOB
        if JOB is not None:
            try:
                self.end_watch(context)
            except (AttributeError, ReferenceError, RuntimeError):
                pass
            JOB.stop()
            JOB = None


class WIRESCULPT_OT_find_planes(_SearchOperator, bpy.types.Operator):
    """Search placements near the slicing planes (offsets, small tilts, other contours) for the
    smallest change that gives a stable, buildable sculpture; the scene is not changed until you
    Apply a candidate (Esc cancels)"""
    bl_idname = "wiresculpt.find_planes"
    bl_label = "Find Stable Planes"
    bl_options = {'REGISTER', 'UNDO'}  # the result's token in the scene: undoing the search hides it
    mode = "nearby"
    verb = "Find Stable Planes"


class WIRESCULPT_OT_suggest_planes(_SearchOperator, bpy.types.Operator):
    """Propose slicing planes from the mesh alone (families along its principal axes), ranked by
    coverage and fidelity; Apply adds them as ordinary slicing planes (Esc cancels)"""
    bl_idname = "wiresculpt.suggest_planes"
    bl_label = "Suggest Planes"
    bl_options = {'REGISTER', 'UNDO'}
    mode = "auto"
    verb = "Suggest Planes"

    count: bpy.props.IntProperty(name="Planes", description="How many planes to propose (unset: the panel's "
                                 "Planes)", default=5, min=2, max=12)

    def _count(self, context):
        """The operator's count when given, else the panel's (scene setting plane_count)."""
        return self.count if self.properties.is_property_set("count") else context.scene.wiresculpt.plane_count


def _place(obj, origin, normal):
    """Moves `obj` (a handle) so that its world Z axis is `normal` and its world location `origin`,
    keeping its scale and its turn about Z as far as the new normal allows."""
    loc, rot, scale = obj.matrix_world.decompose()
    z = (rot @ Vector((0.0, 0.0, 1.0))).normalized()
    new_rot = z.rotation_difference(Vector(normal).normalized()) @ rot
    obj.matrix_world = Matrix.LocRotScale(Vector(origin), new_rot, scale)


def apply_candidate(context, index):
    """The candidate's planes into the scene (moved handles, or new ones for Suggest), sliced, the
    design's contours ticked, and its design as the result. Returns (the candidate, Slice's
    sentence: the contours and how many are wires). ValueError when there is no such candidate in
    this scene (Refused: its code says why) or a plane it moves is gone."""
    result, candidate = _candidate(context, index)
    scene = context.scene
    design = candidate["design"]
    if result["mode"] == "nearby":
        by_name = {h.name: h for h in handles(scene)}
        missing = [p.name for p in candidate["planes"] if p.name not in by_name]
        if missing:
            raise ValueError(f"slicing plane {missing[0]} is gone: search again")
        for p in candidate["planes"]:
            _place(by_name[p.name], p.origin, p.normal)
    else:
        V, _F = mesh.object_triangles(scene.wiresculpt.model, context.evaluated_depsgraph_get())
        renamed = {}
        for p in candidate["planes"]:
            obj = add_handle(context, V.min(axis=0), V.max(axis=0))
            obj.name = p.name  # Blender adds a suffix when the name is taken
            obj.data.name = obj.name
            renamed[p.name] = obj.name
            _place(obj, p.origin, p.normal)
        design = copy.deepcopy(design)
        for w in design["wires"]:
            plane, index = w["name"].split("/")
            w["name"] = f"{renamed[plane]}/{index}"
    context.view_layer.update()
    level, sliced = slice_scene(context, {w["name"] for w in design["wires"]})  # ticked as the design's wires
    if 'ERROR' in level:
        raise ValueError(sliced)
    scene_results.write_results(scene, design)
    clear_preview()  # the candidate is now the scene's own
    return candidate, sliced


def clear_preview():
    """No candidate previewed any more (the overlay stops drawing it)."""
    global PREVIEW
    if PREVIEW is not None:
        PREVIEW = None
        try:
            redraw_3d_views()
        except (AttributeError, ReferenceError):  # no window (closing, loading)
            pass


def preview_candidate(context, index):
    """Previews candidate `index` of the last search (or stops previewing it when it is the one
    shown); True when a candidate is previewed after. Refused when there is no such candidate in this
    scene."""
    global PREVIEW
    _result, candidate = _candidate(context, index)
    if previewed(context) == index:
        clear_preview()
        return False
    shown = candidate["preview"]
    PREVIEW = {"scene": context.scene.name, "index": index, "wires": shown["wires"], "planes": shown["planes"]}
    redraw_3d_views()
    return True


def previewed(context):
    """The index of the candidate previewed in this scene, or None."""
    if PREVIEW is None or current(context) is None or PREVIEW["scene"] != context.scene.name:
        return None
    return PREVIEW["index"]


class WIRESCULPT_OT_apply_planes(bpy.types.Operator):
    """Move the slicing planes to this candidate (or add its planes) and show its sculpture; one
    Undo takes it all back"""
    bl_idname = "wiresculpt.apply_planes"
    bl_label = "Apply"
    bl_options = {'REGISTER', 'UNDO'}

    index: bpy.props.IntProperty(default=0, min=0)

    @classmethod
    def poll(cls, context):
        return not running()  # without candidates in this scene, execute refuses and says why

    def execute(self, context):
        try:
            candidate, sliced = apply_candidate(context, self.index)
        except ValueError as exc:
            self.report({'ERROR'}, f"Cannot apply: {exc}")
            return {'CANCELLED'}
        self.report({'INFO'}, "Applied: " + ("; ".join(candidate["changes"]) or "the planes as they were")
                    + f". {sliced}")
        return {'FINISHED'}


class WIRESCULPT_OT_preview_planes(bpy.types.Operator):
    """Show this candidate's wires and the planes it moves in the viewport, without changing the
    scene (click again to hide it)"""
    bl_idname = "wiresculpt.preview_planes"
    bl_label = "Preview"
    bl_options = {'INTERNAL'}  # no UNDO: a preview is no scene change and no undo step

    index: bpy.props.IntProperty(default=0, min=0)

    @classmethod
    def poll(cls, context):
        result = current(context)
        return result is not None and bool(result["candidates"])

    def execute(self, context):
        try:
            preview_candidate(context, self.index)
        except ValueError as exc:
            self.report({'ERROR'}, f"Cannot preview: {exc}")
            return {'CANCELLED'}
        return {'FINISHED'}


class WIRESCULPT_OT_preview_planes_clear(bpy.types.Operator):
    """Hide the previewed candidate"""
    bl_idname = "wiresculpt.preview_planes_clear"
    bl_label = "Clear Preview"
    bl_options = {'INTERNAL'}

    def execute(self, context):
        if PREVIEW is None:
            return {'CANCELLED'}
        clear_preview()
        return {'FINISHED'}


class WIRESCULPT_OT_find_planes_cancel(bpy.types.Operator):
    """Stop the running plane search; the scene stays as it was"""
    bl_idname = "wiresculpt.find_planes_cancel"
    bl_label = "Cancel"
    bl_options = {'INTERNAL'}

    def execute(self, context):
        if JOB is None:
            self.report({'INFO'}, "Nothing to cancel: no plane search is running")
            return {'CANCELLED'}
        JOB.cancel_event.set()  # the modal finishes once the worker has ended
        self.report({'INFO'}, "Cancelling the plane search…")
        return {'FINISHED'}


_register, _unregister = classes_factory((WIRESCULPT_OT_find_planes, WIRESCULPT_OT_suggest_planes,
                                          WIRESCULPT_OT_apply_planes, WIRESCULPT_OT_preview_planes,
                                          WIRESCULPT_OT_preview_planes_clear, WIRESCULPT_OT_find_planes_cancel))


def register():
    _register()
    ownership.register()
    ownership.on_load(forget)


def unregister():
    ownership.unregister()
    forget()
    _unregister()
