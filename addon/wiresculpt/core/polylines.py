"""Polyline measures on (n, d) point arrays, metres."""
import numpy as np


def polyline_length(points, closed):
    """Sum of edge lengths; a closed polyline includes the edge from its last point to its first."""
    p = np.asarray(points, dtype=np.float64)
    if len(p) < 2:
        return 0.0
    if closed:
        p = np.concatenate([p, p[:1]])
    return float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1)))
