"""The machine preview in the viewport: after an export, one ghost curve per
wire showing the wire the machine is predicted to make (fab/export.py's "predicted", the bend
program run through the spring-back model), laid on the wire's plane by the rigid map that best
fits the wire's rest shape onto its target there. The ghosts live in the "Machine Preview"
collection, are tagged by wire name and replaced on every export (never accumulated); a wire that
is no longer exported (or has no plane to lay it on) loses its ghost."""
import bpy
import numpy as np

from ..core.frames import plane_frame, rigid_fit_2d, to_2d, to_3d
from .objects import remove_object, scene_collection, tagged, write_polyline

PREVIEW_KEY = "wiresculpt_preview"  # custom property on ghost curves: the wire's name
PREVIEW_COLLECTION = "Machine Preview"
GHOST_COLOUR = (0.5, 0.0, 0.75, 1.0)  # the template's dashed violet
GHOST_MATERIAL = "wiresculpt machine preview"
GHOST_RADIUS = 0.35  # the ghost's tube radius in wire radii: thinner than the wire, seen through it


def _ghost_material():
    mat = bpy.data.materials.get(GHOST_MATERIAL) or bpy.data.materials.new(GHOST_MATERIAL)
    mat.diffuse_color = GHOST_COLOUR  # the viewport's Material colour
    return mat


def rest_on_target(wire):
    """The wire's target points matched to its rest points (rest starts at the cut; a closed
    wire's rest repeats the cut at its end): (n, 3)."""
    target = np.asarray(wire["target"], dtype=np.float64)
    n, m = len(wire["rest"]), len(target)
    start = max(int(wire.get("cut", -1)), 0)
    return target[[(start + i) % m for i in range(n)]]


def ghost_points(wire, predicted):
    """The predicted 2D wire (m, rest frame) in 3D on the wire's plane."""
    _n, u, v = plane_frame(wire["plane"]["normal"])
    origin = wire["plane"]["origin"]
    M, t = rigid_fit_2d(wire["rest"], to_2d(rest_on_target(wire), origin, u, v))
    return to_3d(np.asarray(predicted, dtype=np.float64) @ M.T + t, origin, u, v)


MODEL_KEY = "wiresculpt_preview_springback"  # custom property on ghosts: the spring-back line used (a, b deg)
DISTANCE_KEY = "wiresculpt_preview_distance_mm"  # custom property on ghosts: largest distance, mm


def figures(scene):
    """([(wire name, largest distance from the rest shape in mm)] by name, (a, b in degrees) of the
    spring-back line used or None) of the ghosts in the scene, for the Fabrication panel."""
    ghosts = tagged(scene, PREVIEW_KEY)
    rows = [(name, float(obj.get(DISTANCE_KEY, 0.0))) for name, obj in sorted(ghosts.items())]
    model = next((tuple(float(v) for v in obj[MODEL_KEY]) for obj in ghosts.values() if MODEL_KEY in obj), None)
    return rows, model


def clear_ghosts(scene):
    """Removes every ghost (a new design, or cleared results, makes them stale)."""
    for obj in tagged(scene, PREVIEW_KEY).values():
        remove_object(obj)


def write_ghosts(scene, design, result):
    """One ghost curve per exported wire of `result` (fab.export.export's); returns how many."""
    wires = {w["name"]: w for w in design["wires"]}
    existing = tagged(scene, PREVIEW_KEY)
    radius = GHOST_RADIUS * 0.5 * float(design.get("material", {}).get("wire_diameter", 0.002))
    mat = _ghost_material()
    coll = scene_collection(scene, PREVIEW_COLLECTION)
    written = 0
    for summary in result["wires"]:
        wire = wires.get(summary["name"])
        if wire is None or "predicted" not in summary or "plane" not in wire or not wire.get("target"):
            continue  # nowhere to lay it (a hand-made design without its plane): no ghost
        obj = existing.pop(wire["name"], None)
        if obj is None or obj.type != 'CURVE':
            name = f"Predicted {wire['name']}"
            obj = bpy.data.objects.new(name, bpy.data.curves.new(name, 'CURVE'))
            obj[PREVIEW_KEY] = wire["name"]
            coll.objects.link(obj)
        obj.data.dimensions = '3D'
        obj.data.bevel_depth = radius
        obj.data.bevel_resolution = 2
        if obj.data.materials:
            obj.data.materials[0] = mat
        else:
            obj.data.materials.append(mat)
        write_polyline(obj.data, ghost_points(wire, summary["predicted"]), False)
        obj.matrix_world = ((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1))
        obj.color = GHOST_COLOUR
        obj.show_in_front = True
        obj.hide_render = True
        obj.hide_select = True
        obj[DISTANCE_KEY] = round(float(summary["preview_distance"]) * 1000.0, 3)
        if "preview_springback" in result:
            obj[MODEL_KEY] = list(result["preview_springback"])
        written += 1
    for obj in existing.values():
        remove_object(obj)
    return written
