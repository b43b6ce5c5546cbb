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
    # np.stack([p @ u, p @ v], axis=1) without its wrappers: the same products, 4.5 us against 7 us
    # for a 48-point contour (the target-shape stage, once per wire and solve, before its first wire)
    out = np.empty((len(p), 2))
    out[:, 0] = p @ u
    out[:, 1] = p @ v
    return out


def to_3d(points2, origin, u, v):
    q = np.asarray(points2, dtype=np.float64)
    # origin + outer(q[:, 0], u) + outer(q[:, 1], v), broadcast: the same products and sums
    return np.asarray(origin, dtype=np.float64) + q[:, 0:1] * u + q[:, 1:2] * v


def rigid_fit_2d(src, dst):
    """(M, t): the rigid map x -> M x + t (a rotation, or a rotation and a mirror when that fits
    better) taking the 2D points `src` closest to `dst` in least squares (both (n, 2), matched by
    row; Kabsch). Used to lay a wire's rest frame onto its plane."""
    a, b = np.asarray(src, dtype=np.float64), np.asarray(dst, dtype=np.float64)
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    U, _s, Vt = np.linalg.svd((a - ca).T @ (b - cb))
    d = 1.0 if np.linalg.det(Vt.T @ U.T) >= 0 else -1.0  # diag(1, d): the best rotation (Kabsch)
    best = None
    for last in (d, -d):  # the rotation, then the mirrored map
        M = Vt.T @ np.diag([1.0, last]) @ U.T
        t = cb - M @ ca
        residual = float(np.sum((a @ M.T + t - b) ** 2))
        if best is None or residual < best[0] - 1e-18:
            best = (residual, M, t)
    return best[1], best[2]
