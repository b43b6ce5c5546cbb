"""The design document written into the scene: one curve per wire (real thickness, interlocked at
its crossings), a marker per crossing, and the document itself as a Text datablock so it is saved
inside the .blend and read back on reopening.

Objects are matched by custom properties, so a new Optimize updates the same objects in place.
"""
import json

import bmesh
import bpy
import numpy as np

from ..core import assembly_view, stale
from ..core.design import crossing_direction, dumps
from . import cut_handles, preview
from .handles import contour_plane_name, contour_planes, handle_id, handle_plane, is_handle
from .objects import remove_object, scene_collection, tagged, write_polyline

DESIGN_TEXT = "wiresculpt_design.json"  # Text datablock holding the last design
# custom property of that Text: JSON of what Optimize solved it with besides the design's own keys
# ({"target": name, "settings": solver settings, "material": material, "planes": {plane name:
# persistent id, handles.plane_ids}}; core/stale.py compares it with the panel and finds renamed
# planes by it). Kept beside the design, not in it, so design.json stays as docs/formats.md says.
INPUTS_KEY = "wiresculpt_inputs"
WIRE_KEY = "wiresculpt_wire"  # custom property on wire curves: the wire's name
WIRE_ID_KEY = "wiresculpt_wire_id"  # custom property on wire curves: the wire's id this run
CROSSING_KEY = "wiresculpt_crossing"  # custom property on crossing markers: the crossing's id
WIRES_COLLECTION = "Wires"
CROSSINGS_COLLECTION = "Crossings"
MARKER_MESH = "wiresculpt marker"
MARKER_SIZE = 2.0  # marker radius in wire radii: a bead wider than the wire
BUMP_REACH = 4.0  # the interlock offset fades out over this many wire diameters along the wire

# Colour per wire id (RGBA, linear): distinct, readable on a white page and a grey viewport.
PALETTE = [
    (0.80, 0.22, 0.10), (0.10, 0.36, 0.80), (0.15, 0.60, 0.20), (0.85, 0.60, 0.05),
    (0.55, 0.20, 0.70), (0.05, 0.62, 0.65), (0.75, 0.15, 0.45), (0.45, 0.40, 0.30),
]
# a hooked crossing the 3D check finds slipping (`admissible` false): magenta, as the as-built ghosts' mark
MARKER_COLOURS = {"hooked": (0.1, 0.85, 0.2, 1.0), "null": (0.55, 0.55, 0.55, 1.0), "slips": (1.0, 0.0, 1.0, 1.0)}


def wire_colour(wire_id):
    return PALETTE[wire_id % len(PALETTE)] + (1.0,)


def colour_hex(wire_id):
    """The wire's colour as CSS #rrggbb (sRGB), for the assembly guide."""
    def srgb(c):
        return 12.92 * c if c <= 0.0031308 else 1.055 * c ** (1 / 2.4) - 0.055
    return "#" + "".join(f"{round(255 * srgb(c)):02x}" for c in PALETTE[wire_id % len(PALETTE)])


# --- the stored design ------------------------------------------------------------------------

_cache = {"text": None, "design": None}


def store_design(design):
    """Writes the design into the Text datablock (created when missing)."""
    text = bpy.data.texts.get(DESIGN_TEXT) or bpy.data.texts.new(DESIGN_TEXT)
    text.from_string(dumps(design))
    return text


def store_inputs(inputs):
    """Records `inputs` (a JSON-able dict, or None: unknown) beside the stored design."""
    text = bpy.data.texts.get(DESIGN_TEXT)
    if text is None:
        return
    if inputs is None:
        if INPUTS_KEY in text:
            del text[INPUTS_KEY]
    else:
        text[INPUTS_KEY] = json.dumps(inputs)


def stored_inputs():
    """What the stored design was solved with (store_inputs), or None when not recorded."""
    text = bpy.data.texts.get(DESIGN_TEXT)
    string = text.get(INPUTS_KEY) if text is not None else None
    if not isinstance(string, str):
        return None
    try:
        inputs = json.loads(string)
    except ValueError:
        return None
    return inputs if isinstance(inputs, dict) else None


def scene_planes(scene, depsgraph, names, ids=None):
    """({plane name now: (origin, unit normal), or None when it has no normal}, {(plane name,
    contour index)} ticked, {recorded plane name: its name now, or None when gone}): the scene's
    side of core/stale.changes. `names`: the design's plane names; `ids`: the persistent ids
    Optimize recorded for them (stored_inputs()["planes"]; None: by name), which find a renamed
    plane (core/stale.current_names) among the contour list's planes and those of a recorded
    name. By those lookups, not a pass over every object of the scene: a panel draws this at
    every redraw."""
    # a ticked contour's plane by its current name (items follow their plane object)
    ticked = {(contour_plane_name(item), item.index) for item in scene.wiresculpt.contours if item.use}
    found = contour_planes(scene)
    for name in names:
        handle = None if name in found else scene.objects.get(name)
        if handle is not None and is_handle(handle):
            found[name] = handle
    current = stale.current_names(names, ids, {name: handle_id(h) for name, h in found.items()})
    planes = {}
    for name in {n for n in current.values() if n is not None} | {p for p, _i in ticked}:
        handle = found.get(name) or scene.objects.get(name)
        if handle is None or not is_handle(handle):
            continue
        try:
            planes[name] = handle_plane(handle, depsgraph)[1:]
        except ValueError:
            planes[name] = None
    return planes, ticked, current


