"""The limits a stable design can still break, said first and in short: `stable` (docs/formats.md) means
every segment and bend can be made and the assembly holds, but a maker also needs the sculpture to
carry the load factor asked for, to keep its wires in their planes, to fit the machine's stock and
to be of a size such wires make. A design that breaks one of these is never shown as plainly
"Stable" (the Stability box, Optimize's report, Live): it is "stable, over its limits", with
these phrases. Computed from the design's own figures, the same ones its warnings give in full.
bpy-free.
"""
import math

from . import standing
from .figures import versus
# STOCK_LENGTH: the default stock, which callers take from here too
from .sizes import LARGEST_MODEL, MEASURED_WIRE, OVER_STOCK, STOCK_LENGTH, TOO_LARGE, size_facts, split_sentence

# m: the forces stage's deflection_limit (native forces_and_rest; the add-on never sets another):
# a wire predicted to bend further out of its plane under its contact forces is warned about.
DEFLECTION_LIMIT = 0.002
RELATIVE = 1e-9  # a figure this close to its limit is at it, not over it (the solver's own rounding)

OVER_LIMITS = "stable, over its limits"  # the verdict's words for such a design
# The codes of the limits, in the order they are said (most decisive first).
STANDS_3D = "stands_3d"  # the assembled sculpture does not stand in 3D (core/standing.py)
LOAD_FACTOR = "load_factor"  # the load factor asked for not reached
# wires bending out of their planes past DEFLECTION_LIMIT, each loaded alone (forces stage): said
# only where the coupled 3D check did not run, whose sag it overstates
DEFLECTION = "deflection"
STOCK = "stock"  # wires longer than the machine's stock and not made in pieces that fit it (fab/pieces.py)
SIZE = "size"  # a model over LARGEST_MODEL
# the limits another hook pattern may keep (the pre-stress follows the hooks): not the stock or the size
HOOK_LIMITS = (STANDS_3D, LOAD_FACTOR, DEFLECTION)


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
    first: not standing in 3D, the load factor not reached, wires bending out of their planes (where
    the 3D check did not run), wires longer than the
    stock (`stock_length`, m), a model over LARGEST_MODEL. [] for a design within them all (and for
    one whose stages did not report these figures). The phrases of limit_records."""
    return [phrase for _code, phrase in limit_records(design, stock_length)]


def limit_records(design, stock_length=STOCK_LENGTH):
    """[(code, phrase)] of the limits `design` breaks (broken_limits), the phrase made from the
    code and its figures by phrase()."""
    return [(code, phrase(code, **figures)) for code, figures in limit_figures(design, stock_length)]


def limit_figures(design, stock_length=STOCK_LENGTH):
    """[(code, {figure: value})] of the limits `design` breaks, in broken_limits' order."""
    out = []
    checked = design.get("stands_3d")
    checked = checked if isinstance(checked, dict) and checked.get("cause") in standing.CAUSES else None
    if checked is not None and not checked.get("stands"):
        out.append((STANDS_3D, {"record": checked}))
    factor = design.get("load_factor")
    factor = factor if isinstance(factor, dict) else {}
    asked, reached = factor.get("asked"), factor.get("reached")
    if isinstance(asked, (int, float)) and isinstance(reached, (int, float)) and reached < asked * (1.0 - RELATIVE):
        out.append((LOAD_FACTOR, {"reached": reached, "asked": asked, "weakest": factor.get("weakest") or ""}))
    wires = [w for w in design.get("wires") or [] if isinstance(w, dict)]
    bent = [(float(w["out_of_plane_deflection"]), w.get("name", "?")) for w in wires
            if isinstance(w.get("out_of_plane_deflection"), (int, float))
            and _over(float(w["out_of_plane_deflection"]), DEFLECTION_LIMIT)]
    if bent and checked is None:
        worst, name = max(bent)
        out.append((DEFLECTION, {"worst": worst, "name": name, "count": len(bent)}))
    # the figures of the size warnings (core/sizes.size_facts): the solved wires' lengths, the model's size
    ok = isinstance(stock_length, (int, float)) and math.isfinite(stock_length) and stock_length > 0
    stock_length = stock_length if ok else STOCK_LENGTH  # as recorded_stock: the default profile's
    facts = size_facts({"wires": wires, "model_size": design.get("model_size")}, stock_length) if wires else []
    # a wire made in pieces that each fit the stock (fab/pieces.py) is within it; one that cannot be
    # split says why (its split_fault)
    long = [(f["length"], f["wire"], f["split_fault"]) for f in facts
            if f["cause"] == OVER_STOCK and f["measured"] == MEASURED_WIRE and _over(f["length"], stock_length)
            and not f["pieces"]]
    if long:
        worst, name, fault = max(long, key=lambda item: (item[0], item[1]))
        out.append((STOCK, {"worst": worst, "name": name, "count": len(long), "stock_length": stock_length,
                            "fault": fault}))
    for f in facts:
        if f["cause"] == TOO_LARGE and _over(f["size"], LARGEST_MODEL):
            out.append((SIZE, {"size": f["size"]}))
    return out


def phrase(code, **figures):
    """The words of the limit `code` with its figures (limit_figures'): the one place they are made."""
    if code == STANDS_3D:
        return standing.words(figures["record"])
    if code == LOAD_FACTOR:
        weakest = f" ({figures['weakest']})" if figures["weakest"] else ""
        shown, limit = versus(figures["reached"], figures["asked"], 2)
        return f"holds {shown}x its weight{weakest}, not the {limit}x asked"
    if code == DEFLECTION:
        shown, limit = versus(figures["worst"] * 1000, DEFLECTION_LIMIT * 1000, 1)
        return (f"wire {figures['name']} bends {shown} mm out of its plane (limit {limit} mm)" if figures["count"] == 1
                else f"{figures['count']} wires bend out of their planes, {figures['name']} by {shown} mm "
                     f"(limit {limit} mm)")
    if code == STOCK:
        shown, limit = versus(figures["worst"] * 1000, figures["stock_length"] * 1000, 0)
        fault = figures.get("fault")
        why = f" ({split_sentence(fault)})" if fault else ""
        return (f"wire {figures['name']} is {shown} mm long, over the {limit} mm stock{why}" if figures["count"] == 1
                else f"{figures['count']} wires are longer than the {limit} mm stock, {figures['name']} {shown} mm{why}")
    if code == SIZE:
        shown, limit = versus(figures["size"], LARGEST_MODEL, 2)
        return f"{shown} m across, over {limit} m"
    raise ValueError(f"no such limit: {code!r}")


def hooks_may_help(codes):
    """Whether another hook pattern may keep a design within the limits of `codes` (limit_records'
    codes): the load factor and the out-of-plane deflection follow the pre-stress the hooks choose."""
    return any(code in HOOK_LIMITS for code in codes)
