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