def stored_design():
    """The design saved in this .blend, or None (no Optimize yet, or the text was edited into
    something that is not a design)."""
    text = bpy.data.texts.get(DESIGN_TEXT)
    if text is None:
        return None
    string = text.as_string()
    if string != _cache["text"]:
        try:
            design = json.loads(string)
            if not isinstance(design, dict) or design.get("format") != "wiresculpt-design":
                design = None
        except ValueError:
            design = None
        _cache.update(text=string, design=design)
    return _cache["design"]


# --- geometry ---------------------------------------------------------------------------------

def polyline_segments(points, closed):
    """(2k, 3) float32 end points of the segments of a polyline (closed: the last back to the
    first), as the overlays draw lines."""
    points = np.asarray(points, dtype=np.float32).reshape(-1, 3)
    if len(points) < 2:
        return np.empty((0, 3), dtype=np.float32)
    ends = np.concatenate([points[1:], points[:1]]) if closed else points[1:]
    return np.stack([points[:len(ends)], ends], axis=1).reshape(-1, 3)


def wire_points(wire):
    """The wire's shape to show: the optimized target, or the contour when it was not computed."""
    return np.asarray(wire.get("target") or wire["contour"], dtype=np.float64)


def crossing_vertex(wire, crossing, k):
    """Index of crossing's point in wire_points(wire) (k: 0 or 1, the wire's place in it)."""
    if wire.get("target") and crossing.get("vertices") and crossing["vertices"][k] is not None:
        return crossing["vertices"][k]
    return crossing["contour_vertices"][k]


def side_of(crossing, k):
    """Which way wire k (0 or 1) of the crossing is pushed, in units of d: with hook = +1 the kink of
    wires[0] opens towards +d, so wires[0] lies on the -d side and wires[1] on the +d side."""
    hook = crossing.get("hook", 0)
    return -hook if k == 0 else hook


def bumped_polyline(points, closed, bumps, reach):
    """`points` with each vertex i of `bumps` {i: offset vector} moved by its offset, and points
    added at distance `reach` on its two edges so the offset stays local around the crossing."""
    n = len(points)
    edges = n if closed else n - 1
    out = []
    for i in range(n):
        out.append(points[i] + bumps.get(i, 0.0))
        if i >= edges:
            continue
        j = (i + 1) % n
        a, b = points[i], points[j]
        length = float(np.linalg.norm(b - a))
        ts = set()
        if length > 2 * reach:
            if i in bumps:
                ts.add(reach / length)
            if j in bumps:
                ts.add(1 - reach / length)
        for t in sorted(ts):
            out.append(a + (b - a) * t)
    return np.asarray(out)


def wire_shapes(design):
    """{wire id: (n, 3) points} of every wire with the interlock offsets applied."""
    diameter = design["material"]["wire_diameter"]
    bumps = {w["id"]: {} for w in design["wires"]}
    for c in design.get("crossings", []):
        if not c.get("hook"):
            continue
        d = crossing_direction(design, c)
        for k in (0, 1):
            wire = design["wires"][c["wires"][k]]
            bumps[wire["id"]][crossing_vertex(wire, c, k)] = side_of(c, k) * 0.5 * diameter * d
    return {w["id"]: bumped_polyline(wire_points(w), w["closed"], bumps[w["id"]], BUMP_REACH * diameter)
            for w in design["wires"]}


# --- scene objects ----------------------------------------------------------------------------

def _material(name, colour):
    mat = bpy.data.materials.get(name) or bpy.data.materials.new(name)
    mat.diffuse_color = colour
    mat.metallic = 0.3
    mat.roughness = 0.35
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes.get("Principled BSDF")
    if bsdf is not None:
        bsdf.inputs["Base Color"].default_value = colour
        bsdf.inputs["Metallic"].default_value = 0.3
        bsdf.inputs["Roughness"].default_value = 0.35
    return mat


def _marker_mesh():
    mesh = bpy.data.meshes.get(MARKER_MESH)
    if mesh is None:
        mesh = bpy.data.meshes.new(MARKER_MESH)
        bm = bmesh.new()
        bmesh.ops.create_uvsphere(bm, u_segments=12, v_segments=8, radius=1.0)
        bm.to_mesh(mesh)
        bm.free()
        mesh.materials.append(None)
    return mesh


