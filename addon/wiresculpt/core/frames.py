"""A plane's 2D frame, the same one the native core uses (Plane::make in geometry.hpp): u is the
world axis least aligned with the normal, projected into the plane; v = n x u."""
import numpy as np


def plane_frame(normal):
    """(n, u, v): unit normal and in-plane axes with u x v = n."""
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    seed = np.zeros(3)
    seed[int(np.argmin(np.abs(n)))] = 1.0
    u = seed - seed.dot(n) * n
    u /= np.linalg.norm(u)
    return n, u, np.cross(n, u)


def to_2d(points, origin, u, v):
    p = np.asarray(points, dtype=np.float64) - np.asarray(origin, dtype=np.float64)
    return np.stack([p @ u, p @ v], axis=1)


def to_3d(points2, origin, u, v):
    q = np.asarray(points2, dtype=np.float64)
    return np.asarray(origin, dtype=np.float64) + np.outer(q[:, 0], u) + np.outer(q[:, 1], v)
