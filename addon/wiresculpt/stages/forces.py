"""Internal forces, cuts, rest shapes and load capacity (Sec. 4.4, Eq. 6-12, and beyond the paper):
one native call on the target shapes (docs/method-forces.md).

Fills, per crossing, `force` (N, on wires[0] by wires[1], docs/formats.md), `normal_force` and
`out_of_plane` (|f.n|/|f| for the plane of wires[0] and of wires[1]); per wire `cut`, `rest`
(2D, metres, in the wire's plane frame, from the cut in the direction of increasing target index),
`rest_angles` and `target_angles` (radians, one per rest point), `closure_gap` (m),
`max_torque` (N m) and `max_torque_vertex`, `max_out_of_plane_torque`, `max_torque_3d` (N m, in-plane
and out-of-plane bending and twist together; bounded by t_max, stages.forces.torque_bound "3d"),
`rest_over_bend`;
`load_capacity` (weight_N and the multiple of it the sculpture holds with gravity along each
axis direction; absent when the material has no density), `out_of_plane` statistics (mean and max of
the shares; mean_to_max_force and max_to_max_force: |f.n| over the largest |f|, the paper's measure),
`stages.forces` and `stages.rest_shape`; `torque_fraction` (the one used) and, when the load
factor chose it, `load_factor` ({asked, reached, at_plastic_limit, weakest, limited}). Only
computed values are written.

A user's cut for a closed wire may be given as the wire's `cut_override` (index into `target`,
the batch scene's settings.cuts), validated by the solver (a ValueError names the wire), or as a
`cut_point` (x, y, z metres, the add-on's cut handle), which is snapped to the target point
nearest it that is not a crossing.
"""
import math

import numpy as np

from .. import native
from .stands3d import resting

AXES = ("+x", "-x", "+y", "-y", "+z", "-z")


def snap_cut(design, wire):
    """Index of the wire's target point nearest its `cut_point` among those that are not a
    crossing (where the solver refuses to cut). ValueError when every point is a crossing."""
    target = np.asarray(wire["target"], dtype=np.float64)
    crossing = {c["vertices"][k] for c in design.get("crossings", []) for k in (0, 1)
                if c["wires"][k] == wire["id"]}
    distance = np.linalg.norm(target - np.asarray(wire["cut_point"], dtype=np.float64), axis=1)
    distance[sorted(crossing)] = np.inf
    if not np.isfinite(distance).any():
        raise ValueError(f'wire {wire["name"]}: every target point is a crossing; there is no point to cut at')
    return int(np.argmin(distance))


def requested_cut(design, wire):
    """The cut the user asked for: an index, a point snapped to the target, or -1 (automatic)."""
    if "cut_override" in wire:
        return int(wire["cut_override"])
    if wire["closed"] and "cut_point" in wire:
        return snap_cut(design, wire)
    return -1


def torque_choice(material, settings, design):
    """(torque fraction, load factor) for the solver: an explicit settings.torque_fraction with no
    load factor (0); otherwise the load factor, from which the solver picks the least fraction
    that holds it (docs/method-forces.md §10). Without a density there is no weight to hold: the
    plastic limit (fraction 1), with a warning."""
    if settings.get("torque_fraction") is not None:
        return settings["torque_fraction"], 0.0
    if "density" not in material:
        design.setdefault("warnings", []).append(
            f"the material has no density, so the sculpture's weight and the load factor "
            f"{settings['load_factor']:g} cannot be used; the full plastic-limit torque is (torque fraction 1)")
        return 1.0, 0.0
    return 1.0, settings["load_factor"]


def load_factor_warnings(load_factor, fraction):
    """A warning when even the plastic limit cannot hold the load factor asked."""
    if not load_factor["limited"]:
        return []
    return [f"load factor {load_factor['asked']:g} not reached: at the plastic limit (torque fraction "
            f"{fraction:g}) the sculpture holds {load_factor['reached']:.2f}x its weight in its weakest "
            f"direction ({load_factor['weakest']})"]


def _inputs(design):
    wires = [{"name": w["name"], "origin": w["plane"]["origin"], "normal": w["plane"]["normal"],
              "target": np.asarray(w["target"], dtype=np.float64), "closed": w["closed"],
              "cut": requested_cut(design, w)}
             for w in design["wires"]]
    crossings = [{"wires": list(c["wires"]), "vertices": list(c["vertices"]), "hook": int(c["hook"])}
                 for c in design["crossings"]]
    return wires, crossings


