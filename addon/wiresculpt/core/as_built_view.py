"""What the as-built ghosts show (ui/overlay draws them; docs/user-guide.md, Result > Show As Built):
each wire of the 3D check (stages/stands3d.py) as it would stand, `wires[].as_built`, its points
coloured by their distance from the target point each was walked from, on a ramp from 0 to the
design's sag limit; the crossings whose 3D force leaves its pyramid marked. bpy-free.

`as_built` has one point per rest point, walked from the cut (a closed wire's last point is its
cut again): point i belongs to target vertex walk(...)[i]. The ghost may be drawn with its shape
change exaggerated `scale` times about the target (scale 1: the as-built points themselves); the
colours are always the true distances.
"""
import numpy as np

from . import standing

# The ramp over the distance as a share of the sag limit (RGBA, linear): blue at the target,
# yellow at half the limit, red at the limit and beyond (clamped).
RAMP = ((0.0, (0.10, 0.35, 1.00, 1.0)), (0.5, (1.00, 0.85, 0.00, 1.0)), (1.0, (1.00, 0.10, 0.10, 1.0)))
SLIP_COLOUR = (1.0, 0.0, 1.0, 1.0)  # magenta: not on the ramp
MARK_SHARE = 0.03  # half the arms of a slipping crossing's mark, as a share of the sculpture's size


def walk(n, closed, cut):
    """Target vertex of each as-built point (as stages/stands3d.walk, rest_shape.hpp's wire_walk):
    from the cut round to it again for a closed wire of `n` target points, 0..n-1 for an open one."""
    if not closed:
        return list(range(n))
    cut = max(int(cut), 0)
    return [(cut + k) % n for k in range(n + 1)]


def has_as_built(design):
    """Whether the 3D check found an equilibrium: some wire has `as_built`."""
    return any(w.get("as_built") for w in design.get("wires") or [])


def matched_targets(wire):
    """(k, 3): the target point each as-built point was walked from."""
    target = np.asarray(wire["target"], dtype=np.float64)
    return target[walk(len(target), wire["closed"], wire.get("cut", -1))][:len(wire["as_built"])]


def distances(wire):
    """(k,) m: each as-built point's distance from its target point (its largest is `sag`)."""
    return np.linalg.norm(np.asarray(wire["as_built"], dtype=np.float64) - matched_targets(wire), axis=1)


def ghost_points(wire, scale=1.0):
    """(k, 3): the ghost's points, the shape change drawn `scale` times (1: `as_built` itself)."""
    built = np.asarray(wire["as_built"], dtype=np.float64)
    if scale == 1.0:
        return built
    return built + (scale - 1.0) * (built - matched_targets(wire))


def ramp_colour(distance, limit):
    """RGBA of a point `distance` m from its target, on RAMP over [0, `limit`] (linear between its
    stops, clamped at both ends)."""
    x = 0.0 if limit <= 0 else min(max(distance / limit, 0.0), 1.0)
    for (x0, c0), (x1, c1) in zip(RAMP, RAMP[1:]):
        if x <= x1:
            t = (x - x0) / (x1 - x0)
            return tuple(a + t * (b - a) for a, b in zip(c0, c1))
    return RAMP[-1][1]


def segments(points):
    """(2(k-1), 3) float32 end points of the segments of an open polyline (the as-built walk is
    already closed by its repeated cut point)."""
    points = np.asarray(points, dtype=np.float32).reshape(-1, 3)
    if len(points) < 2:
        return np.empty((0, 3), dtype=np.float32)
    return np.stack([points[:-1], points[1:]], axis=1).reshape(-1, 3)


def limit_of(design):
    """m: the sag limit the 3D check used (`stands_3d.sag_limit`), else core/standing's."""
    record = design.get("stands_3d")
    if isinstance(record, dict) and isinstance(record.get("sag_limit"), (int, float)) and record["sag_limit"] > 0:
        return float(record["sag_limit"])
    return standing.sag_limit(design)


def ghost_lines(design, shown=None, scale=1.0):
    """{wire id: ((2m, 3) float32 segment end points, (2m, 4) float32 colours)} of every wire with
    `as_built` whose id is in `shown` (None: all): what the overlay draws, each end of a segment in
    the colour of its point's distance (ramp_colour, over limit_of)."""
    limit = limit_of(design)
    out = {}
    for w in design.get("wires") or []:
        if not w.get("as_built") or (shown is not None and w["id"] not in shown):
            continue
        colours = np.asarray([ramp_colour(float(d), limit) for d in distances(w)], dtype=np.float32)
        out[w["id"]] = (segments(ghost_points(w, scale)), segments_colours(colours))
    return out


def segments_colours(colours):
    """(2(k-1), 4): the colour of each segment end, as segments() orders the points."""
    colours = np.asarray(colours, dtype=np.float32).reshape(-1, 4)
    if len(colours) < 2:
        return np.empty((0, 4), dtype=np.float32)
    return np.stack([colours[:-1], colours[1:]], axis=1).reshape(-1, 4)


def slipping(design, shown=None):
    """The crossings the 3D check found slipping (`admissible` false) whose two wires are in `shown`
    (None: all)."""
    return [c for c in design.get("crossings") or [] if c.get("admissible") is False
            and (shown is None or all(k in shown for k in c["wires"]))]


def slip_point(design, crossing, scale=1.0):
    """(3,): where the ghost of the crossing's first wire passes it (its as-built point at the
    crossing's vertex), or the crossing's own point when that wire has no as-built shape."""
    wire = design["wires"][crossing["wires"][0]]
    vertex = (crossing.get("vertices") or [None])[0]
    if wire.get("as_built") and vertex is not None:
        order = walk(len(wire["target"]), wire["closed"], wire.get("cut", -1))
        if vertex in order[:len(wire["as_built"])]:
            return ghost_points(wire, scale)[order.index(vertex)]
    return np.asarray(crossing["point"], dtype=np.float64)


def slip_marks(design, shown=None, scale=1.0, size=None):
    """(6j, 3) float32: a three-armed mark (along x, y, z, each 2 MARK_SHARE of the sculpture's
    `size` long) at every slipping crossing (slipping, slip_point); None when none slips."""
    crossings = slipping(design, shown)
    if not crossings:
        return None
    if size is None:
        points = np.vstack([ghost_points(w, scale) for w in design["wires"] if w.get("as_built")])
        size = float(np.max(points.max(axis=0) - points.min(axis=0))) or 1.0
    arm = MARK_SHARE * size
    lines = []
    for c in crossings:
        p = slip_point(design, c, scale)
        for axis in np.eye(3):
            lines += [p - arm * axis, p + arm * axis]
    return np.asarray(lines, dtype=np.float32)


def legend(design, scale=1.0):
    """The legend's rows: {"title", "stops": [(share of the bar, RGBA, label)], "notes": [text]}
    (core/standing.legend_words), None without as-built shapes."""
    if not has_as_built(design):
        return None
    limit = limit_of(design)
    words = standing.legend_words(design.get("stands_3d") or {}, limit, scale,
                                  [c["id"] for c in slipping(design)])
    stops = [(x, colour, label) for (x, colour), label in zip(RAMP, words["stops"])]
    return {"title": words["title"], "stops": stops, "notes": words["notes"]}
