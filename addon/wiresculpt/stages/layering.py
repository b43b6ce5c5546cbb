"""Layering and assembly order (Sec. 4.1-4.2): crossings, a hook per crossing, the order."""
import math

from .. import native
from ..core import settings as settings_table
from ..core.design import UNREALISED
from ..core.polylines import point_array
from ..core.sizes import close_crossing_sentence, required_size


def knob(settings, key):
    """A setting of core/settings.py, its default when `settings` (e.g. a test's) lacks it."""
    return settings.get(key, settings_table.SETTINGS[key][0])


def settings_for(material, settings):
    """The native layering settings from the design's material and settings."""
    return {
        "min_segment": settings["min_segment"],
        "friction": material["friction"],
        "contact_angle": math.radians(settings["contact_angle_deg"]),
        "in_plane_tiebreak": bool(knob(settings, "in_plane_tiebreak")),
        "max_nodes": int(knob(settings, "max_nodes")),
    }


def wire_specs(design, key="contour", arrays=None):
    """The design's wires as the native network functions take them; `arrays`: their `key` points
    already as float64 arrays, in the wires' order."""
    if arrays is None:
        arrays = [point_array(w[key]) for w in design["wires"]]
    return [{"name": w["name"], "origin": w["plane"]["origin"], "normal": w["plane"]["normal"],
             "points": a, "closed": w["closed"]}
            for w, a in zip(design["wires"], arrays, strict=True)]


def run(design, material, settings, native_progress=None, forbidden=(), too_close=None, arrays=False,
        contour_cache=None):
    """Fills crossings, assembly order, stable/reason and stages.layering. Returns a progress line.
    `native_progress(stage, fraction) -> bool` (False cancels) is handed to the solver.
    `forbidden`: (crossing id, hook) pairs the search may not choose (the re-layering loop,
    pipeline.solve); crossing ids are those of the network the design's contours give.
    `too_close`: an angle tolerance (radians, the target shape's): forbid too every hook that the
    target shape cannot realise for want of a free bending point between two crossings (the native
    forbid_too_close; the plane search's screen, and pipeline.relayer's rounds); the pairs it
    forbade go to `too_close_forbidden`, which never reaches a design.json. `arrays`: the wires'
    contours become float64 (n, 3) arrays instead of lists (the screen's probes: a few arrays
    instead of a list per point for Python's garbage collector to walk). `contour_cache`: a
    core.polylines.ContourArrays of the solve: the contours are read from it, and the new ones'
    arrays (the native result's `arrays`) go into it, for the later stages."""
    options = settings_for(material, settings)
    if forbidden:
        options["forbidden_hooks"] = [[int(c), int(h)] for c, h in sorted(forbidden)]
    if too_close is not None:
        options.update(forbid_too_close=True, too_close_angle_tolerance=float(too_close))
    if arrays:
        options["contour_arrays"] = True
    elif contour_cache is not None:
        options["arrays_too"] = True
    given = None if contour_cache is None else [contour_cache.get(w["contour"]) for w in design["wires"]]
    result = native.layering(wire_specs(design, arrays=given), options, native_progress)
    net = result["network"]
    for wire, solved in zip(design["wires"], net["wires"]):
        wire["contour"] = solved["contour"]  # the sliced contour with its crossing points inserted
    if options.get("arrays_too"):
        for solved, array in zip(net["wires"], result["arrays"], strict=True):
            contour_cache.remember(solved["contour"], array)
    design["crossings"] = net["crossings"]  # the design's keys (contour_vertices, metric, ...)
    design["assembly_order"] = list(result["assembly_order"])
    design["assembly_steps"] = [list(s) for s in result["steps"]]
    design["two_hand_steps"] = list(result["two_hand_steps"])
    design["stable"] = bool(result["stable"])
    design["reason"] = result["reason"]
    design["verdict_cause"] = result["cause"]  # core/design.py LAYERING_CAUSES
    if result["what_moves"]:  # the hook-relaxed check failed: the clause naming what moves
        design["what_moves"] = result["what_moves"]
    if not result["complete_search"] and not design["stable"]:
        design["search_incomplete"] = True  # max_nodes stopped it: a stable design may still exist
    design.setdefault("warnings", []).extend(result["warnings"])
    if net["close_crossings"]:  # worded here, with the model's size (core/sizes), warnings and design alike
        close = [close_crossing_sentence(design, g, settings["min_segment"]) for g in net["close_crossings"]]
        design["warnings"].extend(close)
        design["close_crossings"] = close
        design["required_size"] = required_size(design, max(g["scale"] for g in net["close_crossings"]))
    if too_close is not None:  # for the screen (plane_faults.screen_fault) and relayer, never in a design.json
        design["too_close_forbidden"] = [list(p) for p in result["too_close_forbidden"]]
    stats = result["stats"]
    design["stages"]["layering"] = {
        "seconds": stats["seconds"], "lp_solves": stats["lp_solves"], "nodes": stats["nodes"],
        "complete_search": result["complete_search"], "in_plane_complete": result["in_plane_complete"],
        "forbidden_hooks": result["forbidden_hooks"], **result["objective"],
    }
    return (f"{len(design['crossings'])} crossings, {'stable' if design['stable'] else 'not stable'}, "
            f"order {design['assembly_order']}, {stats['lp_solves']} LPs, {stats['nodes']} nodes "
            f"({stats['seconds']:.3f} s)")


def recheck(design, material, settings, native_progress=None, contours=None):
    """Eq. 1 for every prefix of the design's assembly with its current hooks (after a later
    stage nulled crossings). Returns the native verdict dict; `native_progress` as for run();
    `contours`: the wires' contours already as float64 arrays (wire_specs)."""
    hooks = [c["hook"] for c in design["crossings"]]
    return native.check_assembly(wire_specs(design, arrays=contours), hooks, design["assembly_steps"],
                                 settings_for(material, settings), native_progress)


def recheck_verdict(design, material, settings, cause, count, native_progress=None, contours=None, codes=()):
    """The layering's verdict after a later stage nulled `count` crossings for `cause` (a
    sentence naming them): re-checks the assembly (recheck) and, when it no longer stands, sets
    `stable` false with a `reason` naming the cause and the step that fails, `verdict_cause`
    UNREALISED (core/design.py), and `reason_causes`
    to `codes` (those of the causes `cause` names, core/design.py) when there are any. Returns the
    number of LPs the re-check solved. `contours` as for recheck."""
    verdict = recheck(design, material, settings, native_progress, contours)
    if not verdict["stable"] and design["stable"]:
        step = design["assembly_steps"][verdict["failed_step"]]
        names = " and ".join(design["wires"][w]["name"] for w in step)
        design["stable"] = False
        design.pop("what_moves", None)  # the reason is no longer the layering's own
        design["verdict_cause"] = UNREALISED
        design["reason"] = (f"{cause}; without {'them' if count > 1 else 'it'} the assembly is no longer stable "
                            f"when adding {names}")
        if codes:
            design["reason_causes"] = list(codes)
    return verdict["lp_solves"]
