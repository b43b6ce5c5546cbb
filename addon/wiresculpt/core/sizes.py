"""Size sense: a wire longer than the machine's stock, or a model too big to be a wire sculpture
of this kind, is a warning with the figure, said before the long optimization starts."""
import math
from operator import itemgetter

import numpy as np

from .figures import versus

STOCK_LENGTH = 1.0   # m: the default machine profile's straight wire stock (profile key stock_length)
LARGEST_MODEL = 1.5  # m: beyond this a sculpture of stiff planar wires sags and is hard to build


def stock(profile):
    """(m, name): a machine profile's stock length (key stock_length, STOCK_LENGTH when absent) and
    the name its warnings use; the default profile's for None."""
    if profile is None:
        return STOCK_LENGTH, "the default machine profile"
    return float(profile.get("stock_length", STOCK_LENGTH)), profile.get("name") or "the machine profile"


# Causes of the size warnings (codes; size_sentence makes their words)
OVER_STOCK = "over_stock"        # a wire longer than the machine's stock: wire, length, stock, profile, measured
TOO_LARGE = "model_too_large"    # a model over LARGEST_MODEL: size, limit
# What a length was measured on: the solved wire (its `length` or target), or only its sliced contour
# (before the target shape), whose length the solve changes.
MEASURED_WIRE, MEASURED_CONTOUR = "wire", "contour"


def wire_length(wire):
    """m: the wire's own `length`, else the length of its target (or contour) polyline, closed
    when the wire is closed. Every message, warning and file that gives a wire's length asks here."""
    if wire.get("length") is not None:
        return float(wire["length"])
    points = wire.get("target") or wire.get("contour") or []
    path = list(points) + (list(points[:1]) if wire.get("closed") else [])
    return sum(math.dist(a, b) for a, b in zip(path, path[1:]))


def measured_on(wire):
    """MEASURED_WIRE when wire_length(wire) is the solved wire's, MEASURED_CONTOUR when only its
    sliced contour is known."""
    return MEASURED_WIRE if wire.get("length") is not None or wire.get("target") else MEASURED_CONTOUR


def mesh_size(vertices):
    """m: the largest side of the bounding box of a mesh's vertices ((n, 3)); 0.0 without any. The
    model's size: what a scene's "size" sets, what the design records as `model_size`."""
    V = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    return float(np.max(V.max(axis=0) - V.min(axis=0))) if len(V) else 0.0


def model_size(design):
    """m: the model's size, one figure for every message: the design's `model_size` (the mesh's
    largest side, recorded when it was sliced, mesh_size), else the largest side of the bounding box
    of every wire's contour (or target) points."""
    recorded = design.get("model_size")
    if isinstance(recorded, (int, float)) and math.isfinite(recorded) and recorded > 0:
        return float(recorded)
    points = [p for w in design["wires"] for p in (w.get("contour") or w.get("target") or [])]
    if not points:
        return 0.0
    return max(max(map(itemgetter(k), points)) - min(map(itemgetter(k), points)) for k in range(3))


def gap_scale(arc, min_segment):
    """The one scale rule: two crossings `arc` m apart along a wire need room for a free bending
    point between them, two straight pieces of at least `min_segment` each, so the model must grow
    by 2 min_segment / arc (math.inf for arc <= 0). The native network and target shape compute
    the same (native/src/figures.hpp gap_scale), and hand it over as each gap's `scale`; this is
    the rule for the add-on's own gaps (a short feed between two crossings). Why twice: scaled by
    min_segment / arc only, the two crossings would be one straight piece apart, a fixed edge both
    kinks share, which the target shape still refuses unless the contour happens to lie in both
    contact cones, and the user would be told to scale up a second time."""
    return 2.0 * min_segment / arc if arc > 0 else math.inf


