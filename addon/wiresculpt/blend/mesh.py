"""Blender meshes as numpy arrays for the solver (world-space, triangulated, modifiers applied), and
mesh files read into such arrays through Blender's own importers, coordinates exactly as written in
the file (docs/formats.md: no axis conversion, every object of the file joined into one mesh).

A mesh with holes, several parts or non-manifold edges is closed for slicing (close_for_slicing,
the rule in core/mesh_faults.py): its holes capped, then remeshed by voxels, on a temporary mesh
that is removed again; the user's mesh object is never changed."""
import contextlib
import io
import os
import sys

import bmesh
import bpy
import numpy as np
from mathutils.bvhtree import BVHTree

from . import compat
from ..core import mesh_faults, meshcheck
from ..core.sizes import mesh_size


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


LOST_SAMPLES = 20_000  # original vertices at most measured against the closed surface (lost)
# The remesh's grid is aligned with the origin, and its vertices lie on the grid's layers: a plane
# through a layer (an axis-aligned plane through the origin, say) would meet faces lying in it and
# cut specks of contours. The mesh is moved by these fractions of a voxel for the remesh and back.
GRID_SHIFT = (0.3183098861837907, 0.2718281828459045, 0.1414213562373095)
_closings = {}  # the last closing: "key" (digest, voxel), "V", "F", "record"


def _temporary_mesh(V, F, name):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(np.asarray(V, dtype=np.float64).tolist(), [], np.asarray(F, dtype=np.int64).tolist())
    mesh.update()
    return mesh


def _capped(mesh, weld):
    """Welds vertices closer than `weld` and fills every hole of `mesh` (its boundary loops) with
    triangles, in place."""
    bm = bmesh.new()
    try:
        bm.from_mesh(mesh)
        bmesh.ops.remove_doubles(bm, verts=bm.verts, dist=weld)
        boundary = [e for e in bm.edges if e.is_boundary]
        if boundary:
            filled = bmesh.ops.holes_fill(bm, edges=boundary, sides=0)
            if filled["faces"]:
                bmesh.ops.triangulate(bm, faces=filled["faces"])
        bm.to_mesh(mesh)
    finally:
        bm.free()


def _voxel_remesh(mesh, voxel):
    """`mesh` remeshed by Blender's voxel remesh (the Remesh operator of the mesh's Object Data
    properties) of `voxel` m, through a temporary object that no scene holds."""
    obj = bpy.data.objects.new(mesh.name, mesh)
    try:
        mesh.remesh_voxel_size = voxel
        mesh.remesh_voxel_adaptivity = 0.0
        with bpy.context.temp_override(object=obj, active_object=obj, selected_objects=[obj],
                                       selected_editable_objects=[obj]):
            done = bpy.ops.object.voxel_remesh()
        if "FINISHED" not in done:
            raise RuntimeError(f"Blender's voxel remesh ended {', '.join(sorted(done))}")
    finally:
        bpy.data.objects.remove(obj)
    return mesh_triangles(mesh)


def mesh_triangles(mesh):
    """(V, F) of a mesh datablock's loop triangles, in its own coordinates."""
    mesh.calc_loop_triangles()
    V = np.empty(len(mesh.vertices) * 3, dtype=np.float64)
    mesh.vertices.foreach_get("co", V)
    F = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", F)
    return V.reshape(-1, 3), F.reshape(-1, 3)


def _lost(V, closedV, closedF, voxel):
    """(share, centre or None): the share of the vertices V (at most LOST_SAMPLES of them, evenly)
    outside the closed surface (closedV, closedF) and farther than `voxel` from it, and the centre of
    their box. A vertex inside (a part's corner within another part, fused away) is not lost: the
    remesh's faces face outwards, so a vertex behind its nearest face is inside."""
    tree = BVHTree.FromPolygons(closedV.tolist(), closedF.tolist())
    sample = V[::max(1, len(V) // LOST_SAMPLES)]
    far = []
    for p in sample:
        location, normal, _index, distance = tree.find_nearest(p)
        if location is None or (distance > voxel and (p - np.asarray(location)) @ np.asarray(normal) > 0):
            far.append(p)
    if not far:
        return 0.0, None
    far = np.asarray(far)
    return len(far) / len(sample), 0.5 * (far.min(axis=0) + far.max(axis=0))


def close_for_slicing(V, F, min_segment):
    """(V, F, record): the mesh (V, F) itself and None when it is one closed part (core/mesh_faults
    .check finds nothing), else the mesh closed for slicing (holes capped, then a voxel remesh of
    mesh_faults.closing_voxel of its size and `min_segment`) and the closing's record
    (mesh_faults.closing), which the pipeline writes into the design as `mesh_closing`
    (mesh_faults.remember). Works on temporary data only, removed again; RuntimeError when
    Blender's remesh fails. The last closing is kept: Live and the plane assistant ask again."""
    faults = mesh_faults.check(V, F)
    if not mesh_faults.needs_closing(faults):
        return V, F, None
    size = mesh_size(V)
    voxel = mesh_faults.closing_voxel(size, min_segment)
    key = (mesh_faults._digest(V, F), voxel)
    if _closings.get("key") != key:
        shift = voxel * np.asarray(GRID_SHIFT)
        mesh = _temporary_mesh(np.asarray(V, dtype=np.float64) + shift, F, "wiresculpt closing (temporary)")
        try:
            _capped(mesh, mesh_faults.WELD * size)
            closedV, closedF = _voxel_remesh(mesh, voxel)
        finally:
            bpy.data.meshes.remove(mesh)
        closedV -= shift
        closedF, specks = mesh_faults.drop_specks(closedV, closedF)
        if not len(closedF):
            raise RuntimeError(f"closing the mesh for slicing by a {voxel * 1000:.1f} mm voxel remesh left nothing "
                               "(a mesh of sheets without inside): give the parts thickness")
        lost, lost_at = _lost(np.asarray(V, dtype=np.float64), closedV, closedF, voxel)
        record = mesh_faults.closing(faults, mesh_faults.check(closedV, closedF), voxel, len(closedF), lost, lost_at,
                                     specks)
        _closings.clear()
        _closings.update(key=key, V=closedV, F=closedF, record=record)
    mesh_faults.remember(_closings["V"], _closings["F"], _closings["record"])
    return _closings["V"], _closings["F"], dict(_closings["record"])


def model_triangles(obj, depsgraph, min_segment):
    """(V, F, record) of the model `obj` as it is sliced: object_triangles, closed for slicing when
    it has holes, several parts or non-manifold edges (close_for_slicing; record None otherwise)."""
    return close_for_slicing(*object_triangles(obj, depsgraph), min_segment)
