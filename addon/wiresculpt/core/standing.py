"""The 3D check's vocabulary (stages/stands3d.py computes it): its causes, the sag limit and the
sentence a user reads for a `stands_3d` record, made here from its cause and figures. bpy-free."""
from .sizes import model_size

# The sag a maker accepts: the larger of 2 mm (the size a bender's tolerance and a hand's fit
# already allow) and 1 % of the sculpture's largest side (what the eye does not see at arm's length).
SAG_FLOOR = 0.002
SAG_SHARE = 0.01
# Relative tolerance of the pyramid test (the force's distance from the cone over its size): the
# solver's residual is 1e-8 of the load, so 1e-6 is far above its noise and far below a real slip.
PYRAMID_TOLERANCE = 1e-6

TILT_SAID_DEG = 1.0  # a sculpture that rolls further than this on a table is said to rest tilted

STANDS = "stands"
NO_EQUILIBRIUM = "no_equilibrium"  # no equilibrium found (the native's cause is `solver_cause`)
SLIPS = "slips"  # a crossing's force outside its pyramid
SAGS = "sags"  # a wire further than the sag limit from its target
CAUSES = (STANDS, NO_EQUILIBRIUM, SLIPS, SAGS)
# A plane-assistant candidate's 3D verdict in the panel's line ("..., stands in 3D (sag 0.4 mm)")
CANDIDATE_WORDS = {STANDS: "stands", NO_EQUILIBRIUM: "finds no balance", SLIPS: "slips at a crossing",
                   SAGS: "sags"}


def sag_limit(design):
    """m: the larger of SAG_FLOOR and SAG_SHARE of the sculpture's largest side."""
    return max(SAG_FLOOR, SAG_SHARE * model_size(design))


def _mm(metres):
    return f"{metres * 1000:.1f} mm"


def words(record):
    """The sentence for a `stands_3d` record, made from its cause and figures."""
    cause = record["cause"]
    if cause == STANDS:
        tilt = record.get("tilt_deg") or 0.0
        rests = f"; on a table it rests tilted by {tilt:.1f}°" if tilt >= TILT_SAID_DEG else ""
        return (f"stands in 3D: every crossing holds, the wires within {_mm(record['max_sag'])} of their targets "
                f"(limit {_mm(record['sag_limit'])}){rests}")
    if cause == NO_EQUILIBRIUM:
        return f"does not stand in 3D: the assembled wires under their weight find no equilibrium ({record['solver_message']})"
    if cause == SLIPS:
        ids = record["slipping"]
        return (f"does not stand in 3D: crossing{'s' if len(ids) > 1 else ''} {', '.join(map(str, ids))} would have "
                f"to pull or slip (the force leaves its friction and hook pyramid)")
    return (f"does not stand in 3D: wire {record['max_sag_wire']} sags {_mm(record['max_sag'])} from its target "
            f"(limit {_mm(record['sag_limit'])})")


# --- the display's words (Blender's Stability box, the as-built legend, Live) -----------------

DEFLECTION_NOTE = ("the out-of-plane warnings load each wire alone and overstate its bending; the assembled "
                   "sculpture's sag above is the 3D check's")


def checked(design):
    """The design's `stands_3d` record when the 3D check ran (its cause one of CAUSES), else None."""
    record = design.get("stands_3d")
    return record if isinstance(record, dict) and record.get("cause") in CAUSES else None


def has_sag(design):
    """Whether the 3D check ran and gave its wires a sag (the per-wire rows show it)."""
    return checked(design) is not None and any("sag" in w for w in design.get("wires") or [])


def sag_column(design):
    """The per-wire rows' word for their last figure: "sag" (has_sag) or "out of plane"."""
    return "sag" if has_sag(design) else "out of plane"


def sag_text(metres):
    """A wire's sag as the panel shows it: "0.15 mm"."""
    return f"{metres * 1000:.2f} mm"


def wire_heading(design):
    """The heading of the per-wire rows: the 3D check's sag where it ran (with its limit), else the
    out-of-plane deflection of each wire loaded alone, said as such."""
    if has_sag(design):
        return f"Per wire: closure gap, sag in 3D (limit {sag_text(checked(design)['sag_limit'])})"
    return "Per wire: closure gap, out of plane (each wire alone)"


def summary(record):
    """The 3D verdict in one short line (Live's second line): "3D: stands, sag at most 0.15 mm
    (limit 2.50 mm)", "3D: crossings 3, 5 slip", "3D: wire A/0 sags 4.10 mm (limit 2.50 mm)",
    "3D: no equilibrium"."""
    cause = record["cause"]
    if cause == STANDS:
        return f"3D: stands, sag at most {sag_text(record['max_sag'])} (limit {sag_text(record['sag_limit'])})"
    if cause == SLIPS:
        ids = record["slipping"]
        return f"3D: crossing{'s' if len(ids) > 1 else ''} {', '.join(map(str, ids))} slip{'' if len(ids) > 1 else 's'}"
    if cause == SAGS:
        return (f"3D: wire {record['max_sag_wire']} sags {sag_text(record['max_sag'])} "
                f"(limit {sag_text(record['sag_limit'])})")
    return "3D: no equilibrium"


def legend_words(record, limit, scale, slipping):
    """The as-built legend's words (core/as_built_view.legend): its title, the labels of the ramp's
    stops (0, half the limit, the limit) and its notes (the largest sag, the exaggeration, the
    slipping crossings)."""
    notes = []
    if isinstance(record.get("max_sag"), (int, float)) and record.get("max_sag_wire") is not None:
        notes.append(f"largest {sag_text(record['max_sag'])} ({record['max_sag_wire']})")
    if scale != 1.0:
        notes.append(f"shape change drawn {scale:g}x")
    if slipping:
        notes.append(f"+ marks: crossing{'s' if len(slipping) > 1 else ''} {', '.join(map(str, slipping))} "
                     f"slip{'' if len(slipping) > 1 else 's'}")
    notes.insert(0, f"red: at the {sag_text(limit)} sag limit or past it")
    return {"title": "As built: distance from target",
            "stops": ["0 mm", sag_text(limit / 2), sag_text(limit)], "notes": notes}
