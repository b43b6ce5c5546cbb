"""A plane's 2D frame: the native core's own (Plane::make in geometry.hpp, through
native.plane_frame), so the frame is defined once; u is the world axis least aligned with the
normal, projected into the plane; v = n x u."""
import numpy as np

from .. import native


def plane_frame(normal):
    """(n, u, v): unit normal and in-plane axes with u x v = n (float64 arrays of shape (3,))."""
    return native.plane_frame(normal)


def to_2d(points, origin, u, v):
    p = np.asarray(points, dtype=np.float64) - np.asarray(origin, dtype=np.float64)
    return np.stack([p @ u, p @ v], axis=1)


def to_3d(points2, origin, u, v):
    q = np.asarray(points2, dtype=np.float64)
    return np.asarray(origin, dtype=np.float64) + np.outer(q[:, 0], u) + np.outer(q[:, 1], v)
