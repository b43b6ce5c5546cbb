"""The design document (`design.json`, docs/formats.md): its vocabulary, built as a plain dict,
written atomically.

This module owns the design's vocabulary: which stage writes which key (KEYS, checked by
blender_tests/pure/test_design_vocabulary.py against docs/formats.md and a real design), and the
few facts every reader derives the same way (crossing_direction, model_size). The solver's
binding answers in these names, so no stage renames a key. One name, one meaning: a crossing's
`vertices` index its wires' `target`, `contour_vertices` their `contour`.

Only stages that ran put values in it: a key a stage owns is absent until that stage exists, and
`pending_stages` names the stages that did not run.
"""
import json
import math
import re

import numpy as np

from .files import write_atomic

FORMAT = "wiresculpt-design"
VERSION = 1


# Who writes each key: "design" (new_design), a stage of the pipeline ("slicing", "layering",
# "target_shape", "forces" with the rest shape and load capacity, all from one native call),
# "pipeline" (pipeline.py itself), "user" (what the user asked for, kept for the next solve),
# "fabrication" (the batch's exports) or "every stage" (appended to by each). `fidelity` is
# written by the plane search's batch entry for every batch design and by the searches for each
# candidate (core/fidelity.py: it needs the mesh, which the pipeline's stages do not see).
# `stable`/`reason` are the layering's verdict (new_design's default until it runs; the pipeline
# answers when there are fewer than two wires; layering.recheck_verdict after a later stage nulls
# crossings; fab/buildability.apply, through the pipeline, when a wire's bend program cannot be
# made: "stable" means buildable). A crossing's `hook` and `metric` are the layering's; the target shape sets both to
# 0 for a crossing it cannot realise. `torque_fraction` is the settings' (null when the load
# factor chooses it) until the forces stage writes the fraction it used.
KEYS = {
    "top": {
        "format": "design", "version": "design", "units": "design", "material": "design",
        "torque_fraction": "design", "machine": "design", "wires": "design", "stages": "design",
        "stable": "layering", "reason": "layering", "reason_causes": "layering", "what_moves": "layering",
        "verdict_cause": "layering",
        "pending_stages": "pipeline", "warnings": "every stage",
        "crossings": "layering", "assembly_order": "layering", "assembly_steps": "layering",
        "two_hand_steps": "layering", "close_crossings": "layering", "required_size": "layering",
        "search_incomplete": "layering",
        "out_of_plane": "forces", "load_capacity": "forces", "load_factor": "forces", "buildability": "pipeline",
        "fabrication": "fabrication", "plane_search": "plane_search",
        "model_size": "pipeline", "mesh_faults": "pipeline", "mesh_closing": "pipeline", "stands_3d": "stands_3d",
        "fidelity": "plane_search",
    },
    "wire": {
        "id": "slicing", "name": "slicing", "plane": "slicing", "closed": "slicing", "contour": "slicing",
        "target": "target_shape", "length": "target_shape", "target_max_distance": "target_shape",
        "target_rms_distance": "target_shape",
        "cut": "forces", "rest": "forces", "rest_angles": "forces", "target_angles": "forces",
        "closure_gap": "forces", "max_torque": "forces", "max_torque_vertex": "forces",
        "max_out_of_plane_torque": "forces", "max_torque_3d": "forces", "rest_over_bend": "forces",
        "out_of_plane_deflection": "forces", "out_of_plane_deflection_vertex": "forces",
        "cut_override": "user", "cut_point": "user",
        "sag": "stands_3d", "as_built": "stands_3d",
        "pieces": "pipeline", "joints": "pipeline", "split_fault": "pipeline",
    },
    "crossing": {
        "id": "layering", "wires": "layering", "contour_vertices": "layering", "point": "layering",
        "hook": "layering", "metric": "layering", "hook_metrics": "layering",
        "vertices": "target_shape",
        "force": "forces", "normal_force": "forces", "out_of_plane": "forces", "pyramid": "forces",
        "carried_force": "forces", "carried_weight": "forces", "force_3d": "stands_3d", "admissible": "stands_3d",
    },
    "stages": {
        "slicing": "slicing", "layering": "layering", "target_shape": "target_shape",
        "forces": "forces", "rest_shape": "forces", "hook_search": "pipeline", "relayering": "pipeline",
        "stands_3d": "stands_3d", "pieces": "pipeline",
    },
    # the plane search's record (`plane_search`, plane_search/records.py)
    "plane_search": {k: "plane_search" for k in (
        "mode", "planes_before", "planes_after", "changes", "candidates", "full_solves", "budget_seconds",
        "solves_stopped", "solves_failed", "final_solve", "seconds", "score", "measure", "not_found",
        "limits", "stopped_by", "screens_cut")},
}

