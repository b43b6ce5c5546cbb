"""What a search did, for the design's `plane_search` record, its progress line and the reason
when it found nothing."""
import time

from .placements import OFFSETS, TILTS_DEG, Placement
from .searcher import FINAL_HOOK_PATTERNS, SCREEN_NODES


def _record(mode, before, candidate, searcher, start):
    return {"mode": mode,
            "planes_before": [Placement(p.name, p.origin, p.normal, p.contours).as_dict() for p in before],
            "planes_after": [p.as_dict() for p in candidate["planes"]] if candidate else [],
            "changes": candidate["changes"] if candidate else [],
            "candidates": searcher.screened, "full_solves": searcher.full_solves,
            "budget_seconds": searcher.budget, "solves_stopped": searcher.timed_out,
            "solves_failed": searcher.failed, "final_solve": searcher.final,
            # what bounded the search: its counts of work, whether one of them or the guard ended it
            "limits": dict(searcher.limits, screen_nodes=SCREEN_NODES, final_hook_patterns=FINAL_HOOK_PATTERNS),
            "stopped_by": searcher.stopped_by(), "screens_cut": searcher.screens_cut,
            "seconds": time.perf_counter() - start, "score": candidate["score"] if candidate else None,
            # the returned candidate's looks (Searcher.looks): fidelity (the design's `fidelity` share) and coverage
            "fidelity": (candidate or {}).get("fidelity"), "coverage": (candidate or {}).get("coverage"),
            **({"not_found": nearby_ending(searcher)} if mode == "nearby" and not candidate and searcher.tally else {}),
            "measure": ("cost = sum of |offset| / model size + tilt in radians + 0.05 per contour-rule change; "
                        "score = -cost" if mode == "nearby" else
                        "score = fidelity (mean share over the front, side and top views of the model's outline "
                        "within 0.03 model size of a projected wire)")}


def nearby_reason(searcher):
    """Why the nearby search `searcher` ran found no stable placement (plane_faults.Tally.report):
    what it searched, how far the budget let it, its candidates counted by fault, what to change."""
    s = searcher
    return s.tally.report(OFFSETS[-1] * s.size * 1000.0, s.size * 1000.0, TILTS_DEG[-1], _ended_by(s),
                          float(s.settings.get("min_segment") or 0.0))


def _ended_by(s):
    """What ended a search with work left, for Tally.report: the guard's seconds (a number), or the
    count of work reached, in words."""
    if s.time_stopped or not s.count_stopped:
        return s.budget
    if s.screened >= s.limits.get("candidates", float("inf")):
        return f"limit of {s.limits['candidates']} candidates screened"
    return f"limit of {s.limits['full_solves']} full solves"


def nearby_ending(searcher):
    """How the nearby search `searcher` ran ended without a stable placement, as data
    (plane_faults.Tally.ending, with the settings' min_segment as nearby_reason words it)."""
    return searcher.tally.ending(float(searcher.settings.get("min_segment") or 0.0))


def _summary(record):
    what = "; ".join(record["changes"]) or ("the planes as given" if record["planes_after"] else "nothing stable")
    looks = "".join(f"; {words} {record[key]:.0%} of the {what}" for key, words, what in (
        ("fidelity", "traces", "outline"), ("coverage", "covers", "mesh")) if record.get(key) is not None)
    return (f"{record['mode']}: {what}{looks} ({record['candidates']} candidates screened, {record['full_solves']} "
            f"full solves, {record['seconds']:.2f} s)")
