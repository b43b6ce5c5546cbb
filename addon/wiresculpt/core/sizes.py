"""Size sense: a wire longer than the machine's stock, or a model too big to be a wire sculpture
of this kind, is a warning with the figure, said before the long optimization starts."""
import math
from operator import itemgetter

from .figures import versus

STOCK_LENGTH = 1.0   # m: the default machine profile's straight wire stock (profile key stock_length)
LARGEST_MODEL = 1.5  # m: beyond this a sculpture of stiff planar wires sags and is hard to build


def stock(profile):
    """(m, name): a machine profile's stock length (key stock_length, STOCK_LENGTH when absent) and
    the name its warnings use; the default profile's for None."""
    if profile is None:
        return STOCK_LENGTH, "the default machine profile"
    return float(profile.get("stock_length", STOCK_LENGTH)), profile.get("name") or "the machine profile"


def wire_length(wire):
    """m: the wire's own `length`, else the length of its target (or contour) polyline, closed
    when the wire is closed."""
    if wire.get("length") is not None:
        return float(wire["length"])
    points = wire.get("target") or wire.get("contour") or []
    path = list(points) + (list(points[:1]) if wire.get("closed") else [])
    return sum(math.dist(a, b) for a, b in zip(path, path[1:]))


def model_size(design):
    """m: the largest side of the bounding box of every wire's contour (or target) points."""
    points = [p for w in design["wires"] for p in (w.get("contour") or w.get("target") or [])]
    if not points:
        return 0.0
    return max(max(map(itemgetter(k), points)) - min(map(itemgetter(k), points)) for k in range(3))


def size_warnings(design, stock_length=STOCK_LENGTH, profile_name="the default machine profile"):
    """One sentence per wire longer than `stock_length` (m) and one when the model is over
    LARGEST_MODEL, each with its figure in millimetres or metres (the model's first)."""
    stock = stock_warnings(design, stock_length, profile_name)  # a bad stock_length is refused first
    out = []
    size = model_size(design)
    if size > LARGEST_MODEL:
        shown, largest = versus(size, LARGEST_MODEL, 2)
        out.append(f"the model is {shown} m across, over {largest} m: check the mesh's units or "
                   f"the scene's size (a wire sculpture this large sags and needs very long wires)")
    return out + stock


def stock_warnings(design, stock_length=STOCK_LENGTH, profile_name="the default machine profile"):
    """size_warnings' sentences of the wires longer than `stock_length` (m), one per wire."""
    if not (isinstance(stock_length, (int, float)) and math.isfinite(stock_length) and stock_length > 0):
        raise ValueError(f"machine profile key stock_length must be a positive number of metres, got {stock_length!r}")
    out = []
    for w in design["wires"]:
        length = wire_length(w)
        if length > stock_length:
            shown, stock_mm = versus(length * 1000, stock_length * 1000, 0)
            out.append(f"wire {w['name']} is {shown} mm long, longer than the {stock_mm} mm "
                       f"stock of {profile_name}: it needs a longer stock or a joint")
    return out
