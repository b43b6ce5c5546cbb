"""The add-on's settings: one PropertyGroup on the scene, `scene.wiresculpt`.

Solver defaults and bounds are declared once, in core/settings.py and core/materials.py; the
properties below read them from there.
"""
import math

import bpy
from bpy.app.handlers import persistent
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty, IntProperty,
                       PointerProperty, StringProperty)

from . import native
from .blend import results as scene_results
from .blend.calibration import MATERIAL_NAME_KEY, config_folder
from .blend.handles import is_handle
from .blend.registration import classes_factory
from .blend import view
from .core import calibration as cal
from .core import materials, settings as settings_table
from .fab import streaming


def _poll_model(_settings, obj):
    return obj.type == 'MESH' and not is_handle(obj)


OLD_MODEL_KEY = "target"  # the name under which a .blend saved by an earlier version keeps the model


def adopt_old_model(scene):
    """A scene saved while the model's property was named `target`: its pointer (an IDProperty
    the PropertyGroup no longer declares) becomes `model`, once, and the old key goes away. A
    model already picked wins; an old pointer to something that is not a mesh is dropped."""
    settings = getattr(scene, "wiresculpt", None)
    if settings is None or OLD_MODEL_KEY not in settings.keys():
        return
    old = settings.get(OLD_MODEL_KEY)
    if settings.model is None and isinstance(old, bpy.types.Object) and _poll_model(settings, old):
        settings.model = old
    del settings[OLD_MODEL_KEY]


def adopt_old_models():
    """adopt_old_model for every scene of the open file."""
    for scene in bpy.data.scenes:
        adopt_old_model(scene)


@persistent
def _load_post(*_args):
    adopt_old_models()


def _adopt_after_register():
    try:
        adopt_old_models()
    except AttributeError:  # bpy.data is restricted while add-ons register at start-up
        pass
    return None  # a one-shot timer


# --- solver settings, from the one table ------------------------------------------------------

REFERENCE = materials.PRESETS["steel"]  # the custom material starts from steel's numbers


def _setting(key, name, **kw):
    """A property for core/settings.py's `key`: default, bounds and text from the table; a
    BoolProperty or IntProperty for the "bool" and "int" keys, else a FloatProperty. Degrees are
    stored as radians (subtype ANGLE) so Blender shows the user's unit."""
    default, low, high, unit, text = settings_table.SETTINGS[key]
    if unit == "bool":
        return BoolProperty(name=name, description=text, default=default, **kw)
    if unit == "int":
        return IntProperty(name=name, description=text, default=default, min=low, max=high, **kw)
    if unit == "deg":
        kw.update(subtype='ANGLE', default=math.radians(default), min=math.radians(low),
                  max=math.radians(high))
        text += " (degrees)"
    elif unit == "m":
        kw.update(subtype='DISTANCE', unit='LENGTH', default=default, min=low, max=high)
        text += " (metres)"
    else:  # no default in the table (chosen by the solver): the property starts at its maximum
        kw.update(default=high if default is None else default, min=low, max=high,
                  subtype='FACTOR' if high <= 1.0 else 'NONE')
    return FloatProperty(name=name, description=text, **kw)


def _material_field(key, name, text, **kw):
    unit, low, _high = materials.FIELDS[key]
    # FIELDS bounds are exclusive below: the smallest positive step stands in for "> 0"
    return FloatProperty(name=name, description=f"{text} ({unit})" if unit else text,
                         default=REFERENCE[key], min=max(low, 1e-9), max=materials.FIELDS[key][2], **kw)


_PRESET_ITEMS = [(key, key.capitalize(),
                  f"{key.capitalize()} wire: bending stiffness {p['bending_stiffness']} N m², "
                  f"plastic torque {p['max_torque']} N m, friction {p['friction']} at "
                  f"{p['wire_diameter'] * 1000:g} mm, scaled to the wire diameter")
                 for key, p in materials.PRESETS.items()]
