"""Blender meshes as numpy arrays for the solver: world-space, triangulated, modifiers applied."""
import numpy as np


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
        V = V @ M[:3, :3].T + M[:3, 3]
        return V, F
    finally:
        evaluated.to_mesh_clear()


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
