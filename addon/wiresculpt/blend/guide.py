"""The assembly guide: a printable HTML page, one picture per assembly step rendered by Blender's
Workbench engine, the wire(s) to add and, at each new crossing, which wire passes on which side.

The words are pure functions of the design (crossing_sentence, step_text); rendering borrows the
scene for a moment and puts every setting it touched back. Files are written atomically.
"""
import html
import math
import os
import tempfile

import bpy
import numpy as np
from mathutils import Vector

from ..core import closure, sizes
from ..core.design import crossing_direction
from ..core.files import write_atomic
from ..core.limits import OVER_LIMITS, broken_limits, recorded_stock
from . import results
from .objects import tagged

RESOLUTION = (480, 360)
VIEW_DIRECTION = (1.0, -1.25, 0.9)  # from the sculpture's centre towards the camera
LENS_ANGLE = math.radians(35.0)
BACKGROUND = (1.0, 1.0, 1.0)
GUIDE_MARKER_SCALE = 2.5  # crossing beads in the pictures, larger than in the viewport
AXES = "xyz"


# --- words ----------------------------------------------------------------------------------

def direction_words(d):
    """(name of +d, name of -d) for a direction: "+z"/"-z" when it is close to an axis."""
    d = np.asarray(d, dtype=np.float64)
    k = int(np.argmax(np.abs(d)))
    if abs(d[k]) > 0.9:
        sign = 1 if d[k] > 0 else -1
        return (f"{'+' if sign > 0 else '-'}{AXES[k]}", f"{'-' if sign > 0 else '+'}{AXES[k]}")
    text = "(" + ", ".join(f"{x:+.2f}" for x in d) + ")"
    return text, "-" + text


def crossing_sentence(design, crossing, centre=None):
    """e.g. "at crossing 3 (x 0, y -125, z 0 mm), Equator/0 passes below Meridian0/0 (on its -z
    side) and hooks around it". With the sculpture's `centre`, a side that points at or away from
    it is said as inside / outside."""
    a, b = (design["wires"][w]["name"] for w in crossing["wires"])
    mm = [round(1000 * x) or 0 for x in crossing["point"]]  # `or 0`: no "-0"
    where = ", ".join(f"{AXES[k]} {mm[k]}" for k in range(3))
    head = f"at crossing {crossing['id']} ({where} mm)"
    hook = crossing.get("hook", 0)
    if not hook:
        return f"{head}, {a} and {b} only touch: no hook, either wire may lie on top"
    d = crossing_direction(design, crossing)
    side = results.side_of(crossing, 0)  # where wires[0] lies, in units of d
    push = d if side > 0 else -d  # the way wires[0] is pushed
    plus, minus = direction_words(push)
    if centre is not None:
        radial = np.asarray(crossing["point"], dtype=np.float64) - np.asarray(centre, dtype=np.float64)
        if np.linalg.norm(radial) > 0 and abs(push @ radial) > 0.8 * np.linalg.norm(radial):
            where_to = "outside" if push @ radial > 0 else "inside"
            return f"{head}, {a} passes {where_to} {b} (on its {plus} side) and hooks around it"
    if plus in ("+z", "-z"):
        verb = "above" if plus == "+z" else "below"
        return f"{head}, {a} passes {verb} {b} (on its {plus} side) and hooks around it"
    return f"{head}, {a} passes on the {plus} side of {b}, {b} on the {minus} side of {a}; they hook"


def step_crossings(design, step):
    """Crossings that close at assembly step `step` (0-based): both wires present, one new."""
    steps = design.get("assembly_steps") or []
    before = {w for s in steps[:step] for w in s}
    new = set(steps[step])
    return [c for c in design.get("crossings", [])
            if set(c["wires"]) <= before | new and set(c["wires"]) & new]


def step_text(design, step):
    """(title, [sentences]) of assembly step `step` (0-based)."""
    steps = design["assembly_steps"]
    names = [design["wires"][w]["name"] for w in steps[step]]
    two_hands = step in (design.get("two_hand_steps") or [])
    if step == 0:
        title = f"Step 1: hold {' and '.join(names)} together"
    elif two_hands:
        title = f"Step {step + 1}: add {' and '.join(names)} at once (two hands)"
    else:
        title = f"Step {step + 1}: add {', '.join(names)}"
    centre, _radius = sculpture_bounds(design)
    return title, [crossing_sentence(design, c, centre) for c in step_crossings(design, step)]


# --- pictures -------------------------------------------------------------------------------

def sculpture_bounds(design):
    points = np.concatenate([results.wire_points(w) for w in design["wires"]])
    low, high = points.min(axis=0), points.max(axis=0)
    centre = 0.5 * (low + high)
    radius = float(np.max(np.linalg.norm(points - centre, axis=1))) + design["material"]["wire_diameter"]
    return centre, radius