_PRESET_ITEMS.append(("CUSTOM", "Custom", "Give the material's numbers yourself (for the wire "
                                          "diameter below)"))


def _f(value):
    """A property's float32 value as the number the user typed (7 significant digits)."""
    return float(f"{value:.7g}")


def material_of(settings):
    """The design's material dict from the panel: a preset scaled to the chosen wire diameter
    (bending stiffness ~ d^4, plastic torque ~ d^3 for a round wire), or the custom numbers."""
    d = _f(settings.wire_diameter)
    if settings.material_preset == "CUSTOM":
        # A calibrated or saved material's name (set by the Calibration panel), else "custom".
        name = str(settings.id_data.get(MATERIAL_NAME_KEY, "custom"))
        return {"name": name, "wire_diameter": d, "bending_stiffness": _f(settings.bending_stiffness),
                "max_torque": _f(settings.max_torque), "friction": _f(settings.friction),
                "density": _f(settings.density), "shear_modulus": _f(settings.shear_modulus)}
    out = dict(materials.PRESETS[settings.material_preset])
    ratio = d / out["wire_diameter"]
    out["bending_stiffness"] *= ratio ** 4
    out["max_torque"] *= ratio ** 3
    if ratio != 1.0:
        out["bending_stiffness"] = _f(out["bending_stiffness"])
        out["max_torque"] = _f(out["max_torque"])
    out["wire_diameter"] = d
    return out


def solver_settings(settings):
    """The pipeline's settings dict (core/settings.py keys, degrees where the table says so)."""
    out = settings_table.defaults()
    for key, (_default, _low, _high, unit, _text) in settings_table.SETTINGS.items():
        if key not in SETTING_PROPS:
            continue
        value = getattr(settings, key)
        if unit in ("bool", "int"):
            out[key] = bool(value) if unit == "bool" else int(value)
        else:
            out[key] = _f(math.degrees(value) if unit == "deg" else value)
    if settings.use_load_factor:  # the solver picks the least torque fraction that holds it
        out["torque_fraction"] = None
    if out["min_bend_deg"] >= out["max_bend_deg"]:
        raise ValueError("the smallest bend must be smaller than the largest bend (Machine settings)")
    return out


def solve_inputs(settings):
    """Every panel value material_of and solver_settings read, as they stand (not validated): what
    a Live solve depends on besides the planes and the model, compared at every tick."""
    return (tuple(getattr(settings, key) for key in SETTING_PROPS + MATERIAL_PROPS + ("use_load_factor",))
            + (str(settings.id_data.get(MATERIAL_NAME_KEY, "")),))


# the material's panel values (material_of)
MATERIAL_PROPS = ("material_preset", "wire_diameter", "bending_stiffness", "max_torque", "friction", "density",
                  "shear_modulus")
# core/settings.py keys shown in the panel (weld_tolerance stays automatic)
SETTING_PROPS = ("min_segment", "max_bend_deg", "min_bend_deg", "contact_angle_deg", "torque_fraction",
                 "load_factor", "in_plane_tiebreak", "max_nodes", "relayer_rounds")
ADVANCED_PROPS = ("in_plane_tiebreak", "max_nodes", "relayer_rounds")  # the panel's Advanced box


LIVE_HOOKS = []  # live/engine.py's live_changed (props may not import live)


def _live_changed(settings, context):
    for hook in LIVE_HOOKS:
        hook(settings, context)


def _assembly_step_changed(settings, context):
    scene_results.apply_assembly_step(context.scene)


def _redraw_views(_settings, context):
    """A display toggle changed: the overlay draws it at the 3D views' next redraw."""
    try:
        view.redraw_3d_views()
    except (AttributeError, ReferenceError):  # no window (background)
        pass


