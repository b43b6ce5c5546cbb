"""Is the stored design still the scene's? The Stability box's first line (core/stale.py with the
scene's planes, ticks and panel values) and the Live line's hint when Live and a current Optimize
disagree. Shared by ui/results.py and ui/panel.py; no panel here."""
from .. import props
from ..blend import results as scene_results
from ..blend import model_watch
from ..blend.handles import model_name
from ..core import live_verdict, stale
from ..core.limits import broken_limits, hooks_may_help, recorded_stock


def setting_labels():
    """{solver setting or material key: the name the panel shows it by}, for core/stale's phrase."""
    rna = props.WiresculptSettings.bl_rna.properties
    labels = {key: rna[key].name for key in props.SETTING_PROPS + props.MATERIAL_PROPS if key in rna}
    labels["name"] = rna["material_preset"].name  # the material's name: a preset or a calibrated one
    return labels


# core/stale.recorded_planes of the stored design and the setting labels, kept while
# stored_design() returns the same dict (it does until the text changes): read at every redraw
_recorded = {"design": None, "planes": None, "labels": None}


def report(context):
    """(what changed in the scene since the stored design was optimized (core/stale.changes), [] while
    it is current; {the design's plane names: their names now (core/stale.current_names)}), ([], {})
    when there is no design. Reads the handles as last evaluated (the view layer's depsgraph, not
    evaluated again from a panel's draw)."""
    design = scene_results.stored_design()
    if design is None:
        return [], {}
    if _recorded["design"] is not design:
        _recorded.update(design=design, planes=stale.recorded_planes(design), labels=setting_labels())
    scene = context.scene
    ws = scene.wiresculpt
    inputs = scene_results.stored_inputs()
    planes, ticked, names = scene_results.scene_planes(scene, context.view_layer.depsgraph, _recorded["planes"][0],
                                                       (inputs or {}).get("planes"))
    try:
        settings = props.solver_settings(ws)
    except ValueError:  # the panel's values cannot be solved (smallest bend above the largest)
        settings = None
    mesh = None
    if inputs and "mesh" in inputs and ws.model is not None and inputs.get("target") == ws.model.name:
        mesh = model_watch.mesh_state(ws.model, context.view_layer.depsgraph)
    now = stale.SceneNow(planes, ticked, names, model_name(ws), settings, props.material_of(ws), mesh)
    said = stale.changes(design, now, inputs, _recorded["labels"], _recorded["planes"])
    return said, names


def report_changes(context):
    """The phrases of report(context): what changed since the stored design was optimized."""
    return report(context)[0]


def design_limits(design):
    """core/limits.broken_limits(design), computed once per stored design (panels read it at every
    redraw)."""
    if _limits["design"] is not design:
        _limits.update(design=design, said=broken_limits(design, recorded_stock(scene_results.stored_inputs())))
    return _limits["said"]


_limits = {"design": None, "said": []}

# Live solves with the layering's own hook pattern only; Optimize compares more of them.
TRIES_MORE = "Live tries the layering's hooks only: Optimize tries more and may keep these planes within their limits"


def live_hint(context, kind, limits=()):
    """A short line under the Live line when Live's verdict (of `kind`, breaking the limits of the
    codes `limits`, core/live_verdict and core/limits) disagrees with the stored design while
    that design is current: Optimize searched more hook patterns on the same planes, its verdict is
    the one to build from. Live's "stable, over its limits" without a current Optimize says that
    Optimize may do better (TRIES_MORE) when another hook pattern may help (the load factor, the
    deflection; not the stock or the size). "" otherwise (no disagreement, Live solving or unable to
    solve)."""
    if kind not in (live_verdict.STABLE, live_verdict.OVER_LIMITS, live_verdict.NOT_STABLE):
        return ""
    design = scene_results.stored_design()
    current = design is not None and not report_changes(context)
    if not current:
        helps = kind == live_verdict.OVER_LIMITS and hooks_may_help(limits)
        return TRIES_MORE if helps else ""
    if design.get("stable"):
        found = live_verdict.OVER_LIMITS if design_limits(design) else live_verdict.STABLE
    else:
        found = live_verdict.NOT_STABLE
    if found == kind:
        return ""
    said = {live_verdict.STABLE: "stable within their limits", live_verdict.OVER_LIMITS: live_verdict.OVER_LIMITS,
            live_verdict.NOT_STABLE: "not stable"}[found]
    return f"Optimize found these planes {said} (it tries more hook patterns): build from Optimize's result"