# Keys written only in some cases (a stage that ran may leave them out): close crossings, a
# material without density, a user's cut, the batch's exports.
OPTIONAL = {
    "top": {"close_crossings", "required_size", "load_capacity", "load_factor", "fabrication", "warnings",
            "buildability", "search_incomplete", "plane_search", "reason_causes", "model_size", "mesh_faults",
            "mesh_closing", "stands_3d", "what_moves", "fidelity"},
    "wire": {"cut_override", "cut_point", "out_of_plane_deflection", "out_of_plane_deflection_vertex", "sag",
             "as_built", "pieces", "joints", "split_fault"},
    "crossing": {"pyramid", "carried_force", "carried_weight", "force_3d", "admissible"},
    "stages": {"stands_3d", "pieces"},
    "plane_search": {"not_found"},
}


# The codes of the causes a `reason` names (`reason_causes`), for the code that acts on a cause;
# the reason's words are for people.
TOO_CLOSE = "too_close"  # crossings too close along a wire for a free bending point between them
# The pipeline's setup problems, when slicing gave fewer than two wires (pipeline.solve stops before
# any stage): a scene still to set up, not a verdict on a design. The add-on (Live's "cannot solve",
# the Stability box, Optimize's report) knows them by these codes (setup_problem).
NO_WIRES_CAUSE = "no_wires"  # no plane cuts the mesh
ONE_WIRE_CAUSE = "one_wire"  # one wire only
SETUP_CAUSES = (NO_WIRES_CAUSE, ONE_WIRE_CAUSE)

# The words of the setup problems, by code; design.json keeps them as written (`stable` false,
# `reason` one of these, `reason_causes` its code).
NO_WIRES = "no plane cuts the mesh: move the planes through the mesh"
ONE_WIRE = "a sculpture needs at least two wires: add a plane or pick more contours"
SETUP_WORDS = {NO_WIRES_CAUSE: NO_WIRES, ONE_WIRE_CAUSE: ONE_WIRE}


# The code of the verdict (`verdict_cause`): what makes the design not stable, written with
# `stable` and `reason` by whoever sets them (KEYS' comment); the reason's words are for people.
STABLE_CAUSE = "none"  # stable
# The layering's own verdicts: the native LayeringCause, as the binding names it.
ALONE = "alone"  # a wire crosses no other wire
DISCONNECTED = "disconnected"  # a group of wires crosses none of the others
NO_CROSSINGS = "no_crossings"  # no two wires cross
NO_STABLE_PAIR = "no_stable_pair"  # no pair of wires is stable under forces only
NO_ASSEMBLY_ORDER = "no_assembly_order"  # no wire can be added stably to the largest stable partial assembly
MECHANISM = "mechanism"  # not stable even with both hooks at every crossing (`what_moves`)
SEARCH_INCOMPLETE = "search_incomplete"  # max_nodes stopped the search (`search_incomplete`)
LAYERING_CAUSES = (STABLE_CAUSE, ALONE, DISCONNECTED, NO_CROSSINGS, NO_STABLE_PAIR, NO_ASSEMBLY_ORDER, MECHANISM,
                   SEARCH_INCOMPLETE)
# The layering's verdicts that depend on the hooks allowed: over the allowed ones only when
# stages.layering.forbidden_hooks is not 0.
HOOK_VERDICTS = (NO_CROSSINGS, NO_STABLE_PAIR, NO_ASSEMBLY_ORDER, MECHANISM, SEARCH_INCOMPLETE)
# Later stages' verdicts (and the setup problems' codes, SETUP_CAUSES, when slicing gave fewer
# than two wires):
UNREALISED = "unrealised"  # the target shape nulled crossings and the assembly no longer stands without them
NOT_BUILDABLE = "not_buildable"  # a wire's bend program cannot be made (fab/buildability.apply)

# How the re-layering loop ended (stages.relayering.end, pipeline.relayer).
RELAYER_STABLE = "stable"  # the design is stable
RELAYER_NOTHING_NEW = "nothing_new"  # not stable, and no hook the target shape failed is left to forbid
RELAYER_INCOMPLETE = "search_incomplete"  # max_nodes stopped the last layering
RELAYER_ROUNDS = "max_rounds"  # relayer_rounds re-layerings ran
# The last layering found no stable assembly without the forbidden hooks: the design is the last
# round that reached the target shape
RELAYER_NO_ASSEMBLY = "no_assembly"
RELAYER_ENDS = (RELAYER_STABLE, RELAYER_NOTHING_NEW, RELAYER_INCOMPLETE, RELAYER_ROUNDS, RELAYER_NO_ASSEMBLY)


