"""Is the model's mesh still the one the stored design was solved on? Optimize records a digest of
the triangles it sliced (core/stale.mesh_digest of blend/mesh.object_triangles: world coordinates,
modifiers applied), and the Stability box compares the model's now with it (mesh_state).

Reading a mesh at every redraw would cost 25 ms at 100,000 triangles, so it is read again only
after a change that may have moved it (`generation` counts them): the depsgraph reporting the
model's geometry or placement changed (an edit, a modifier, a move), a frame change (animation
reports no update), an undo or a redo; at most once per change, and not while the changes follow
each other (a drag): then, and for a model over mesh.MAX_REREAD_TRIANGLES, a change since the
digest last taken counts as one (MESH_CHANGED), and the 3D views are asked to redraw once the
changes have settled, when the next reading may take it back. A model the depsgraph does not evaluate (hidden
from viewports, in an excluded collection) is not read: without its modifiers it would not be
the mesh Optimize sliced.

Only module state is written here (no ID data: the handler runs after every update and the state
is asked for from a panel's draw)."""
import time

import bpy

from ..core.stale import MESH_CHANGED, mesh_digest
from .mesh import MAX_REREAD_TRIANGLES, object_triangles, triangle_count
from .registration import handlers_factory
from .view import redraw_3d_views

SETTLE_SECONDS = 0.3  # a model changed more recently is still moving: not read yet

# digest: (model name, generation, digest) of the last reading; changed_at: time.monotonic() of
# the last change counted
_STATE = {"generation": 0, "digest": None, "changed_at": 0.0}


def remember(model, vertices, faces):
    """The digest of the triangles just read from `model` (Optimize's), kept for the current
    generation; returned."""
    digest = mesh_digest(vertices, faces)
    _STATE["digest"] = (model.name, _STATE["generation"], digest)
    return digest


def kept_digest(model):
    """The digest taken of `model` since its last change, or None."""
    kept = _STATE["digest"]
    return kept[2] if kept is not None and kept[0] == model.name and kept[1] == _STATE["generation"] else None


def mesh_state(model, depsgraph):
    """The digest of `model` as evaluated in `depsgraph`, read again when it changed since the
    last reading; MESH_CHANGED when it changed since a reading of it but is not read now (still
    moving, or over MAX_REREAD_TRIANGLES); None when unknown (never read and not readable now)."""
    kept = kept_digest(model)
    if kept is not None:
        return kept
    earlier = _STATE["digest"] is not None and _STATE["digest"][0] == model.name
    if time.monotonic() - _STATE["changed_at"] < SETTLE_SECONDS:
        if not bpy.app.timers.is_registered(_settled):
            bpy.app.timers.register(_settled, first_interval=SETTLE_SECONDS)
        return MESH_CHANGED if earlier else None
    if not model.evaluated_get(depsgraph).is_evaluated:
        return None
    if triangle_count(model, depsgraph) > MAX_REREAD_TRIANGLES:
        return MESH_CHANGED if earlier else None
    return remember(model, *object_triangles(model, depsgraph))


def _settled():
    """Once the changes have settled: the panels read the model again at their next redraw."""
    try:
        redraw_3d_views()
    except (AttributeError, ReferenceError):  # no window (closing, background)
        pass
    return None


def _changed():
    _STATE["generation"] += 1
    _STATE["changed_at"] = time.monotonic()


@bpy.app.handlers.persistent
def _depsgraph_post(scene=None, depsgraph=None, *_args):
    """Counts the updates that changed the scene's model's geometry or placement."""
    try:
        model = scene.wiresculpt.model if scene is not None else None
        if model is None or depsgraph is None:
            return
        watched = (model, model.data)
        for update in depsgraph.updates:
            if (update.is_updated_geometry or update.is_updated_transform) and update.id.original in watched:
                _changed()
                return
    except (AttributeError, ReferenceError):  # closing, loading, the add-on half unregistered
        pass


@bpy.app.handlers.persistent
def _maybe_changed(*_args):
    """A frame change (animation moves a mesh without a depsgraph update), an undo or a redo."""
    _changed()


@bpy.app.handlers.persistent
def _load_post(*_args):
    """Another file: no reading of this session holds for its model, even by the same name."""
    _STATE["digest"] = None


register, _remove_handlers = handlers_factory((
    ("depsgraph_update_post", _depsgraph_post), ("frame_change_post", _maybe_changed), ("undo_post", _maybe_changed),
    ("redo_post", _maybe_changed), ("load_post", _load_post)))


def unregister():
    if bpy.app.timers.is_registered(_settled):
        bpy.app.timers.unregister(_settled)
    _remove_handlers()