def run(design, material, settings, native_progress=None, load_capacity_within=None):
    """Computes forces, rest shapes and load capacity into `design`. Returns the forces stage's
    progress line; rest_summary(design) gives the rest-shape stage's. `load_capacity_within`
    (radians): when a rest angle is beyond it, no load capacity (the pipeline's coupling rounds
    that will be solved again; native forces_and_rest.hpp)."""
    wires, crossings = _inputs(design)
    mat = {k: material[k] for k in ("bending_stiffness", "max_torque", "friction", "wire_diameter", "density",
                                    "shear_modulus") if k in material}
    fraction, load_factor = torque_choice(material, settings, design)
    options = {"torque_fraction": fraction, "load_factor": load_factor,
               "max_bend": math.radians(settings["max_bend_deg"]),
               # "3d" (default: |t_v| <= t_max, Sec. 4.4) or "in_plane" (the plane-normal part only,
               # to compare with the earlier model); not a scene-file key
               "torque_bound": settings.get("torque_bound", "3d"),
               # within 3% of the optimal G_stb, the least out-of-plane force (docs/method-forces.md §12)
               "least_out_of_plane": settings.get("least_out_of_plane", True),
               # the forces the assembled 3D structure carries kept in their pyramids (§17)
               "carried_3d": settings.get("carried_3d", True),
               "carried_margin": settings.get("carried_margin", 0.2),
               "carried_share": settings.get("carried_share", 0.25)}
    if load_capacity_within is not None:
        options["load_capacity_within"] = load_capacity_within
    if options["carried_3d"]:  # the weight's share, as the sculpture rests on its table
        turn, supports = resting(design)
        options["carried_gravity"] = list(turn.T @ np.array([0.0, 0.0, -9.81]))
        options["carried_supports"] = supports
    steps = [list(s) for s in design.get("assembly_steps", [])]
    r = native.forces_and_rest(wires, crossings, steps, mat, options, native_progress)

    # The solver answers in the design's own keys (docs/formats.md): copied, never renamed.
    for c, out in zip(design["crossings"], r["crossings"]):
        c.update(out)
    # A rest bend over the machine's limit is named by the buildability verdict (fab/buildability.py),
    # in the bend program's numbering, after the pipeline's coupling rounds (Sec. 4.3).
    for w, out in zip(design["wires"], r["wires"]):
        w.update(out)
    design["torque_fraction"] = r["torque_fraction"]
    if r["load_factor"] is not None:
        design["load_factor"] = r["load_factor"]
        design.setdefault("warnings", []).extend(load_factor_warnings(r["load_factor"], r["torque_fraction"]))
    design["out_of_plane"] = r["out_of_plane"]
    if r["load_capacity"] is not None:
        design["load_capacity"] = r["load_capacity"]
    design.setdefault("warnings", []).extend(r["warnings"])
    design["stages"].update(r["stages"])
    hooked = [c for c in design["crossings"] if c["hook"] != 0]
    summary, out_of_plane = design["stages"]["forces"], design["out_of_plane"]
    normals = [c["normal_force"] for c in hooked]
    line = (f"{len(hooked)} loaded crossings, normal forces {min(normals, default=0):.2f}-"
            f"{max(normals, default=0):.2f} N (sum {summary['g_stb'] / 2:.2f} N), out of plane "
            f"{100 * out_of_plane['mean']:.1f}% mean, {100 * out_of_plane['max']:.1f}% max "
            f"({100 * out_of_plane['mean_to_max_force']:.1f}% mean of the largest force), "
            f"{summary['method']} ({summary['seconds']:.3f} s)")
    if "load_capacity" in design:
        lc = design["load_capacity"]
        held = [lc[a] for a in AXES if lc[a] is not None]
        line += (f"; holds {min(held):.1f}x its weight ({lc['weight_N']:.2f} N) in the weakest direction"
                 if held else "")
    line += f"; torque fraction {design['torque_fraction']:.3f}"
    if "load_factor" in design:
        line += f" (load factor {design['load_factor']['asked']:g})"
    return line


def rest_summary(design):
    """The rest-shape stage's progress line (after run)."""
    stage = design["stages"]["rest_shape"]
    return (f"{len(design['wires'])} rest shapes, largest closure gap {stage['max_closure_gap'] * 1000:.2f} mm, "
            f"{stage['over_bend']} bends over the machine limit ({stage['seconds']:.4f} s)")
