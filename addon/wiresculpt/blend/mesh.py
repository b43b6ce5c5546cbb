"""Blender meshes as numpy arrays for the solver (world-space, triangulated, modifiers applied), and
mesh files read into such arrays through Blender's own importers, coordinates exactly as written in
the file (docs/formats.md: no axis conversion, every object of the file joined into one mesh)."""
import contextlib
import io
import os
import sys

import bpy
import numpy as np

from . import compat
from ..core import meshcheck


def object_triangles(obj, depsgraph):
    """(V, F) of `obj` as evaluated in `depsgraph`: V (#V, 3) float64 world coordinates, F (#F, 3)
    int32 indices of its loop triangles (n-gons split the way Blender draws them)."""
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        V = np.empty(len(mesh.vertices) * 3, dtype=np.float64)
        mesh.vertices.foreach_get("co", V)
        V = V.reshape(-1, 3)
        F = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
        mesh.loop_triangles.foreach_get("vertices", F)
        F = F.reshape(-1, 3)
        M = np.array(evaluated.matrix_world, dtype=np.float64)
        # an Inf or 1e308 coordinate makes NaN or Inf here without numpy's RuntimeWarning: the
        # mesh checks after (core.meshcheck.check_vertices) name the vertex in one sentence
        with np.errstate(invalid="ignore", over="ignore"):
            V = V @ M[:3, :3].T + M[:3, 3]
        return V, F
    finally:
        evaluated.to_mesh_clear()


# The most triangles read again on Blender's own thread whenever a model changes (Live, the
# Stability box's check of the model): object_triangles took 52-56 ms at 199,200 triangles and
# 24-26 ms at 101,888 (a UV sphere, background Blender), against the 50 ms a Live step may take.
MAX_REREAD_TRIANGLES = 100_000


def triangle_count(obj, depsgraph=None):
    """Triangles of the mesh `obj` from its polygons: as evaluated in `depsgraph` (its modifiers
    applied, but for a last subdivision Blender leaves to the GPU), else its own data. Far cheaper
    than object_triangles: no mesh is copied."""
    polygons = (obj.evaluated_get(depsgraph) if depsgraph is not None else obj).data.polygons
    totals = np.empty(len(polygons), dtype=np.int32)
    polygons.foreach_get("loop_total", totals)
    return int((totals - 2).sum())


def join_triangles(parts):
    """One (V, F) from several, re-indexing faces."""
    Vs, Fs, offset = [], [], 0
    for V, F in parts:
        Vs.append(V)
        Fs.append(F + offset)
        offset += len(V)
    if not Vs:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int32)
    return np.concatenate(Vs), np.concatenate(Fs).astype(np.int32)

FORMATS = (".obj", ".stl", ".ply")


def import_mesh(path):
    """(V, F, objects): the file's meshes joined, world coordinates equal to the file's numbers.
    ValueError for a missing, unreadable or empty file."""
    if not os.path.isfile(path):
        raise ValueError(f"mesh file not found: {path}")
    ext = os.path.splitext(path)[1].lower()
    if ext not in FORMATS:
        raise ValueError(f"mesh file {path}: unsupported format {ext or '(none)'}; use OBJ, STL or PLY")
    meshcheck.check_file(path)  # what the importer would drop silently or choke on
    before = set(bpy.data.objects)
    # An importer written in Python prints its traceback through sys.stderr before bpy.ops raises:
    # keep it (WIRESCULPT_DEBUG=1 shows it) and give the user the exception's last line only.
    caught = io.StringIO()
    try:
        with contextlib.redirect_stderr(caught):
            result = compat.IMPORTERS[ext](path)
    except RuntimeError as exc:
        if os.environ.get("WIRESCULPT_DEBUG"):
            sys.__stderr__.write(caught.getvalue())
        lines = [l.strip() for l in str(exc).strip().splitlines() if l.strip()]
        raise ValueError(f"mesh file {path}: Blender could not read it ({lines[-1] if lines else 'no reason given'})") from None
    if "FINISHED" not in result:
        raise ValueError(f"mesh file {path}: Blender could not read it")
    objects = [o for o in bpy.data.objects if o not in before and o.type == "MESH"]
    if not objects:
        raise ValueError(f"mesh file {path} holds no mesh")
    depsgraph = bpy.context.evaluated_depsgraph_get()
    V, F = join_triangles([object_triangles(o, depsgraph) for o in objects])
    if len(V) == 0:
        raise ValueError(f"mesh file {path} has no vertices")
    if len(F) == 0:
        raise ValueError(f"mesh file {path} has no faces (only points or edges): planes cut surfaces")
    return V, F, objects
