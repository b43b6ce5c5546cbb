"""Viewport overlay: Live's preview wires (live/engine.preview_shown) while Live is on; the
plane assistant's previewed candidate (operators/plane_search.PREVIEW: its wires, and the outlines
of the planes it moves or adds); the contact force at every crossing as an arrow (gpu module, no bgl), and
each wire's predicted out-of-plane deflection as a whisker.

Drawn only when the stored design has `force` per crossing and scene.wiresculpt.show_forces is
on. The longest arrow is ARROW_SHARE of the sculpture's size; each arrow starts at the crossing
and shows the force on wires[0] (docs/formats.md `force`). A wire with `out_of_plane_deflection` gets a
whisker at the target vertex where it deflects most, along its plane normal, DEFLECTION_SCALE times
the deflection long (so 1 mm shows as 1 cm), red when over the limit (DEFLECTION_LIMIT, the
solver's default 2 mm), else blue; not where the 3D check ran (its as-built ghosts show the sag).

With scene.wiresculpt.show_as_built, each wire of the 3D check as it would stand (core/as_built_view:
`as_built`, the shape change drawn as_built_scale times), every point in the colour of its distance
from its target, the slipping crossings marked, and a legend in the view's lower left corner.
The assembly slider hides what belongs to later wires: their arrows, whiskers, ghosts and marks.
"""

import blf
import bpy
import gpu
import numpy as np
from gpu_extras.batch import batch_for_shader

from ..blend import compat, results
from ..core import as_built_view, assembly_view, standing
from ..core.limits import DEFLECTION_LIMIT
from ..live import engine as live
from ..operators import plane_search

ARROW_SHARE = 0.2
HEAD_SHARE = 0.25  # arrow head length as a share of the arrow
COLOUR = (1.0, 0.35, 0.05, 1.0)
DEFLECTION_SCALE = 10.0
DEFLECTION_COLOURS = {False: (0.2, 0.45, 1.0, 1.0), True: (1.0, 0.1, 0.1, 1.0)}

_handle = None
_legend_handle = None
_shader = None
_smooth = None
_ghosts = {"design": None, "key": None, "shown": None}  # the last as-built ghosts drawn
_arrows = {"design": None, "step": None, "lines": None, "whiskers": None}  # the last design drawn


def uniform_colour_shader():
    """The built-in flat-colour shader (its name depends on the Blender: blend.compat)."""
    global _shader
    if _shader is None:
        _shader = compat.uniform_colour_shader()
    return _shader


def smooth_colour_shader():
    """The built-in per-vertex colour shader (blend.compat)."""
    global _smooth
    if _smooth is None:
        _smooth = compat.smooth_colour_shader()
    return _smooth


def as_built_shown(scene, design=None):
    """What the overlay draws of the as-built ghosts in `scene`: {"lines": {wire id: (segment end
    points, their colours)}, "marks": the slipping crossings' marks or None, "legend":
    core/as_built_view.legend}, for the wires shown after the assembly slider's step; None when
    show_as_built is off or the stored design (or `design`) has no as-built shapes."""
    design = results.stored_design() if design is None else design
    if scene is None or design is None or not scene.wiresculpt.show_as_built or not as_built_view.has_as_built(design):
        return None
    ws = scene.wiresculpt
    step, scale = ws.assembly_step, float(ws.as_built_scale)
    key = (step, scale)
    if _ghosts["design"] is not design or _ghosts["key"] != key:  # stored_design(): the same dict until it changes
        shown = results.visible_wires(design, step) if step else None
        _ghosts.update(design=design, key=key, shown={
            "lines": as_built_view.ghost_lines(design, shown, scale),
            "marks": as_built_view.slip_marks(design, shown, scale),
            "legend": as_built_view.legend(design, scale)})
    return _ghosts["shown"]


