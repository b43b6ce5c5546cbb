"""Sub-panels of the Wire tab: material and machine settings, Optimize with its progress, the
stability report of the stored design, and the display of the result (forces, assembly steps,
assembly guide)."""
import math

import bpy

from .. import native, props
from ..blend import results as scene_results
from ..blend.registration import classes_factory
from ..core import as_built_view, closure, mesh_faults, stale, standing
from ..core.design import setup_problem
from ..core.figures import mass_text
from ..core.limits import DEFLECTION_LIMIT, OVER_LIMITS
from .stale import design_limits, report, report_changes  # noqa: F401 (report_changes: read here by the tests)
from ..operators import optimize
from ..operators.results import WIRESCULPT_OT_assembly_guide, WIRESCULPT_OT_clear_results
from .panel import VIEW3D_PT_wiresculpt, length_text, wrap_labels

GRAVITY = 9.81  # m/s^2: weights in newtons to grams


# --- report text, no UI -------------------------------------------------------------------------

AXIS_WORDS = {"-z": "down (-z)", "+z": "up (+z)"}


def sculpture_weight(design):
    """The sculpture's weight in newtons: the forces stage's `load_capacity.weight_N`, or wire
    length x section x density x g when the material has a density; None otherwise."""
    capacity = design.get("load_capacity")
    if isinstance(capacity, dict):
        for key in ("weight_N", "weight"):
            if isinstance(capacity.get(key), (int, float)):
                return float(capacity[key])
    mat = design["material"]
    lengths = [w.get("length") for w in design["wires"]]
    if "density" not in mat or None in lengths:
        return None
    area = math.pi * (0.5 * mat["wire_diameter"]) ** 2
    return sum(lengths) * area * mat["density"] * GRAVITY


def load_capacity_rows(design):
    """[(direction, grams or None)] from design["load_capacity"] (docs/formats.md: the weight multiple the
    sculpture holds with gravity along each axis direction, "+x" ... "-z"), [] when absent.
    grams = multiple x weight / g x 1000; None where no limit was found (unbounded)."""
    capacity = design.get("load_capacity")
    weight = sculpture_weight(design)
    if not isinstance(capacity, dict) or weight is None:
        return []
    rows = []
    for axis in ("-z", "+z", "+x", "-x", "+y", "-y"):
        if axis not in capacity:
            continue
        multiple = capacity[axis]
        finite = isinstance(multiple, (int, float)) and math.isfinite(multiple)
        rows.append((AXIS_WORDS.get(axis, axis), multiple * weight / GRAVITY * 1000.0 if finite else None))
    return rows


def wire_rows(design, names=None):
    """[(wire name, closure gap text or None, sag or out-of-plane text or None)] per wire that has
    either figure: the gap in mm and % of the wire's length (core/closure.py); where the 3D check
    ran, the wire's sag in the assembled sculpture (`sag`, core/standing.sag_text), else its
    out-of-plane deflection loaded alone (`out_of_plane_deflection`, mm), as standing.wire_heading
    says. names: core/stale.current_names, for the wires of renamed planes (core/stale.renamed_wire)."""
    in_3d = standing.has_sag(design)
    rows = []
    for w in design.get("wires", []):
        gap = closure.closure_text(w)
        if in_3d:
            bend = standing.sag_text(w["sag"]) if "sag" in w else None
        else:
            bend = w.get("out_of_plane_deflection")
            bend = f"{bend * 1000:.2f} mm" if bend is not None else None
        if gap is not None or bend is not None:
            rows.append((stale.renamed_wire(w["name"], names), gap, bend))
    return rows


def standing_line(design):
    """The 3D check's sentence under a plain "Stable" (core/standing.words), or None when the check
    did not run or failed (then the box's limits say it)."""
    record = standing.checked(design)
    return standing.words(record) if record is not None and record.get("stands") else None


def deflection_note(design):
    """Whether the warnings need standing.DEFLECTION_NOTE: the 3D check ran and some wire loaded
    alone bends past the limit (the forces stage's warning for it is among the warnings)."""
    return standing.checked(design) is not None and any(
        isinstance(w.get("out_of_plane_deflection"), (int, float)) and w["out_of_plane_deflection"] > DEFLECTION_LIMIT
        for w in design.get("wires", []))


def torque_text(design):
    """"Torque fraction 0.412 (load factor 3: holds 3.00x its weight)", or None before the forces."""
    fraction = design.get("torque_fraction")
    if fraction is None or "stages" not in design or "forces" not in design["stages"]:
        return None
    text = f"Torque fraction {fraction:.3f}"
    factor = design.get("load_factor")
    if factor:
        reached = factor.get("reached")
        held = f"holds {reached:.2f}x its weight" if reached is not None else "holds any load"
        text += f" (load factor {factor['asked']:g}: {held})"
    return text


