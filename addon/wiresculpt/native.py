"""The compiled solver, or the reason it cannot be loaded.

Everything else in the add-on reaches the native module through this file. It validates the
shapes and types of arrays before anything crosses into C++ (a bad array is a ValueError here,
never a crash inside the module), and when the module is missing it records a sentence the
panel shows to the user instead of failing to register.
"""
import numpy as np

try:
    from . import _wiresculpt as module
    LOAD_ERROR = ""
except ImportError as exc:  # not built, or built for another Python
    module = None
    LOAD_ERROR = (
        "The wiresculpt solver (_wiresculpt) is not installed for this Blender's Python "
        f"({exc}). Build it with scripts/test or install the packaged zip."
    )


def available():
    return module is not None


def require():
    """The loaded module; RuntimeError with the reason when it is missing."""
    if module is None:
        raise RuntimeError(LOAD_ERROR)
    return module


def as_points(array, what, columns=3):
    """A C-contiguous float64 (n, columns) array, or ValueError naming `what`."""
    a = np.asarray(array, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != columns:
        raise ValueError(f"{what} must be an array of shape (n, {columns}), got {a.shape}")
    return np.ascontiguousarray(a)


def as_triangles(array, vertex_count, what="faces"):
    """A C-contiguous int32 (n, 3) array of valid vertex indices, or ValueError."""
    a = np.asarray(array)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{what} must be an array of shape (n, 3), got {a.shape}")
    if a.size and not np.issubdtype(a.dtype, np.integer):
        raise ValueError(f"{what} must hold integer vertex indices, got {a.dtype}")
    if a.size and (a.min() < 0 or a.max() >= vertex_count):
        bad = int(np.argmax((a < 0).any(axis=1) | (a >= vertex_count).any(axis=1)))
        raise ValueError(f"triangle {bad} of {what} refers to a vertex outside 0..{vertex_count - 1}")
    return np.ascontiguousarray(a, dtype=np.int32)


def slice_mesh(vertices, faces, planes, weld_tolerance=-1.0):
    """Slice a triangle mesh by planes.

    vertices: (#V, 3) metres; faces: (#F, 3) indices; planes: [(name, origin, normal)].
    Returns {"contours": [per plane: [{"points", "closed", "length"}]], "mesh": statistics}.
    """
    V = as_points(vertices, "vertices")
    F = as_triangles(faces, len(V))
    specs = []
    for name, origin, normal in planes:
        specs.append((str(name), tuple(float(x) for x in origin), tuple(float(x) for x in normal)))
    return require().slice_mesh(V, F, specs, float(weld_tolerance))