def force_arrows(design, shown=None):
    """(2k, 3) float32 line-segment end points of the force arrows, or None without forces.
    `shown`: wire ids on view (the assembly slider); crossings of hidden wires get no arrow."""
    crossings = [c for c in design.get("crossings", []) if "force" in c
                 and (shown is None or all(w in shown for w in c["wires"]))]
    if not crossings:
        return None
    points = np.concatenate([results.wire_points(w) for w in design["wires"]])
    size = float(np.max(points.max(axis=0) - points.min(axis=0))) or 1.0
    forces = np.asarray([c["force"] for c in crossings], dtype=np.float64)
    largest = float(np.max(np.linalg.norm(forces, axis=1)))
    if largest <= 0:
        return None
    scale = ARROW_SHARE * size / largest
    lines = []
    for c, f in zip(crossings, forces):
        length = float(np.linalg.norm(f))
        if length <= 0:
            continue
        start = np.asarray(c["point"], dtype=np.float64)
        tip = start + scale * f
        axis = f / length
        side = np.cross(axis, [0.0, 0.0, 1.0])
        if np.linalg.norm(side) < 1e-6:
            side = np.cross(axis, [1.0, 0.0, 0.0])
        side /= np.linalg.norm(side)
        head = HEAD_SHARE * scale * length
        lines += [start, tip, tip, tip - head * axis + 0.5 * head * side,
                  tip, tip - head * axis - 0.5 * head * side]
    return np.asarray(lines, dtype=np.float32) if lines else None


def deflection_whiskers(design, shown=None):
    """{over the limit (bool): (2k, 3) float32 segment end points}: one segment per wire with an
    `out_of_plane_deflection`, from its target point of largest deflection along the plane normal,
    DEFLECTION_SCALE x the deflection long. `shown` as force_arrows."""
    out = {False: [], True: []}
    if standing.checked(design) is not None and as_built_view.has_as_built(design):
        return {}  # the 3D check's as-built shapes replace each wire's own figure
    for w in design.get("wires", []):
        if "out_of_plane_deflection" not in w or (shown is not None and w["id"] not in shown):
            continue
        vertex = w.get("out_of_plane_deflection_vertex", -1)
        if not 0 <= vertex < len(w.get("target", [])):
            continue
        start = np.asarray(w["target"][vertex], dtype=np.float64)
        normal = np.asarray(w["plane"]["normal"], dtype=np.float64)
        deflection = w["out_of_plane_deflection"]
        out[deflection > DEFLECTION_LIMIT] += [start, start + DEFLECTION_SCALE * deflection * normal]
    return {k: np.asarray(v, dtype=np.float32) for k, v in out.items() if v}


def live_lines(scene):
    """Live's preview entries (colour, lines) that the overlay draws in `scene`: the wires added up
    to the assembly slider's step of the live verdict's own order (every wire at step 0)."""
    step = scene.wiresculpt.assembly_step if scene is not None else 0
    return assembly_view.shown_lines(live.preview_shown(), *live.preview_order(), step)


def draw_live():
    """The live verdict's wires (live/engine.py) as lines in their colours, over everything: the
    wires lie on the model's surface, where a depth test hid all but their kinks in Solid view."""
    shader = uniform_colour_shader()
    gpu.state.line_width_set(2.0)
    gpu.state.depth_test_set('NONE')
    shader.bind()
    for colour, lines in live_lines(bpy.context.scene):
        shader.uniform_float("color", colour)
        batch_for_shader(shader, 'LINES', {"pos": lines}).draw(shader)
    gpu.state.line_width_set(1.0)
    live.note_drawn()


def draw_candidate(preview):
    """The previewed candidate's wires (thicker than Live's) and the outlines of its moved planes,
    over everything (no depth test: the wires of the scene's own design would hide them)."""
    shader = uniform_colour_shader()
    shader.bind()
    gpu.state.depth_test_set('NONE')
    for width, segments in ((3.0, preview["wires"]), (1.5, preview["planes"])):
        gpu.state.line_width_set(width)
        for colour, lines in segments:
            shader.uniform_float("color", colour)
            batch_for_shader(shader, 'LINES', {"pos": lines}).draw(shader)
    gpu.state.line_width_set(1.0)
    plane_search.DRAWN[0] += 1


def draw_as_built(ghosts):
    """The as-built ghosts in their distance colours and the slipping crossings' marks, over
    everything (they lie within a wire's thickness of the wires when the sag is small)."""
    gpu.state.depth_test_set('NONE')
    gpu.state.line_width_set(3.0)
    shader = smooth_colour_shader()
    shader.bind()
    for lines, colours in ghosts["lines"].values():
        if len(lines):
            batch_for_shader(shader, 'LINES', {"pos": lines, "color": colours}).draw(shader)
    if ghosts["marks"] is not None:
        flat = uniform_colour_shader()
        flat.bind()
        flat.uniform_float("color", as_built_view.SLIP_COLOUR)
        batch_for_shader(flat, 'LINES', {"pos": ghosts["marks"]}).draw(flat)
    gpu.state.line_width_set(1.0)


