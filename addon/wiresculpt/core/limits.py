"""The limits a stable design can still break, said first and in short: `stable` (FORMATS.md) means
every segment and bend can be made and the assembly holds, but a maker also needs the sculpture to
carry the load factor asked for, to keep its wires in their planes, to fit the machine's stock and
to be of a size such wires make. A design that breaks one of these is never shown as plainly
"Stable" (the Stability box, Optimize's report, Live): it is "stable, over its limits", with
these phrases. Computed from the design's own figures, the same ones its warnings give in full.
bpy-free.
"""
import math

from .figures import versus
# STOCK_LENGTH: the default stock, which callers take from here too
from .sizes import LARGEST_MODEL, MEASURED_WIRE, OVER_STOCK, STOCK_LENGTH, TOO_LARGE, size_facts

# m: the forces stage's deflection_limit (native forces_and_rest; the add-on never sets another):
# a wire predicted to bend further out of its plane under its contact forces is warned about.
DEFLECTION_LIMIT = 0.002
RELATIVE = 1e-9  # a figure this close to its limit is at it, not over it (the solver's own rounding)

OVER_LIMITS = "stable, over its limits"  # the verdict's words for such a design
# the limits another hook pattern may keep (the pre-stress follows the hooks): not the stock or the size
HOOK_LIMITS = ("holds ", "out of its plane", "out of their planes")


def recorded_stock(inputs):
    """m: the stock length Optimize solved for (its record's "stock": [length, profile name]), the
    default profile's when not recorded."""
    stock = (inputs or {}).get("stock")
    ok = isinstance(stock, (list, tuple)) and stock and isinstance(stock[0], (int, float)) and stock[0] > 0
    return float(stock[0]) if ok else STOCK_LENGTH


def _over(value, limit):
    return value > limit * (1.0 + RELATIVE)


def broken_limits(design, stock_length=STOCK_LENGTH):
    """Short phrases, each a limit `design` breaks with its figure and the limit, most decisive
    first: the load factor not reached, wires bending out of their planes, wires longer than the
    stock (`stock_length`, m), a model over LARGEST_MODEL. [] for a design within them all (and for
    one whose stages did not report these figures)."""
    said = []
    factor = design.get("load_factor")
    factor = factor if isinstance(factor, dict) else {}
    asked, reached = factor.get("asked"), factor.get("reached")
    if isinstance(asked, (int, float)) and isinstance(reached, (int, float)) and reached < asked * (1.0 - RELATIVE):
        weakest = f" ({factor['weakest']})" if factor.get("weakest") else ""
        shown, limit = versus(reached, asked, 2)
        said.append(f"holds {shown}x its weight{weakest}, not the {limit}x asked")
    wires = [w for w in design.get("wires") or [] if isinstance(w, dict)]
    bent = [(float(w["out_of_plane_deflection"]), w.get("name", "?")) for w in wires
            if isinstance(w.get("out_of_plane_deflection"), (int, float))
            and _over(float(w["out_of_plane_deflection"]), DEFLECTION_LIMIT)]
    if bent:
        worst, name = max(bent)
        shown, limit = versus(worst * 1000, DEFLECTION_LIMIT * 1000, 1)
        said.append(f"wire {name} bends {shown} mm out of its plane (limit {limit} mm)" if len(bent) == 1 else
                    f"{len(bent)} wires bend out of their planes, {name} by {shown} mm (limit {limit} mm)")
    # the figures of the size warnings (core/sizes.size_facts): the solved wires' lengths, the model's size
    ok = isinstance(stock_length, (int, float)) and math.isfinite(stock_length) and stock_length > 0
    stock_length = stock_length if ok else STOCK_LENGTH  # as recorded_stock: the default profile's
    facts = size_facts({"wires": wires, "model_size": design.get("model_size")}, stock_length) if wires else []
    long = [(f["length"], f["wire"]) for f in facts if f["cause"] == OVER_STOCK and f["measured"] == MEASURED_WIRE
            and _over(f["length"], stock_length)]
    if long:
        worst, name = max(long)
        shown, limit = versus(worst * 1000, stock_length * 1000, 0)
        said.append(f"wire {name} is {shown} mm long, over the {limit} mm stock" if len(long) == 1 else
                    f"{len(long)} wires are longer than the {limit} mm stock, {name} {shown} mm")
    for f in facts:
        if f["cause"] == TOO_LARGE and _over(f["size"], LARGEST_MODEL):
            shown, limit = versus(f["size"], LARGEST_MODEL, 2)
            said.append(f"{shown} m across, over {limit} m")
    return said


def hooks_may_help(limits):
    """Whether another hook pattern may keep a design within `limits` (broken_limits' phrases):
    the load factor and the out-of-plane deflection follow the pre-stress the hooks choose."""
    return any(words in limit for limit in limits for words in HOOK_LIMITS)