def _port_suggestions(_settings, _context, _text):
    """Serial ports libserialport lists, offered while typing the port (any path may be typed:
    a pseudo-terminal, a udev symlink)."""
    if not native.available():
        return []
    return [p["name"] for p in native.list_ports()]


NO_WIRE = "__none__"  # the wire enum's only item when the design has no wire with a rest shape


def _wire_items(_settings, _context):
    """The stored design's wires that have a rest shape; the enum's number is the wire's id."""
    wires = streaming.rest_wires(scene_results.stored_design())
    items = [(w["name"], w["name"], f"Wire {w['name']} (id {w['id']}, {w.get('length', 0) * 1000:.0f} mm)", w["id"])
             for w in wires] or [(NO_WIRE, "(no wire with a rest shape)", "Optimize first", 0)]
    _wire_items.cache = items  # Blender needs the strings kept alive
    return items


class WiresculptContour(bpy.types.PropertyGroup):
    plane: StringProperty(
        name="Plane", description="Name of the slicing plane that cut this contour, at the Slice "
                                  "that made it (the plane's current name is plane_object's), or its "
                                  "last name once it is deleted")
    plane_object: PointerProperty(
        name="Plane Object", type=bpy.types.Object,
        description="Slicing plane that cut this contour: the tick follows this object through "
                    "renames; None once that object is deleted")
    has_plane_object: BoolProperty(
        name="Has Plane Object", default=False, options={'HIDDEN'},
        description="Plane Object was set by the Slice that made this contour; False on contours "
                    "saved before it existed, which go by the Plane name instead")
    index: IntProperty(
        name="Index", min=0,
        description="Position of this contour among its plane's contours, longest first (0)")
    length: FloatProperty(
        name="Length", unit='LENGTH', subtype='DISTANCE', min=0.0,
        description="Length of the contour in world space, closing edge included")
    closed: BoolProperty(
        name="Closed", description="The contour is a closed loop (open where the mesh has a hole)")
    use: BoolProperty(
        name="Use as wire", default=False,
        description="Make this contour one of the sculpture's wires")
    curve: PointerProperty(
        name="Curve", type=bpy.types.Object,
        description="Curve object that shows this contour in the viewport")