class _Borrowed:
    """Scene render settings, the camera and object visibility, put back on exit."""

    def __init__(self, scene):
        self.scene = scene

    def __enter__(self):
        s, r = self.scene, self.scene.render
        sh = s.display.shading
        self.saved = [(r, "engine", r.engine), (r, "resolution_x", r.resolution_x),
                      (r, "resolution_y", r.resolution_y),
                      (r, "resolution_percentage", r.resolution_percentage),
                      (r, "film_transparent", r.film_transparent), (s, "camera", s.camera),
                      (sh, "light", sh.light), (sh, "color_type", sh.color_type),
                      (sh, "show_cavity", sh.show_cavity),
                      (s.view_settings, "view_transform", s.view_settings.view_transform),
                      (s.view_settings, "look", s.view_settings.look),
                      (s.wiresculpt, "assembly_step", s.wiresculpt.assembly_step)]
        self.hidden = [(o, o.hide_render) for o in s.objects]
        self.scales = [(o, tuple(o.scale)) for o in tagged(s, results.CROSSING_KEY).values()]
        self.world = s.world
        self.temp_world = None
        if s.world is None:
            self.temp_world = s.world = bpy.data.worlds.new("wiresculpt guide")
        self.world_colour = tuple(s.world.color)
        s.world.color = BACKGROUND
        cam_data = bpy.data.cameras.new("wiresculpt guide camera")
        self.camera = bpy.data.objects.new("wiresculpt guide camera", cam_data)
        s.collection.objects.link(self.camera)
        return self

    def __exit__(self, *_exc):
        s = self.scene
        for owner, attr, value in self.saved:
            setattr(owner, attr, value)
        for obj, hide in self.hidden:
            obj.hide_render = hide
        for obj, scale in self.scales:
            obj.scale = scale
        s.world.color = self.world_colour
        s.world = self.world
        if self.temp_world is not None:
            bpy.data.worlds.remove(self.temp_world)
        data = self.camera.data
        bpy.data.objects.remove(self.camera, do_unlink=True)
        bpy.data.cameras.remove(data)
        results.apply_assembly_step(s)
        return False


def _frame(camera, design):
    centre, radius = sculpture_bounds(design)
    camera.data.lens_unit = 'FOV'
    camera.data.angle = LENS_ANGLE
    r = camera.data  # AUTO sensor fit: the angle is the wider (horizontal) one; fit the height
    vertical = 2 * math.atan(math.tan(LENS_ANGLE / 2) * RESOLUTION[1] / RESOLUTION[0])
    distance = 1.08 * radius / math.sin(vertical / 2)
    direction = Vector(VIEW_DIRECTION).normalized()
    camera.location = Vector(centre) + distance * direction
    camera.rotation_euler = (-direction).to_track_quat('-Z', 'Y').to_euler()
    r.clip_start = max(distance - 2 * radius, distance * 1e-3)
    r.clip_end = distance + 2 * radius


def _render_to(scene, path):
    """Renders the scene's camera and writes a PNG to `path` atomically."""
    scene.render.image_settings.file_format = 'PNG'
    bpy.ops.render.render()
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=".png", dir=folder)
    os.close(fd)
    try:
        bpy.data.images["Render Result"].save_render(tmp, scene=scene)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def render_pictures(scene, design, jobs, resolution=RESOLUTION):
    """Renders with Workbench: `jobs` is [(assembly step shown (0: all), path, marker crossing ids)]."""
    wire_objects = tagged(scene, results.WIRE_KEY)
    markers = tagged(scene, results.CROSSING_KEY)
    with _Borrowed(scene) as borrowed:
        r = scene.render
        r.engine = 'BLENDER_WORKBENCH'
        r.resolution_x, r.resolution_y = resolution
        r.resolution_percentage = 100
        r.film_transparent = False
        shading = scene.display.shading
        shading.light = 'STUDIO'
        shading.color_type = 'MATERIAL'
        shading.show_cavity = True
        scene.view_settings.view_transform = 'Standard'  # white stays white on the printed page
        scene.view_settings.look = 'None'
        for obj in markers.values():
            obj.scale = tuple(GUIDE_MARKER_SCALE * x for x in obj.scale)
        _frame(borrowed.camera, design)
        scene.camera = borrowed.camera
        ours = set(wire_objects.values()) | set(markers.values()) | {borrowed.camera}
        for obj in scene.objects:
            if obj not in ours:
                obj.hide_render = True
        for step, path, crossing_ids in jobs:
            scene.wiresculpt.assembly_step = step  # hides the wires not yet added
            for cid, obj in markers.items():
                obj.hide_render = cid not in crossing_ids
            _render_to(scene, path)


# --- the page -------------------------------------------------------------------------------

PAGE_STYLE = """body{font-family:sans-serif;max-width:60em;margin:2em auto;color:#222}
.step{page-break-inside:avoid;border-top:1px solid #aaa;padding:1em 0;display:flex;gap:1.5em}
.step img{width:480px;height:auto;border:1px solid #ddd}
.swatch{display:inline-block;width:1em;height:1em;border-radius:50%;vertical-align:middle;margin-right:.3em}
.warn{color:#a00}"""


