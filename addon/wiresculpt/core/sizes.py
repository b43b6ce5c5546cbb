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


# A wire longer than the stock is split into pieces joined over JOINT_LENGTH (fab/pieces.py): the
# two pieces overlap there, each running half of it past the joint's centre. A joint on a straight
# stretch of the rest shape is a sleeve (a tube over both ends), one over bends an overlap (the ends,
# bent alike, laid side by side and bound or soldered).
JOINT_LENGTH = 0.03  # m
JOINT_SLEEVE, JOINT_OVERLAP = "sleeve", "overlap"
# Why a wire longer than the stock cannot be split (wires[].split_fault["cause"]; split_sentence
# makes their words), each with the figures length, stock, allowance, joint_length, min_segment and
# least_stock (m: the shortest stock that would do):
NO_JOINT_POINT = "no_joint_point"          # no point of the wire can hold a joint (crossings, bends)
PIECE_TOO_LONG = "piece_too_long"          # the points that can leave a piece longer than the stock
PIECE_NOT_BENDABLE = "piece_not_bendable"  # a piece's own bend program is refused: piece, message
SPLIT_CAUSES = (NO_JOINT_POINT, PIECE_TOO_LONG, PIECE_NOT_BENDABLE)

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
                        "profile": profile_name, "measured": measured_on(w), "pieces": fitting_pieces(w, stock_length),
                        "split_fault": split_fault(w)})
    return out


def fitting_pieces(wire, stock_length):
    """The number of pieces the wire is made of (its `pieces`, fab/pieces.py) when every piece,
    with its allowance, fits `stock_length` (m); 0 when it is not split so."""
    pieces = wire.get("pieces")
    if not isinstance(pieces, list) or len(pieces) < 2:
        return 0
    ok = all(isinstance(p, dict) and isinstance(p.get("length"), (int, float))
             and p["length"] + float(p.get("allowance", 0.0)) <= stock_length * (1 + 1e-9) for p in pieces)
    return len(pieces) if ok else 0


def split_fault(wire):
    """The wire's `split_fault` (why it cannot be split, fab/pieces.py) when it has a known cause, else None."""
    fault = wire.get("split_fault")
    return fault if isinstance(fault, dict) and fault.get("cause") in SPLIT_CAUSES else None


def _mm(metres):
    return f"{metres * 1000:.0f} mm"


def split_sentence(fault):
    """Why a wire cannot be split into pieces of the stock, and what to change: the words of a
    `split_fault` (SPLIT_CAUSES with their figures), the one place they are made."""
    cause = fault["cause"]
    joint, least = fault["joint_length"], fault["least_stock"]
    if cause == NO_JOINT_POINT:
        why = (f"no point of it can take a {_mm(joint)} joint clear of its crossings by {_mm(fault['min_segment'])} "
               f"with a feed of at least {_mm(fault['min_segment'])} to the next bend on both pieces")
    elif cause == PIECE_TOO_LONG:
        shown, stock = versus(least * 1000, fault["stock"] * 1000, 0)
        why = (f"the points that can take a {_mm(joint)} joint leave a piece of at least {shown} mm"
               + (f" (with its {_mm(fault['allowance'])} closing overlap)" if fault.get("allowance") else "")
               + f", over the {stock} mm stock")
    else:
        why = f"the bend program refuses piece {fault['piece']}: {fault['message']}"
    factor = fault["stock"] / least if least > 0 else 1.0
    change = (f"use a stock of at least {math.ceil(round(least * 1000, 2)):.0f} mm"
              + (f" or scale the model down to {math.floor(factor * 100) / 100:.2f} of its size or less"
                 if factor < 1 else ""))
    return f"it cannot be split into pieces of the stock: {why}; {change}"


def joint_sentence(wire, joint, diameter):
    """How to join two pieces of a split wire (the assembly guide): which piece ends meet, where,
    and the sleeve or the overlap (fab/pieces.py)."""
    name = wire["name"]
    a, b = joint["pieces"]
    count = len(wire.get("pieces") or ())
    mm = ", ".join(f"{'xyz'[k]} {round(1000 * joint['point'][k]) or 0}" for k in range(3)) if joint.get("point") else ""
    where = (f"{joint['at'] * 1000:.0f} mm from the cut" + (f", at ({mm} mm)" if mm else ""))
    length = joint["length"]
    head = (f"join {name} piece {a} of {count} and piece {b} of {count} {where} before the wire goes in: "
            f"their ends overlap by {_mm(length)}, each running {_mm(length / 2)} past the joint's centre "
            f"(the last {_mm(length)} of piece {a} lies along the first {_mm(length)} of piece {b}, "
            "an orange band on both templates)")
    if joint["kind"] == JOINT_SLEEVE:
        return (head + f"; slide a {_mm(length)} sleeve whose bore takes two {diameter * 1000:g} mm wires onto the end "
                f"of piece {a}, push the start of piece {b} in beside it and crimp or solder the sleeve")
    return (head + "; the overlap has bends, made alike on both pieces: lay the two ends side by side and bind or "
            "solder them along the whole overlap")


def size_sentence(fact):
    """The words of one size_facts cause, with its figures."""
    if fact["cause"] == TOO_LARGE:
        shown, largest = versus(fact["size"], fact["limit"], 2)
        return (f"the model is {shown} m across, over {largest} m: check the mesh's units or "
                f"the scene's size (a wire sculpture this large sags and needs very long wires)")
    shown, stock_mm = versus(fact["length"] * 1000, fact["stock"] * 1000, 0)
    measured = " (its sliced contour; the solve sets the wire's length)" if fact["measured"] == MEASURED_CONTOUR else ""
    head = f"wire {fact['wire']} is {shown} mm long{measured}, longer than the {stock_mm} mm stock of {fact['profile']}"
    if fact.get("pieces"):
        return f"{head}: it is made in {fact['pieces']} pieces joined at low-stress points (see the assembly guide)"
    if fact.get("split_fault"):
        return f"{head}: {split_sentence(fact['split_fault'])}"
    return f"{head}: it needs a longer stock or a joint"


def size_warnings(design, stock_length=STOCK_LENGTH, profile_name="the default machine profile"):
    """One sentence per wire longer than `stock_length` (m) and one when the model is over
    LARGEST_MODEL, each with its figure in millimetres or metres (size_facts, size_sentence)."""
    return [size_sentence(f) for f in size_facts(design, stock_length, profile_name)]


def stock_warnings(design, stock_length=STOCK_LENGTH, profile_name="the default machine profile"):
    """size_warnings' sentences of the wires longer than `stock_length` (m), one per wire."""
    return [size_sentence(f) for f in size_facts(design, stock_length, profile_name) if f["cause"] == OVER_STOCK]
