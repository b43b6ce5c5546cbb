"""Internal forces, cuts, rest shapes and load capacity (Sec. 4.4, Eq. 6-12, and beyond the paper):
one native call on the target shapes (docs/method-forces.md).

Fills, per crossing, `force` (N, on wires[0] by wires[1], FORMATS.md), `normal_force` and
`out_of_plane` (|f.n|/|f| for the plane of wires[0] and of wires[1]); per wire `cut`, `rest`
(2D, metres, in the wire's plane frame, from the cut in the direction of increasing target index),
`rest_angles` and `target_angles` (radians, one per rest point), `closure_gap` (m),
`max_torque` (N m) and `max_torque_vertex`, `max_out_of_plane_torque`, `max_torque_3d` (N m, in-plane
and out-of-plane bending and twist together; bounded by t_max, stages.forces.torque_bound "3d"),
`rest_over_bend`;
`load_capacity` (weight_N and the multiple of it the sculpture holds with gravity along each
axis direction; absent when the material has no density), `out_of_plane` statistics (mean and max of
the shares; mean_to_max_force and max_to_max_force: |f.n| over the largest |f|, the paper's measure),
`stages.forces` and `stages.rest_shape`. Only computed values are written.

A user's cut for a closed wire may be given as the wire's `cut_override` (index into `target`,
the batch scene's settings.cuts), validated by the solver (a ValueError names the wire), or as a
`cut_point` (x, y, z metres, the add-on's cut handle), which is snapped to the target point
nearest it that is not a crossing.
"""
import math

import numpy as np

from .. import native

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


def _inputs(design):
    wires = [{"name": w["name"], "origin": w["plane"]["origin"], "normal": w["plane"]["normal"],
              "target": np.asarray(w["target"], dtype=np.float64), "closed": w["closed"],
              "cut": requested_cut(design, w)}
             for w in design["wires"]]
    crossings = [{"wires": list(c["wires"]), "vertices": list(c["vertices"]), "hook": int(c["hook"])}
                 for c in design["crossings"]]
    return wires, crossings