def assembly_rows(design, names=None):
    """One row per wire in assembly order: "1. Equator/0", "   + Meridian0/0" for a wire added in
    the same step, "(two hands)" after a step that adds two wires at once beyond the first pair.
    names: as wire_rows'."""
    steps = design.get("assembly_steps")
    if not steps:
        order = design.get("assembly_order") or []
        steps = [[w] for w in order]
    two_hands = set(design.get("two_hand_steps") or [])
    rows = []
    for k, step in enumerate(steps):
        wires = [stale.renamed_wire(design["wires"][w]["name"], names) for w in step]
        note = " (two hands)" if k in two_hands else ""
        rows.append(f"{k + 1}. {wires[0]}" + (note if len(wires) == 1 else ""))
        rows += [f"    + {name}" + (note if i == len(wires) - 2 else "") for i, name in enumerate(wires[1:])]
    return rows


_wrap = wrap_labels


# --- panels -------------------------------------------------------------------------------------

class _Child:
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "Wire"
    bl_parent_id = VIEW3D_PT_wiresculpt.__name__


class VIEW3D_PT_wiresculpt_settings(_Child, bpy.types.Panel):
    bl_label = "Material & Machine"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        ws = context.scene.wiresculpt
        layout.prop(ws, "material_preset")
        layout.prop(ws, "wire_diameter")
        if ws.material_preset == "CUSTOM":
            col = layout.column(align=True)
            for key in ("bending_stiffness", "max_torque", "friction", "density", "shear_modulus"):
                col.prop(ws, key)
        col = layout.column(align=True)
        col.prop(ws, "min_segment")
        col.prop(ws, "min_bend_deg")
        col.prop(ws, "max_bend_deg")
        col = layout.column(align=True)
        col.prop(ws, "contact_angle_deg")
        col.prop(ws, "use_load_factor")
        sub = col.column(align=True)
        sub.active = ws.use_load_factor
        sub.prop(ws, "load_factor")
        sub = col.column(align=True)
        sub.active = not ws.use_load_factor
        sub.prop(ws, "torque_fraction")
        box = layout.box()  # the layering's search knobs (docs/user-guide.md, Advanced)
        box.prop(ws, "show_advanced", icon='TRIA_DOWN' if ws.show_advanced else 'TRIA_RIGHT', emboss=False)
        if ws.show_advanced:
            for key in props.ADVANCED_PROPS:
                box.prop(ws, key)


class VIEW3D_PT_wiresculpt_optimize(_Child, bpy.types.Panel):
    bl_label = "Optimize"
    bl_options = {'HIDE_HEADER'}

    def draw(self, context):
        layout = self.layout
        job = optimize.JOB
        if job is None:
            row = layout.row()
            row.scale_y = 1.4
            row.enabled = native.available()
            row.operator(optimize.WIRESCULPT_OT_optimize.bl_idname, icon='PLAY')
            return
        box = layout.box()
        box.label(text=job.status().replace("wiresculpt: ", ""), icon='SORTTIME')
        for line in job.messages[-3:]:
            box.label(text=line)
        box.operator(optimize.WIRESCULPT_OT_optimize_cancel.bl_idname, icon='CANCEL')


