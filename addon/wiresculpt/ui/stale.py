"""Is the stored design still the scene's? The Stability box's first line (core/stale.py with the
scene's planes, ticks and panel values) and the Live line's hint when Live and a current Optimize
disagree. Shared by ui/results.py and ui/panel.py; no panel here."""
from .. import props
from ..blend import results as scene_results
from ..blend.handles import target_name
from ..core import live_verdict, stale


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
    said = stale.changes(design, planes, ticked, inputs, target_name(ws),
                         settings, props.material_of(ws), _recorded["labels"], _recorded["planes"], names)
    return said, names


def report_changes(context):
    """The phrases of report(context): what changed since the stored design was optimized."""
    return report(context)[0]


def live_hint(context, verdict):
    """A short line under the Live line when Live's `verdict` (stable / not stable) disagrees with
    the stored design while that design is current: Optimize searched more hook patterns on the
    same planes, its verdict is the one to build from. "" otherwise (no design, an earlier one,
    Live solving or unable to solve)."""
    kind = live_verdict.kind_of(verdict)
    design = scene_results.stored_design()
    if kind not in (live_verdict.STABLE, live_verdict.NOT_STABLE) or design is None:
        return ""
    if bool(design.get("stable")) == (kind == live_verdict.STABLE) or report_changes(context):
        return ""
    said = "stable" if design.get("stable") else "not stable"
    return f"Optimize found these planes {said} (it tries more hook patterns): build from Optimize's result"