def run(design, material, settings, native_progress=None):
    """Computes forces, rest shapes and load capacity into `design`. Returns the forces stage's
    progress line; rest_summary(design) gives the rest-shape stage's."""
    wires, crossings = _inputs(design)
    mat = {k: material[k] for k in ("bending_stiffness", "max_torque", "friction", "wire_diameter", "density")
           if k in material}
    options = {"torque_fraction": settings["torque_fraction"], "max_bend": math.radians(settings["max_bend_deg"]),
               # "3d" (default: |t_v| <= t_max, Sec. 4.4) or "in_plane" (the plane-normal part only,
               # to compare with the earlier model); not a scene-file key
               "torque_bound": settings.get("torque_bound", "3d")}
    steps = [list(s) for s in design.get("assembly_steps", [])]
    r = native.require().forces_and_rest(wires, crossings, steps, mat, options, native_progress)

    for c, out in zip(design["crossings"], r["crossings"]):
        c["force"] = [float(x) for x in out["force"]]
        c["normal_force"] = float(out["normal"])
        c["out_of_plane"] = [float(x) for x in out["out_of_plane"]]
    for w, out in zip(design["wires"], r["wires"]):
        w["cut"] = int(out["cut"])
        w["rest"] = np.asarray(out["rest"]).tolist()
        w["rest_angles"] = [float(a) for a in out["rest_angles"]]
        w["target_angles"] = [float(a) for a in out["target_angles"]]
        w["closure_gap"] = float(out["closure_gap"])
        w["max_torque"] = float(out["max_torque"])
        w["max_torque_vertex"] = int(out["max_torque_vertex"])
        w["max_out_of_plane_torque"] = float(out["max_out_of_plane_torque"])
        w["max_torque_3d"] = float(out["max_torque_3d"])
        w["rest_over_bend"] = [{"vertex": int(o["vertex"]), "angle_deg": math.degrees(o["angle"])}
                               for o in out["over_bend"]]
        for o in out["over_bend"]:
            design.setdefault("warnings", []).append(
                f"wire {w['name']}: the rest shape bends {math.degrees(abs(o['angle'])):.1f} deg at vertex "
                f"{o['vertex']}, more than the machine's {settings['max_bend_deg']:g} deg; lower the torque "
                "fraction or the maximum bend of the target shape and solve again")
    summary, stats = r["forces"], r["stats"]
    hooked = [c for c in design["crossings"] if c["hook"] != 0]
    design["out_of_plane"] = {"mean": summary["mean_out_of_plane"], "max": summary["max_out_of_plane"],
                              "mean_to_max_force": summary["mean_out_of_plane_to_max_force"],
                              "max_to_max_force": summary["max_out_of_plane_to_max_force"],
                              "crossings": len(hooked)}
    if r["load_capacity"] is not None:
        lc = r["load_capacity"]
        design["load_capacity"] = {"weight_N": lc["weight_N"], "length": lc["length"],
                                   **{axis: lc[axis] for axis in AXES},
                                   "base": {axis: [design["wires"][i]["name"] for i in lc["base"][axis]]
                                            for axis in AXES},
                                   "status": dict(lc["status"])}
    design.setdefault("warnings", []).extend(r["warnings"])
    design["stages"]["forces"] = {
        "seconds": stats["forces_seconds"], "lp_seconds": stats["lp_seconds"], "nlp_seconds": stats["nlp_seconds"],
        "lp_iterations": stats["lp_iterations"], "lp_rounds": stats["lp_rounds"], "iterations": stats["iterations"],
        "working_set_rounds": stats["working_set_rounds"], "working_set_rows": stats["working_set_rows"],
        "method": summary["method"],
        "nlopt_result": summary["nlopt_result"], "g_stb": summary["g_stb"], "g_asm": summary["g_asm"],
        "assembly_residual": summary["assembly_residual"], "equilibrium_residual": summary["equilibrium_residual"],
        "t_max": summary["t_max"], "torque_active": summary["torque_active"], "torque_bound": summary["torque_bound"],
        "load_capacity_seconds": r["load_capacity"]["seconds"] if r["load_capacity"] is not None else None,
    }
    gaps = [w["closure_gap"] for w in design["wires"] if w["closed"]]
    design["stages"]["rest_shape"] = {
        "seconds": stats["rest_seconds"],
        "max_closure_gap": max(gaps) if gaps else 0.0,
        "over_bend": sum(len(w["rest_over_bend"]) for w in design["wires"]),
    }
    normals = [c["normal_force"] for c in hooked]
    line = (f"{len(hooked)} loaded crossings, normal forces {min(normals, default=0):.2f}-"
            f"{max(normals, default=0):.2f} N (sum {summary['g_stb'] / 2:.2f} N), out of plane "
            f"{100 * summary['mean_out_of_plane']:.1f}% mean, {100 * summary['max_out_of_plane']:.1f}% max "
            f"({100 * summary['mean_out_of_plane_to_max_force']:.1f}% mean of the largest force), "
            f"{summary['method']} ({stats['forces_seconds']:.3f} s)")
    if "load_capacity" in design:
        lc = design["load_capacity"]
        held = [lc[a] for a in AXES if lc[a] is not None]
        line += (f"; holds {min(held):.1f}x its weight ({lc['weight_N']:.2f} N) in the weakest direction"
                 if held else "")
    return line


def rest_summary(design):
    """The rest-shape stage's progress line (after run)."""
    stage = design["stages"]["rest_shape"]
    return (f"{len(design['wires'])} rest shapes, largest closure gap {stage['max_closure_gap'] * 1000:.2f} mm, "
            f"{stage['over_bend']} bends over the machine limit ({stage['seconds']:.4f} s)")