class VIEW3D_PT_wiresculpt_report(_Child, bpy.types.Panel):
    bl_label = "Stability"

    @classmethod
    def poll(cls, context):
        return scene_results.stored_design() is not None

    def draw(self, context):
        layout = self.layout
        design = scene_results.stored_design()
        said, names = report(context)
        if said:  # the scene moved on: the design below is an earlier one's, greyed, and no green tick
            _wrap(layout, context, stale.stale_text(said), icon='TIME')
            layout = layout.column()
            layout.active = False
        box = layout.box()
        limits = design_limits(design) if design["stable"] else []
        if limits:  # stable and buildable, but not what a maker asked for: no green tick, the limits first
            box.alert = not said
            box.label(text=f"Was {OVER_LIMITS}" if said else OVER_LIMITS.capitalize(), icon='ERROR')
            for limit in limits:
                _wrap(box, context, stale.renamed_text(limit, design, names), icon='DOT')
        elif design["stable"]:
            if said:
                box.label(text="Was stable", icon='BLANK1')
            else:
                box.label(text="Stable", icon='CHECKMARK')
            line = standing_line(design)
            if line:
                _wrap(box, context, line[0].upper() + line[1:], icon='BLANK1')
        elif setup_problem(design):  # fewer than two wires: something to set up, as Live's "cannot solve"
            box.label(text="Could not solve" if said else "Cannot solve", icon='INFO')
            _wrap(box, context, design["reason"])
        else:
            box.alert = not said
            # max_nodes stopped the layering: a stable design may exist (the reason says how to go on)
            if design.get("search_incomplete"):
                box.label(text="Search was incomplete" if said else "Search incomplete", icon='ERROR')
            else:
                box.label(text="Was not stable" if said else "Not stable", icon='ERROR')
            _wrap(box, context, stale.renamed_text(design.get("reason"), design, names) or "no reason given")
        rows = assembly_rows(design, names)
        if rows:
            col = layout.column(align=True)
            col.label(text="Assembly order:")
            for row in rows:
                _wrap(col, context, row.strip(), icon='BLANK1' if row.startswith(" ") else 'FORWARD')
        distances = [w["target_max_distance"] for w in design["wires"] if "target_max_distance" in w]
        if distances:
            row = layout.row()
            row.label(text="Max deviation")  # the largest distance of a wire from its contour
            row.label(text=length_text(context.scene, max(distances)))
        torque = torque_text(design)
        if torque:
            _wrap(layout, context, torque)
        wires = wire_rows(design, names)
        if wires:
            # per wire: how far its rest shape's ends stand apart before assembly, and how far it
            # sags in the assembled sculpture (the 3D check), or bends out of its plane loaded alone
            col = layout.column(align=True)
            _wrap(col, context, standing.wire_heading(design))
            word = standing.sag_column(design)
            for name, gap, bend in wires:
                _wrap(col, context, f"{name}: gap {gap or '-'}, {word} {bend or '-'}", icon='DOT')
            if any(w.get("closed") and "closure_gap" in w for w in design["wires"]):
                layout.label(text="Cuts: drag a sphere", icon='INFO')
        capacity = load_capacity_rows(design)
        if capacity:
            col = layout.column(align=True)
            weight = sculpture_weight(design)
            col.label(text=f"Load capacity (weighs {mass_text(weight / GRAVITY * 1000)}):")
            for direction, grams in capacity:
                row = col.row()
                row.label(text=direction)
                row.label(text=mass_text(grams) if grams is not None else "no limit found")
        if design.get("mesh_closing"):  # an open or many-part mesh: what was done to slice it
            _wrap(layout, context, "Mesh: " + mesh_faults.closing_sentence(design["mesh_closing"]), icon='MOD_REMESH')
        pending = design.get("pending_stages") or []
        if pending:
            _wrap(layout, context, "Pending: " + ", ".join(p.replace("_", " ") for p in pending), icon='INFO')
        crossing = [stale.renamed_text(c["message"], design, names)
                    for c in (design.get("buildability") or {}).get("self_crossings", [])]
        if crossing:  # a rest shape that crosses itself: shown first, the maker must see it before bending
            col = layout.column(align=True)
            for message in crossing:
                _wrap(col, context, message, icon='ERROR')
        warnings = [stale.renamed_text(w, design, names) for w in design.get("warnings") or []]
        warnings = [w for w in warnings if w not in crossing]
        if warnings:
            col = layout.column(align=True)
            if deflection_note(design):
                _wrap(col, context, standing.DEFLECTION_NOTE[0].upper() + standing.DEFLECTION_NOTE[1:] + ":", icon='INFO')
            for warning in warnings[:3]:
                _wrap(col, context, warning, icon='ERROR')
            if len(warnings) > 3:
                col.label(text=f"… and {len(warnings) - 3} more (see the wiresculpt_design.json text)")


class VIEW3D_PT_wiresculpt_display(_Child, bpy.types.Panel):
    bl_label = "Result"

    @classmethod
    def poll(cls, context):
        return scene_results.stored_design() is not None

    def draw(self, context):
        layout = self.layout
        ws = context.scene.wiresculpt
        design = scene_results.stored_design()
        if any("force" in c for c in design.get("crossings", [])):
            layout.prop(ws, "show_forces")
        if as_built_view.has_as_built(design):
            row = layout.row(align=True)
            row.prop(ws, "show_as_built")
            sub = row.row(align=True)
            sub.active = ws.show_as_built
            sub.prop(ws, "as_built_scale")
        layout.prop(ws, "show_markers")
        steps = design.get("assembly_steps") or []
        if steps:
            layout.prop(ws, "assembly_step", slider=False)
            if ws.assembly_step:
                names = report(context)[1]
                shown = [stale.renamed_wire(design["wires"][w]["name"], names)
                         for s in steps[:ws.assembly_step] for w in s]
                _wrap(layout, context, "Shown: " + ", ".join(shown))
            col = layout.column(align=True)
            col.prop(ws, "guide_folder", text="")
            col.operator(WIRESCULPT_OT_assembly_guide.bl_idname, icon='HELP')
        layout.operator(WIRESCULPT_OT_clear_results.bl_idname, icon='TRASH')


_classes = (VIEW3D_PT_wiresculpt_settings, VIEW3D_PT_wiresculpt_optimize, VIEW3D_PT_wiresculpt_report,
            VIEW3D_PT_wiresculpt_display)
register, unregister = classes_factory(_classes)