LEGEND_MARGIN = 20  # px from the view's lower left corner
LEGEND_BAR = (240, 12)  # px: the ramp's bar
LEGEND_TEXT = 11  # px


def draw_legend():
    """The as-built legend (POST_PIXEL): the title, the ramp as a bar with its stops' labels, the notes."""
    ghosts = as_built_shown(bpy.context.scene)
    if ghosts is None or ghosts["legend"] is None:
        return
    legend = ghosts["legend"]
    scale = bpy.context.preferences.system.ui_scale
    x0, bar_w, bar_h, text = (int(v * scale) for v in (LEGEND_MARGIN, LEGEND_BAR[0], LEGEND_BAR[1], LEGEND_TEXT))
    line = int(1.5 * text)
    font = 0
    compat.font_size(font, text)
    blf.color(font, 1.0, 1.0, 1.0, 1.0)
    for k, note in enumerate(legend["notes"]):
        blf.position(font, x0, x0 + line * (len(legend["notes"]) - 1 - k), 0)
        blf.draw(font, note)
    label_y = x0 + line * len(legend["notes"])  # the stops' labels above the notes, the bar above them
    bar_y = label_y + line
    stops = legend["stops"]
    pos, col = [], []
    for (xa, ca, _la), (xb, cb, _lb) in zip(stops, stops[1:]):
        a, b = x0 + xa * bar_w, x0 + xb * bar_w
        pos += [(a, bar_y, 0), (b, bar_y, 0), (b, bar_y + bar_h, 0), (a, bar_y, 0), (b, bar_y + bar_h, 0), (a, bar_y + bar_h, 0)]
        col += [ca, cb, cb, ca, cb, ca]
    gpu.state.blend_set('ALPHA')
    shader = smooth_colour_shader()
    shader.bind()
    batch_for_shader(shader, 'TRIS', {"pos": pos, "color": col}).draw(shader)
    for x, _colour, label in stops:
        width = blf.dimensions(font, label)[0]
        left = x0 + x * bar_w - (0 if x == 0 else width if x == 1 else width / 2)
        blf.position(font, left, label_y, 0)
        blf.draw(font, label)
    blf.position(font, x0, bar_y + bar_h + line - text, 0)
    blf.draw(font, legend["title"])
    gpu.state.blend_set('NONE')


def draw():
    if live.preview_shown():
        draw_live()
    preview = plane_search.PREVIEW
    if preview is not None and plane_search.previewed(bpy.context) is not None:
        draw_candidate(preview)
    scene = bpy.context.scene
    ghosts = as_built_shown(scene)
    if ghosts is not None:
        draw_as_built(ghosts)
    if scene is None or not scene.wiresculpt.show_forces:
        return
    design = results.stored_design()
    if design is None:
        return
    step = scene.wiresculpt.assembly_step
    # stored_design() returns the same dict until the text changes
    if _arrows["design"] is not design or _arrows["step"] != step:
        shown = results.visible_wires(design, step) if step else None
        _arrows.update(design=design, step=step, lines=force_arrows(design, shown),
                       whiskers=deflection_whiskers(design, shown))
    shader = uniform_colour_shader()
    gpu.state.line_width_set(2.0)
    gpu.state.depth_test_set('NONE')
    shader.bind()
    segments = [(COLOUR, _arrows["lines"])] if _arrows["lines"] is not None else []
    segments += [(DEFLECTION_COLOURS[over], lines) for over, lines in _arrows["whiskers"].items()]
    for colour, lines in segments:
        shader.uniform_float("color", colour)
        batch_for_shader(shader, 'LINES', {"pos": lines}).draw(shader)
    gpu.state.line_width_set(1.0)


def register():
    global _handle, _legend_handle
    if _handle is None:
        _handle = bpy.types.SpaceView3D.draw_handler_add(draw, (), 'WINDOW', 'POST_VIEW')
    if _legend_handle is None:
        _legend_handle = bpy.types.SpaceView3D.draw_handler_add(draw_legend, (), 'WINDOW', 'POST_PIXEL')


def unregister():
    global _handle, _legend_handle, _shader, _smooth
    if _handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_handle, 'WINDOW')
        _handle = None
    if _legend_handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_legend_handle, 'WINDOW')
        _legend_handle = None
    _shader = _smooth = None
    _ghosts.update(design=None, key=None, shown=None)
    _arrows.update(design=None, step=None, lines=None, whiskers=None)