class WiresculptSettings(bpy.types.PropertyGroup):
    model: PointerProperty(
        name="Model", type=bpy.types.Object, poll=_poll_model,
        description="Mesh to turn into a wire sculpture (evaluated: modifiers and transform "
                    "applied)")
    contours: CollectionProperty(
        name="Contours", type=WiresculptContour,
        description="Contours cut by the slicing planes at the last Slice")
    active_contour: IntProperty(
        name="Active Contour", min=0, default=0,
        description="Contour highlighted in the list")

    # material and wire
    material_preset: EnumProperty(
        name="Material", items=_PRESET_ITEMS, default=next(iter(materials.PRESETS)),
        description="Wire material: a preset from the paper's Table 1, or your own numbers")
    wire_diameter: FloatProperty(
        name="Wire Diameter", subtype='DISTANCE', unit='LENGTH', default=REFERENCE["wire_diameter"],
        min=1e-4, max=materials.FIELDS["wire_diameter"][2], precision=4,
        description="Diameter of the round wire (metres); presets scale their stiffness and "
                    "torque to it, and the wire curves get it as thickness")
    bending_stiffness: _material_field(
        "bending_stiffness", "Bending Stiffness", "Custom material: bending stiffness k_b = E I")
    max_torque: _material_field(
        "max_torque", "Plastic Torque", "Custom material: torque at which the wire yields")
    friction: _material_field(
        "friction", "Friction", "Custom material: friction coefficient between two wires")
    density: _material_field(
        "density", "Density", "Custom material: density, for the sculpture's weight")
    shear_modulus: _material_field(
        "shear_modulus", "Shear Modulus",
        "Custom material: shear modulus G, for the wire's twist in the out-of-plane deflection check")

    # machine and solver (core/settings.py)
    min_segment: _setting("min_segment", "Min Segment", precision=4)
    max_bend_deg: _setting("max_bend_deg", "Max Bend")
    min_bend_deg: _setting("min_bend_deg", "Min Bend")
    contact_angle_deg: _setting("contact_angle_deg", "Contact Angle")
    torque_fraction: _setting("torque_fraction", "Torque Fraction")
    load_factor: _setting("load_factor", "Load Factor", precision=1)
    use_load_factor: BoolProperty(
        name="Torque from Load Factor", default=True,
        description="Use the least torque fraction (pre-stress) whose sculpture holds the load "
                    "factor times its weight in each of the six directions; off: the torque "
                    "fraction as set")
    in_plane_tiebreak: _setting("in_plane_tiebreak", "In-Plane Tie-Break")
    max_nodes: _setting("max_nodes", "Max Search Nodes")
    relayer_rounds: _setting("relayer_rounds", "Re-Layering Rounds")
    # Suggest Planes' count (the search's plane_count); not a solver setting: a solve never reads it
    plane_count: _setting("plane_count", "Planes")
    show_advanced: BoolProperty(
        name="Advanced", default=False,
        description="Show the layering's search settings (tie-break, node budget, re-layering rounds)")

    live: BoolProperty(
        name="Live", default=False, update=_live_changed,
        description="While a slicing plane or the model moves, re-slice and re-solve in the background "
                    "and show stable / not stable (the layering's own hooks only; Optimize may pick "
                    "others). Refused for meshes over 100,000 triangles, counted with their modifiers")

    # results display
    show_forces: BoolProperty(
        name="Show Forces", default=True,
        description="Draw the contact force at every crossing as an arrow in the viewport "
                    "(when the design has forces)")
    show_markers: BoolProperty(
        name="Crossing Markers", default=True,
        description="Show the crossing markers (green: hooked, grey: null, magenta: slips in the 3D check)",
        update=_assembly_step_changed)
    show_as_built: BoolProperty(
        name="Show As Built", default=False,
        description="Draw each wire as the 3D check finds it standing (its as-built shape), coloured by "
                    "each point's distance from the target, and mark the crossings that slip",
        update=_redraw_views)
    as_built_scale: FloatProperty(
        name="Exaggerate", default=1.0, min=1.0, soft_max=100.0, max=10000.0,
        description="Draw the as-built shape's change from the target this many times larger "
                    "(1: as it is); the colours keep the true distances",
        update=_redraw_views)
    assembly_step: IntProperty(
        name="Show After Step", default=0, min=0, soft_max=50,
        description="Show only the wires added up to this assembly step (0: the whole sculpture)",
        update=_assembly_step_changed)
    guide_folder: StringProperty(
        name="Guide Folder", subtype='DIR_PATH', default="//assembly",
        description="Folder the assembly guide (index.html and one picture per step) is written to")

    # fabrication (docs/user-guide.md, Fabrication)
    machine_profile: StringProperty(
        name="Machine Profile", subtype='FILE_PATH', default="",
        description="Machine profile JSON saved by Calibration > Save Machine Profile (spring-back fit, "
                    "axes, serial settings); empty: the default DIWire-class profile")
    fab_port: StringProperty(
        name="Port", default="", search=_port_suggestions,
        description="Serial port of the bender: pick a listed port or type a path (e.g. /dev/ttyUSB0)")
    fab_wire: EnumProperty(
        name="Wire", items=_wire_items,
        description="Wire whose bend program is sent to the machine")
    fab_dry_run: BoolProperty(
        name="Dry Run", default=False,
        description="Only check the program against the machine profile; nothing is sent")
    # the Machine panel (docs/user-guide.md, Machine)
    machine_jog_feed: FloatProperty(
        name="Feed Step", default=10.0, min=0.01, max=1000.0, precision=2,
        description="How far one feed jog moves the wire (millimetres)")
    machine_jog_bend: FloatProperty(
        name="Bend Step", default=5.0, min=0.01, max=180.0, precision=2,
        description="How far one bend jog turns the head (degrees, left positive)")
    machine_console: StringProperty(
        name="Line", default="",
        description="One line for GRBL ($$, $G, G-code; ?, ! or ~ alone go as realtime commands)")


