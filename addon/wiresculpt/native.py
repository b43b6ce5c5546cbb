"""The compiled solver, or the reason it cannot be loaded.

Everything else in the add-on reaches the native module through this file. It validates the
shapes and types of arrays before anything crosses into C++ (a bad array is a ValueError here,
never a crash inside the module), and when the module is missing it records a sentence the
panel shows to the user instead of failing to register.
"""
import os
import re
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def built_for():
    """The Pythons the compiled modules beside this file were built for, e.g. ["3.11"], from their
    file names (_wiresculpt.cpython-311-x86_64-linux-gnu.so)."""
    try:
        names = os.listdir(HERE)
    except OSError:
        return []
    tags = (re.match(r"_wiresculpt\.cpython-(\d)(\d+)", n) for n in names)
    return sorted({f"{t.group(1)}.{t.group(2)}" for t in tags if t}, key=lambda v: tuple(map(int, v.split("."))))


def host_name():
    """ "Blender 4.0.2" inside Blender (bpy already imported), else "this Python"."""
    bpy = sys.modules.get("bpy")
    version = getattr(getattr(bpy, "app", None), "version_string", None)
    return f"Blender {version}" if version else "this Python"


def explain_load_error(exc, builds, python=None, host=None):
    """One sentence saying why the solver did not load and what to do: the Python the zip was
    built for against the one running, or the shared library the loader could not find."""
    python = python or f"{sys.version_info[0]}.{sys.version_info[1]}"
    host = host or host_name()
    text = str(exc)
    if builds and python not in builds:
        advice = ("use Blender 4.1+" if tuple(map(int, python.split("."))) < (3, 11) else
                  "use a Blender whose Python is " + " or ".join(builds))
        return (f"The wiresculpt solver did not load: this build is for Python {' and '.join(builds)}; "
                f"{host} uses {python}: {advice} or build from source with scripts/package.")
    missing = re.search(r"([\w.+-]+\.so[\w.]*): cannot open shared object file", text)
    if missing:
        return (f"The wiresculpt solver did not load: the library {missing.group(1)} is missing. The "
                f"packaged zip carries it in wiresculpt/libs: install the zip again (Preferences > "
                "Add-ons > Install), or install it on the system, or build from source with scripts/package.")
    if not builds:
        return ("The wiresculpt solver (_wiresculpt) is not built: build it with scripts/setup, or "
                "install the packaged zip (scripts/package).")
    return f"The wiresculpt solver (_wiresculpt) did not load in {host}: {text}"


try:
    from . import _wiresculpt as module
    LOAD_ERROR = ""
except ImportError as exc:  # not built, built for another Python, or a library missing
    module = None
    LOAD_ERROR = explain_load_error(exc, built_for())


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