def setup_problem(design):
    """Whether `design` is not stable for a setup problem (`reason_causes` holds one of
    SETUP_CAUSES): nothing was solved, so it says what to set up rather than that a design does not
    stand."""
    if design.get("stable"):
        return False
    causes = design.get("reason_causes")
    if causes is not None:
        return any(code in SETUP_CAUSES for code in causes)
    # A design without `reason_causes`: one written before the pipeline gave setup problems a code
    # (kept in .blend files), or one whose reason names no coded cause. The pipeline stops with a
    # setup problem exactly when slicing gave fewer than two wires, before any stage ran, so such a
    # design is known by those facts: a reason, fewer than two wires and the layering still pending
    # (an unstable design that the layering judged has run it).
    return (bool(design.get("reason")) and len(design.get("wires") or ()) < 2
            and "layering" in (design.get("pending_stages") or ()))


def written_by(stage):
    """{"top": [...], "wire": [...], "crossing": [...], "stages": [...]}: the keys `stage` writes."""
    return {part: [k for k, owner in table.items() if owner == stage] for part, table in KEYS.items()}


def crossing_direction(design, crossing):
    """d = normalize(n0 x n1), n0 and n1 the plane normals of the crossing's wires as written in
    the design (docs/formats.md `hook`: hook 1 opens the kink of wires[0] towards +d)."""
    return np.array(crossing_axis(design, crossing))


def crossing_axis(design, crossing):
    """crossing_direction as a tuple of three floats. The cross product and its length written out:
    numpy's np.cross and np.linalg.norm cost ~20x more on one pair of 3-vectors (the target-shape
    stage asks at every crossing), with the same products and sums in the same order."""
    (a0, a1, a2), (b0, b1, b2) = (map(float, design["wires"][w]["plane"]["normal"]) for w in crossing["wires"])
    x, y, z = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
    length = math.sqrt(x * x + y * y + z * z)
    if length == 0.0:  # parallel planes: no common line (numpy's 0/0)
        return (math.nan, math.nan, math.nan)
    return (x / length, y / length, z / length)


def model_size(design, contours=None):
    """The largest side of the bounding box of every wire's contour (m); `contours`: those contours
    already as arrays, in the wires' order."""
    if contours is None:
        contours = [np.asarray(w["contour"]) for w in design["wires"]]
    points = np.concatenate(contours)
    if points.ndim != 2:
        return float(np.max(points.max(axis=0) - points.min(axis=0)))
    # Column by column: the same extremes as points.max(axis=0), whose reduction across the rows of
    # an (n, 3) array took 0.1 ms on the Duck's 2,500 points against 0.01 ms (np.max, not max, so
    # that a NaN still makes the size NaN).
    return float(np.max([points[:, k].max() - points[:, k].min() for k in range(points.shape[1])]))


def new_design(material, settings):
    return {
        "format": FORMAT,
        "version": VERSION,
        "units": "m",
        "material": dict(material),
        "torque_fraction": settings["torque_fraction"],
        "machine": {
            "min_segment": settings["min_segment"],
            "max_bend_deg": settings["max_bend_deg"],
            "min_bend_deg": settings["min_bend_deg"],
        },
        "wires": [],
        "stable": False,
        "reason": "",
        "stages": {},
    }


def wire_entry(wire_id, name, origin, normal, closed, contour):
    """A wire as sliced: `contour` (n, 3) in metres; later stages add target, rest, cut, length."""
    return {
        "id": wire_id,
        "name": name,
        "plane": {"origin": [float(x) for x in origin], "normal": [float(x) for x in normal]},
        "closed": bool(closed),
        "contour": [[float(x) for x in p] for p in contour],
    }


# An innermost list spread over lines (JSON strings cannot hold a raw newline, so this only
# matches real lists): written on one line, so a polyline reads one point per line.
_INNER_LIST = re.compile(r"\[\n\s+([^\[\]{}]*?)\n\s*\]")


def dumps(design):
    text = json.dumps(design, indent=1, allow_nan=False)
    return _INNER_LIST.sub(lambda m: "[" + " ".join(m.group(1).split()) + "]", text) + "\n"


def write_design(path, design):
    write_atomic(path, dumps(design))