def write_results(scene, design, inputs=None):
    """Makes the scene show `design`: wire curves in "Wires", markers in "Crossings", the Text
    datablock with `inputs` (store_inputs: what it was solved with; None: not known). Returns
    (wires written, wire objects removed)."""
    store_design(design)
    store_inputs(inputs)
    preview.clear_ghosts(scene)  # they showed the programs of the design before this one
    radius = 0.5 * design["material"]["wire_diameter"]
    existing = tagged(scene, WIRE_KEY)
    shapes = wire_shapes(design)
    wires_coll = scene_collection(scene, WIRES_COLLECTION)
    for wire in design["wires"]:
        obj = existing.pop(wire["name"], None)
        if obj is None or obj.type != 'CURVE':
            name = f"Wire {wire['name']}"
            curve = bpy.data.curves.new(name, 'CURVE')
            curve.dimensions = '3D'
            obj = bpy.data.objects.new(name, curve)
            obj[WIRE_KEY] = wire["name"]
            wires_coll.objects.link(obj)
        obj[WIRE_ID_KEY] = wire["id"]
        curve = obj.data
        write_polyline(curve, shapes[wire["id"]], wire["closed"])
        curve.bevel_mode = 'ROUND'
        curve.bevel_depth = radius
        curve.bevel_resolution = 3
        curve.use_fill_caps = True
        obj.matrix_world = ((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1))
        mat = _material(f"Wire {wire['name']}", wire_colour(wire["id"]))
        if curve.materials:
            curve.materials[0] = mat
        else:
            curve.materials.append(mat)
        obj.color = wire_colour(wire["id"])
    for obj in existing.values():
        remove_object(obj)

    markers = tagged(scene, CROSSING_KEY)
    crossings_coll = scene_collection(scene, CROSSINGS_COLLECTION)
    mesh = _marker_mesh()
    hooked = _material("wiresculpt crossing hooked", MARKER_COLOURS["hooked"])
    null = _material("wiresculpt crossing null", MARKER_COLOURS["null"])
    slips = _material("wiresculpt crossing slips", MARKER_COLOURS["slips"])
    for c in design.get("crossings", []):
        obj = markers.pop(c["id"], None)
        if obj is None:
            name = f"Crossing {c['id']}"
            obj = bpy.data.objects.new(name, mesh)
            obj[CROSSING_KEY] = c["id"]
            crossings_coll.objects.link(obj)
        obj.material_slots[0].link = 'OBJECT'
        obj.material_slots[0].material = (slips if c.get("admissible") is False else hooked if c.get("hook")
                                          else null)
        obj.location = c["point"]
        obj.scale = (MARKER_SIZE * radius,) * 3
        obj.hide_render = True
        obj["wiresculpt_wires"] = list(c["wires"])
        obj["wiresculpt_hook"] = int(c.get("hook", 0))
    for obj in markers.values():
        bpy.data.objects.remove(obj, do_unlink=True)
    cut_handles.write(scene, design)
    settings = scene.wiresculpt
    steps = design.get("assembly_steps") or []
    if settings.assembly_step > len(steps):
        settings.assembly_step = 0  # its update calls apply_assembly_step
    apply_assembly_step(scene)
    return len(design["wires"]), len(existing)


def visible_wires(design, step):
    """Ids of the wires present after assembly step `step` (1-based; 0 or no order: all)."""
    return assembly_view.visible([w["id"] for w in design["wires"]], design.get("assembly_steps") or [], step)


def apply_assembly_step(scene):
    """Hides the wires not yet added at scene.wiresculpt.assembly_step, and the markers of their
    crossings (and every marker when markers are switched off)."""
    design = stored_design()
    if design is None:
        return
    settings = scene.wiresculpt
    shown = visible_wires(design, settings.assembly_step)
    for obj in tagged(scene, WIRE_KEY).values():
        hidden = obj.get(WIRE_ID_KEY) not in shown
        obj.hide_viewport = hidden
        obj.hide_render = hidden
    for obj in tagged(scene, CROSSING_KEY).values():
        wires = list(obj.get("wiresculpt_wires", []))
        obj.hide_viewport = not (settings.show_markers and all(w in shown for w in wires))
    ids = {w["name"]: w["id"] for w in design["wires"]}
    for name, obj in tagged(scene, cut_handles.CUT_KEY).items():
        obj.hide_viewport = ids.get(name) not in shown
    for name, obj in tagged(scene, preview.PREVIEW_KEY).items():  # the machine preview's ghosts
        obj.hide_viewport = ids.get(name) not in shown


def clear_results(scene):
    """Removes the wire curves, markers, machine-preview ghosts and stored design."""
    preview.clear_ghosts(scene)
    for obj in tagged(scene, WIRE_KEY).values():
        remove_object(obj)
    for obj in tagged(scene, CROSSING_KEY).values():
        bpy.data.objects.remove(obj, do_unlink=True)
    cut_handles.remove(scene)
    text = bpy.data.texts.get(DESIGN_TEXT)
    if text is not None:
        bpy.data.texts.remove(text)