def feed_scale(feed, min_segment):
    """The factor by which a lone straight feed of `feed` m must grow to be `min_segment` long (one
    piece, no crossing at both its ends: min_segment / feed)."""
    return min_segment / feed if feed > 0 else math.inf


def scale_advice(design, factor):
    """The words of "scale the model up by `factor`", with the model's size (model_size) before and
    after: every scale advice the add-on makes says its figures this way, as the native's
    (native/src/figures.hpp scale_words) do."""
    return scale_words(model_size(design), factor)


def scale_words(size, factor):
    """scale_advice's words for a model `size` m across (without the sizes when `size` <= 0)."""
    if not size > 0:
        return f"scale the model up at least {factor:.2f} times"
    return f"scale the model up at least {factor:.2f} times (largest side {size:.4g} m -> {size * factor:.4g} m)"


def required_size(design, factor):
    """m: the model's size (model_size) once scaled up by `factor`: the design's `required_size`,
    the figure after the arrow of scale_advice."""
    return model_size(design) * factor


def close_crossing_sentence(design, gap, min_segment):
    """The words of one of the network's close crossings (`gap`: wire, crossings, distance, scale,
    as native.layering hands them over), with the model's size (scale_advice)."""
    shown, least = versus(gap["distance"] * 1000, min_segment * 1000, 1)
    a, b = gap["crossings"]
    return (f"wire {design['wires'][gap['wire']]['name']}: crossings {a} and {b} are {shown} mm apart along the "
            f"wire, less than the machine's minimum segment {least} mm; a free bending point between them needs "
            f"twice that: " + scale_advice(design, gap["scale"]))


def size_facts(design, stock_length=STOCK_LENGTH, profile_name="the default machine profile"):
    """The size problems of `design` as causes with their figures: one TOO_LARGE when the model is
    over LARGEST_MODEL, one OVER_STOCK per wire longer than `stock_length` (m)."""
    if not (isinstance(stock_length, (int, float)) and math.isfinite(stock_length) and stock_length > 0):
        raise ValueError(f"machine profile key stock_length must be a positive number of metres, got {stock_length!r}")
    out = []
    size = model_size(design)
    if size > LARGEST_MODEL:
        out.append({"cause": TOO_LARGE, "size": size, "limit": LARGEST_MODEL})
    for w in design["wires"]:
        length = wire_length(w)
        if length > stock_length:
            out.append({"cause": OVER_STOCK, "wire": w["name"], "length": length, "stock": float(stock_length),
                        "profile": profile_name, "measured": measured_on(w)})
    return out


def size_sentence(fact):
    """The words of one size_facts cause, with its figures."""
    if fact["cause"] == TOO_LARGE:
        shown, largest = versus(fact["size"], fact["limit"], 2)
        return (f"the model is {shown} m across, over {largest} m: check the mesh's units or "
                f"the scene's size (a wire sculpture this large sags and needs very long wires)")
    shown, stock_mm = versus(fact["length"] * 1000, fact["stock"] * 1000, 0)
    measured = " (its sliced contour; the solve sets the wire's length)" if fact["measured"] == MEASURED_CONTOUR else ""
    return (f"wire {fact['wire']} is {shown} mm long{measured}, longer than the {stock_mm} mm "
            f"stock of {fact['profile']}: it needs a longer stock or a joint")


def size_warnings(design, stock_length=STOCK_LENGTH, profile_name="the default machine profile"):
    """One sentence per wire longer than `stock_length` (m) and one when the model is over
    LARGEST_MODEL, each with its figure in millimetres or metres (size_facts, size_sentence)."""
    return [size_sentence(f) for f in size_facts(design, stock_length, profile_name)]


def stock_warnings(design, stock_length=STOCK_LENGTH, profile_name="the default machine profile"):
    """size_warnings' sentences of the wires longer than `stock_length` (m), one per wire."""
    return [size_sentence(f) for f in size_facts(design, stock_length, profile_name) if f["cause"] == OVER_STOCK]