def _wire_html(design, wire_id):
    w = design["wires"][wire_id]
    return (f'<span class="swatch" style="background:{results.colour_hex(wire_id)}"></span>'
            f"<b>{html.escape(w['name'])}</b>")


def pieces_html(wire, diameter):
    """A split wire's pieces and how to join them (fab/pieces.py; words: core/sizes.joint_sentence),
    as HTML after the wire's line; "" for a wire of one piece."""
    parts = wire.get("pieces") or []
    if len(parts) < 2:
        return ""
    lengths = ", ".join(f"piece {k + 1} {p['length'] * 1000:.0f} mm"
                        + (f" and {p['allowance'] * 1000:.0f} mm fed past the cut" if p.get("allowance") else "")
                        for k, p in enumerate(parts))
    joints = "".join(f"<li>{html.escape(s[0].upper() + s[1:])}.</li>"
                     for s in (sizes.joint_sentence(wire, j, diameter) for j in wire.get("joints") or []))
    return f"; made in {len(parts)} pieces ({lengths}), each with its own bend program and template:<ul>{joints}</ul>"


def page_html(design, pictures, overlap=0.0):
    """The guide page; `pictures` [file name per step]."""
    parts = ["<!DOCTYPE html>", '<html><head><meta charset="utf-8"><title>wiresculpt assembly guide</title>',
             f"<style>{PAGE_STYLE}</style></head><body>", "<h1>Assembly guide</h1>"]
    mat = design["material"]
    total = sum(w.get("length", 0.0) for w in design["wires"])
    parts.append(f"<p>{len(design['wires'])} wires of {html.escape(str(mat.get('name', '')))}, "
                 f"{mat['wire_diameter'] * 1000:g} mm diameter"
                 + (f", {total * 1000:.0f} mm of wire in total" if total else "") + ". "
                 "The green beads in the pictures mark the crossings that close at that step.</p>")
    if not design.get("stable"):
        parts.append(f'<p class="warn">This design is not stable: {html.escape(design.get("reason", ""))}</p>')
    elif limits := broken_limits(design, recorded_stock(results.stored_inputs())):  # it stands, but not as asked (core/limits.py): said before the steps
        parts.append(f'<p class="warn">This design is {OVER_LIMITS}: {html.escape("; ".join(limits))}.</p>')
    items = []
    for w in design["wires"]:
        text = _wire_html(design, w["id"])
        if w.get("length"):
            text += f", {w['length'] * 1000:.0f} mm long"
        target = w.get("target") or []
        if w.get("closed") and isinstance(w.get("cut"), int) and 0 <= w["cut"] < len(target):
            mm = ", ".join(f"{AXES[k]} {round(1000 * target[w['cut']][k]) or 0}" for k in range(3))
            text += f"; its two ends meet at ({mm} mm): join them there"
            advice = closure.closure_advice(w, mat["wire_diameter"], overlap)
            if advice is not None:
                text += f" with {'a sleeve' if advice[0] == 'sleeve' else 'an overlap'}: {html.escape(advice[1])}"
        text += pieces_html(w, mat["wire_diameter"])
        items.append(f"<li>{text}</li>")
    parts.append("<p>Wires:</p><ul>" + "".join(items) + "</ul>")
    for k, picture in enumerate(pictures):
        title, sentences = step_text(design, k)
        wires = ", ".join(_wire_html(design, w) for w in design["assembly_steps"][k])
        items = "".join(f"<li>{html.escape(s[0].upper() + s[1:])}.</li>" for s in sentences)
        parts.append(f'<div class="step"><img src="{html.escape(picture)}" alt="{html.escape(title)}">'
                     f"<div><h2>{html.escape(title)}</h2><p>Wire{'s' if len(design['assembly_steps'][k]) > 1 else ''}: "
                     f"{wires}</p><ul>{items or '<li>No crossing closes at this step.</li>'}</ul></div></div>")
    parts.append("</body></html>\n")
    return "\n".join(parts)


def write_guide(scene, design, folder, resolution=RESOLUTION, overlap=0.0):
    """Writes folder/index.html and folder/step_NN.png (the design must be in the scene: see
    results.write_results). Returns the page's path. ValueError without an assembly order.
    `overlap`: m the bend programs feed past a closed wire's cut (the profile's closed_overlap)."""
    steps = design.get("assembly_steps") or []
    if not steps:
        raise ValueError("the design has no assembly order (" + (design.get("reason") or "not solved") + ")")
    pictures = [f"step_{k + 1:02d}.png" for k in range(len(steps))]
    jobs = [(k + 1, os.path.join(folder, name), {c["id"] for c in step_crossings(design, k)})
            for k, name in enumerate(pictures)]
    render_pictures(scene, design, jobs, resolution)
    path = os.path.join(folder, "index.html")
    write_atomic(path, page_html(design, pictures, overlap))
    return path


def render_still(scene, design, path, resolution=(960, 720)):
    """A still of the whole sculpture (Workbench) at `path`."""
    render_pictures(scene, design, [(0, path, set())], resolution)
