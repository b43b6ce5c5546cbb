"""Can every wire be made? `stable: true` is a promise to a person holding pliers (docs/formats.md
additions): every segment >= min_segment and every bend of the bend program, after spring-back
compensation with the machine profile in use, within the machine's limits. This module asks the
bend program itself (native bend_program_problems, the same code that writes the G-code and bend
tables) for every wire's rest shape, and finds where a rest shape crosses itself (a warning: the
wire must pass over itself on the bender; the paper found small overlaps harmless).

Places on a wire are named one way everywhere: bend k is the k-th bend from the cut (step k of
the G-code and row k of the bend table), and a place is also given in mm from the cut.

    check(design, profile=None)   -> {"profile", "problems": [...], "self_crossings": [...]}
    apply(design, profile=None)   the verdict into the design: `stable`/`reason`, `warnings`,
                                  `buildability`
"""
import numpy as np

from .. import native
from ..core.design import NOT_BUILDABLE
from ..core.sizes import feed_scale, gap_scale, scale_advice
from ..core.polylines import self_crossings
from .export import machine_profile


def walk(wire):
    """Target index of each rest point (docs/formats.md: rest starts at the cut)."""
    m = len(wire["target"])
    if wire["closed"]:
        return [(wire["cut"] + k) % m for k in range(m + 1)]
    return list(range(m))


def crossings_at(design, wire, target_index):
    """Ids of the crossings at a target vertex of the wire."""
    return [c["id"] for c in design.get("crossings", [])
            for k in (0, 1) if c["wires"][k] == wire["id"] and c["vertices"][k] == target_index]


def between_bends(bend_points, edge):
    """The place of rest edge `edge` in the bend numbering: "between bends 3 and 4"."""
    k = int(np.searchsorted(np.asarray(bend_points), edge, side="right"))  # bends at or before the edge start
    if not bend_points:
        return "on a wire without bends"
    if k == 0:
        return "before bend 1"
    if k == len(bend_points):
        return f"after bend {k}, the last"
    return f"between bends {k} and {k + 1}"


def _scale_advice(design, feed, limit, ends):
    """How to lengthen a short feed: scale the model (every length grows with it); between two
    crossings by the one rule for crossings (core/sizes.gap_scale: room for a free bending point),
    else until the feed is `limit` long (feed_scale)."""
    scale = scale_advice(design, gap_scale(feed, limit) if len(ends) == 2 else feed_scale(feed, limit))
    if len(ends) == 2:
        return (f"its ends are crossings {ends[0]} and {ends[1]}, fixed points of the wire: {scale} or move the "
                "planes so that they lie farther apart")
    return scale


def check(design, profile=None):
    """What keeps the design's wires from being made, and where their rest shapes cross themselves,
    with `profile` (None: the default machine profile, the design's limits; see
    export.machine_profile). Wires without a rest shape are skipped."""
    machine, _notes = machine_profile(design, profile)
    problems, crossings = [], []
    for wire in design["wires"]:
        if "rest" not in wire:
            continue
        rest = np.asarray(wire["rest"], dtype=np.float64)
        order = walk(wire)
        try:
            found = native.bend_program_problems(rest, machine)
        except ValueError as exc:  # a rest shape the bend program cannot read (a repeated point)
            found = [{"kind": "input", "number": 0, "from": 0, "to": 0, "at": 0.0, "value": 0.0, "limit": 0.0,
                      "message": str(exc)}]
        bends = [] if found else list(native.make_bend_program(rest, machine)["bend_vertices"])
        for p in found:
            entry = {"wire": wire["id"], **p}
            text = f"wire {wire['name']}: {p['message']}"
            if p["kind"] == "short_feed":
                ends = [c for v in (p["from"], p["to"]) for c in crossings_at(design, wire, order[v])]
                entry["crossings"] = ends
                text += "; " + _scale_advice(design, p["value"], p["limit"], ends)
            entry["message"] = text  # the bend program's own sentence, with the wire's name and advice
            problems.append(entry)
        for i, j, point, s_i, s_j in self_crossings(rest, wire["closed"]):
            places = ("" if found else f" ({between_bends(bends, i)} and {between_bends(bends, j)})")
            crossings.append({
                "wire": wire["id"], "edges": [i, j], "point": [float(point[0]), float(point[1])],
                "at": [s_i, s_j],
                "message": (f"wire {wire['name']}: the rest shape crosses itself {s_i * 1000:.1f} mm and "
                             f"{s_j * 1000:.1f} mm from the cut{places}; the wire must pass over itself there "
                             "on the bender (small overlaps are harmless, Sec. 6 of the paper)")})
    return {"profile": machine.get("name", ""), "problems": problems, "self_crossings": crossings}


def apply(design, profile=None):
    """check() into the design: a design that cannot be made is not stable, its reason naming each
    wire and bend or step; each self-crossing is a warning. Returns the check."""
    result = check(design, profile)
    design["buildability"] = {"profile": result["profile"], "problems": result["problems"],
                              "self_crossings": result["self_crossings"]}
    design.setdefault("warnings", []).extend(c["message"] for c in result["self_crossings"])
    if result["problems"] and design["stable"]:
        design["stable"], design["verdict_cause"] = False, NOT_BUILDABLE
        design["reason"] = ("the design cannot be made on the machine: "
                            + "; ".join(p["message"] for p in result["problems"]))
    return result
