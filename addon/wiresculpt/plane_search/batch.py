"""The headless pipeline with settings.plane_search (the batch script's entry)."""
from .. import pipeline
from ..core import fidelity
from ..core import settings as settings_table
from ..core.solve_context import SolveContext
from .auto import auto, family_planes
from .nearby import nearby
from .placements import Placement
from .records import _record, _summary, nearby_reason

MODES = ("off", "nearby", "auto")


def _looks(design, vertices, faces):
    """The design with its `fidelity` record (core/fidelity.py) against the mesh, when it has wires
    and no record yet (a candidate of a search has its own)."""
    if "fidelity" not in design and design.get("wires"):
        fidelity.record(design, vertices, faces)
    return design


def run(vertices, faces, planes, material, settings, progress=None, cancel=None, stock=None):
    """The headless pipeline with settings.plane_search: "off" -> pipeline.run; "nearby" -> the
    given planes first, the nearby search when they give no stable design; "auto" -> planes
    from the mesh. The design carries `plane_search` whenever a search ran, and `fidelity` whenever it
    has wires (core/fidelity.py); when none is found the
    design of the given planes (nearby) or of the first proposal (auto) is returned, not stable,
    with the reason saying what was tried. `stock`: as pipeline.solve's. One wall-clock budget,
    settings.max_solve_seconds, for the whole run, the search and every solve in it included: past
    it OutOfTime (naming the key and the stage) ends the run. `progress`: a callback (stage, message),
    or a SolveContext whose progress, cancel and clock the run takes (a test's clock may run fast;
    the budget is still the settings'). Returns (design, planes actually used)."""
    clock = None
    if isinstance(progress, SolveContext):
        progress, cancel, clock = progress.progress, cancel or progress.cancelled, progress.clock
    say = progress or (lambda stage, message: None)
    budget = float(settings.get("max_solve_seconds") or settings_table.SETTINGS["max_solve_seconds"][0])
    context = SolveContext(progress, cancel, budget, clock)  # the run's progress, cancel and one deadline
    mode = settings.get("plane_search", "off")
    if mode == "off":
        return _looks(pipeline.run(vertices, faces, planes, material, settings, context, None, stock), vertices,
                      faces), list(planes)
    if mode == "nearby":
        if not planes:
            raise ValueError('settings.plane_search "nearby" needs planes to start from; give "planes" or use "auto"')
        found, s, start = nearby((vertices, faces), planes, material, settings, 1, context=context, stock=stock)
        if found:
            best = found[0]
            design = best["design"]
        else:
            design = pipeline.run(vertices, faces, planes, material, settings, context, None, stock)
            best = None
            if not design["stable"]:
                design["reason"] = (f"{nearby_reason(s)}. The planes as given: {design['reason']}"
                                    if design["reason"] else nearby_reason(s))
        _looks(design, vertices, faces)
        design["plane_search"] = _record("nearby", planes, best, s, start)
        used = [p.spec() for p in best["planes"]] if best else list(planes)
        say("plane_search", _summary(design["plane_search"]))
        return design, used
    if mode == "auto":
        count = int(settings.get("plane_count", 5))
        found, s, start = auto((vertices, faces), count, material, settings, context=context, stock=stock)
        if found:
            best = found[0]
            design = best["design"]
            used = [p.spec() for p in best["planes"]]
        else:
            best = None
            used = [p.spec() for p in family_planes(s, (count - count // 2, count // 2, 0))]
            design = pipeline.run(vertices, faces, used, material, settings, context, None, stock)
            if not design["stable"]:
                design["reason"] += (f"; no proposed set of {count} planes ({s.screened} tried) gives a "
                                     f"stable design")
        _looks(design, vertices, faces)
        design["plane_search"] = _record("auto", planes, best or ({"planes": [
            Placement(p.name, p.origin, p.normal, p.contours) for p in used], "changes": [], "score": None,
            "fidelity": design["fidelity"]["share"] if "fidelity" in design else None}
            if design["stable"] else None), s, start)
        say("plane_search", _summary(design["plane_search"]))
        return design, used
    raise ValueError(f'settings.plane_search must be one of {", ".join(MODES)}, got {mode!r}')