# --- calibration (Calibration panel) ------------------------------------------------------------

KINDS = (("CANTILEVER", "Cantilever", "Bending stiffness and plastic limit (load_g, state, s_m, deflection_m)"),
         ("TILT", "Tilt", "Friction coefficient (repeat, angle_deg)"),
         ("SPRINGBACK", "Spring-back", "Machine spring-back line (commanded_deg, measured_deg)"))


def material_items(_self, _context):
    try:
        found, _errors = cal.list_materials(config_folder())
    except OSError:
        found = dict(materials.PRESETS)
    items = []
    for name, m in found.items():
        kind = "preset (Table 1)" if name in materials.PRESETS else "calibrated"
        items.append((name, name, f"{name}, {kind}: k_b {m['bending_stiffness']:.4g} N m², plastic torque "
                                  f"{m['max_torque']:.4g} N m, friction {m['friction']:.3g}"))
    material_items.cache = items  # Blender needs the strings kept alive
    return items


class WiresculptSpringbackRow(bpy.types.PropertyGroup):
    """One bend of the test piece: the angle commanded and the angle measured on the bent wire."""
    commanded_deg: FloatProperty(name="Commanded", default=0.0, min=-180.0, max=180.0, precision=2,
                                 description="The bend angle the test program commanded (degrees)")
    measured_deg: FloatProperty(name="Measured", default=0.0, min=-180.0, max=180.0, precision=2,
                                description="The angle measured on the bent test piece (degrees; 0: not yet)")


class WiresculptCalibrationSettings(bpy.types.PropertyGroup):
    overhang: FloatProperty(
        name="Overhang", subtype='DISTANCE', unit='LENGTH', default=0.30, min=0.02, max=2.0, precision=3,
        description="Free length of the cantilever from the clamp's edge to the load (metres; paper: 30 cm)")
    include_weight: BoolProperty(
        name="Wire's Own Weight", default=True,
        description="Add the wire's weight (density and diameter of the material below) to the external "
                    "torques of the cantilever fit")
    plastic_tolerance: FloatProperty(
        name="Return Tolerance", subtype='DISTANCE', unit='LENGTH', default=0.001, min=1e-5, max=0.05,
        precision=4,
        description="An unloaded wire has returned unless its smoothed shape is farther than this from the "
                    "initial one by more than the marks' reading noise can explain (metres)")
    material_name: StringProperty(
        name="Name", default="calibrated steel",
        description="Name of the calibrated material (saved as JSON in the user's config folder)")
    plot: EnumProperty(name="Plot", items=KINDS, default="CANTILEVER", description="Which fit the panel shows")
    springback_rows: CollectionProperty(type=WiresculptSpringbackRow)




_register_classes, _unregister_classes = classes_factory(
    (WiresculptContour, WiresculptSettings, WiresculptSpringbackRow, WiresculptCalibrationSettings),
    scene_properties=(("wiresculpt", WiresculptSettings, "Wire Sculpture",
                       "Settings and results of the wiresculpt add-on"),
                      ("wiresculpt_calibration", WiresculptCalibrationSettings, "Calibration",
                       "Settings of the calibration captures")))


def register():
    _register_classes()
    bpy.app.handlers.load_post.append(_load_post)
    try:
        adopt_old_models()  # the add-on enabled in a file that is already open
    except AttributeError:  # bpy.data is restricted while add-ons register at start-up: a moment later
        bpy.app.timers.register(_adopt_after_register, first_interval=0.0)


def unregister():
    if _load_post in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_load_post)
    _unregister_classes()
