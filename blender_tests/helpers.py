"""Shared by the Blender suites: paths, running Blender in a subprocess, small mesh writers, a circle."""
import math
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BATCH = os.path.join(ROOT, "scripts", "wiresculpt_batch.py")
BLENDER = os.environ.get("BLENDER") or sys.argv[0] or "blender"


def run_blender(script, *args, env=None, timeout=300):
    """Runs `script` in a fresh headless Blender; returns the CompletedProcess (text output)."""
    cmd = [BLENDER, "--background", "--factory-startup", "--python-exit-code", "1",
           "--python", script, "--", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                          env={**os.environ, **(env or {})})


def wiresculpt_lines(text):
    """The lines the batch script itself printed (Blender adds its own)."""
    return [line for line in text.splitlines() if line.startswith("wiresculpt:")]


def box_faces():
    """The 12 triangles of the box whose vertex i has coordinates chosen by the bits of i."""
    quads = [(0, 2, 6, 4), (1, 5, 7, 3), (0, 4, 5, 1), (2, 3, 7, 6), (0, 1, 3, 2), (4, 6, 7, 5)]
    return [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]


def box_vertices(lo, hi):
    return [tuple(hi[k] if (i >> k) & 1 else lo[k] for k in range(3)) for i in range(8)]


def write_obj(path, vertices, faces):
    with open(path, "w") as f:
        f.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in vertices)
        f.writelines("f " + " ".join(str(i + 1) for i in t) + "\n" for t in faces)


def write_stl(path, vertices, faces):
    with open(path, "w") as f:
        f.write("solid box\n")
        for t in faces:
            f.write(" facet normal 0 0 0\n  outer loop\n")
            f.writelines("   vertex %r %r %r\n" % vertices[i] for i in t)
            f.write("  endloop\n endfacet\n")
        f.write("endsolid box\n")


def write_ply(path, vertices, faces):
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\n")
        f.write(f"element vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\n")
        f.write(f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
        f.writelines(f"{x!r} {y!r} {z!r}\n" for x, y, z in vertices)
        f.writelines("3 " + " ".join(map(str, t)) + "\n" for t in faces)


def polyline_length(points, closed):
    n = len(points)
    edges = range(n if closed else n - 1)
    return sum(math.dist(points[i], points[(i + 1) % n]) for i in edges)


def circle(normal, radius=0.1, n=64):
    """n points of the circle of `radius` metres about the origin in the plane of `normal`."""
    normal = np.asarray(normal, float)
    u = np.cross(normal, [0.0, 0.0, 1.0] if abs(normal[2]) < 0.9 else [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    t = np.linspace(0, 2 * math.pi, n, endpoint=False)
    return radius * (np.outer(np.cos(t), u) + np.outer(np.sin(t), v))
