"""Does the stored design still match the scene? What changed since the Optimize that made it, in
words a maker acts on ("plane Slice B moved", "contours ticked differently"), for the Stability
box (ui/results.py). bpy-free: the add-on gathers the scene's planes, ticks and settings, this
module compares them with what the design recorded.

What is compared:
- the planes: each wire's `plane` (origin, normal) in the design (a wire's name is "<plane
  name>/<contour index>") against that plane's handle now. A plane is its object, not its name:
  Optimize records a persistent id per plane beside the design (current_names), so a renamed
  handle is the same plane, named by its new name; a record without ids (an older add-on's)
  goes by the names. A plane counts as
  the same when its unit normal is within NORMAL_TOLERANCE (each component) and the new origin
  lies within ORIGIN_TOLERANCE of the recorded plane: sliding or spinning a handle within its own
  plane cuts the same contours, so it does not make the design stale.
- the ticked contours: the (plane, index) pairs of the design's wires against the ticked ones.
- the inputs Optimize recorded besides the design (`inputs`, see blend/results.py
  store_inputs): the model's name, the solver settings and the material it was solved with,
  against the panel's values now, and a digest of the model's triangles as sliced (mesh_digest,
  in world coordinates: an edit, a modifier or a move of the model changes it). A design without that record (the batch's, the plane
  assistant's, an older add-on's) is compared by its planes and ticks only.

The tolerances are far below any edit a maker makes (a nudge is 0.1 mm at least) and far above
the float round trips of a handle's matrix and of the design's JSON.

The design's wire names keep the plane names they were solved with (design.json is written then);
renamed_wire / renamed_text show them with the planes' names now (current_names) where the panel
prints them.
"""
import dataclasses
import hashlib
import math
import re

import numpy as np

ORIGIN_TOLERANCE = 1e-6  # m: the distance of the new origin from the recorded plane
NORMAL_TOLERANCE = 1e-6  # per component of the unit normals
VALUE_TOLERANCE = 1e-9  # relative, for a setting's or the material's number
# a material's numbers that change with its wire diameter (a preset scaled to it, props.material_of):
# not named beside it, the maker changed the diameter
SCALED = ("bending_stiffness", "max_torque")
MAX_NAMED = 3  # contours named after "contours ticked differently"

MESH_CHANGED = "changed"  # the model's mesh changed since its digest was taken, and is not read again yet

PREFIX = "From an earlier Optimize: "
SUFFIX = "; Optimize again"


def mesh_digest(vertices, faces):
    """A short digest of a triangle mesh (world coordinates, (n, 3) float64; faces (m, 3) int32) as
    the solver slices it: any change of a coordinate or a triangle changes it."""
    h = hashlib.blake2b(digest_size=12)
    for array, kind in ((vertices, np.float64), (faces, np.int32)):
        a = np.ascontiguousarray(array, dtype=kind)
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def wire_contour(name):
    """(plane name, contour index) of a wire named "<plane name>/<index>", or None."""
    plane, sep, index = str(name).rpartition("/")
    if not sep:
        return None
    try:
        return plane, int(index)
    except ValueError:
        return None


def recorded_planes(design):
    """({plane name: (origin, normal)}, {(plane name, contour index)}) of the design's wires."""
    planes, ticks = {}, set()
    for wire in design.get("wires") or []:
        key = wire_contour(wire.get("name", ""))
        plane = wire.get("plane")
        if key is None or not isinstance(plane, dict):
            continue
        ticks.add(key)
        planes.setdefault(key[0], (tuple(plane["origin"]), tuple(plane["normal"])))
    return planes, ticks


def current_names(recorded, ids, handles):
    """{recorded plane name: the name of that plane's handle now, or None when it is gone}.

    recorded: the design's plane names. ids: {plane name: persistent id} as Optimize recorded them
    (blend/results.store_inputs, "planes"); None, or a name without one: that plane goes by its
    name, as records before ids did. handles: {name: id or None} of the scene's slicing handles
    that may be the recorded ones (those of the contour list and those of a recorded name).
    A recorded id names the handle that has it now: the one still of its name, else the only
    one (a renamed plane); none, or several and none of them of its name (a copy that kept the
    id), is a plane gone."""
    ids = ids if isinstance(ids, dict) else {}
    holders = {}
    for name, uid in handles.items():
        if uid is not None:
            holders.setdefault(uid, []).append(name)
    names = {}
    for name in recorded:
        uid = ids.get(name)
        if uid is None:
            names[name] = name if name in handles else None
        elif handles.get(name) == uid:
            names[name] = name
        else:
            found = holders.get(uid, [])
            names[name] = found[0] if len(found) == 1 else None
    return names


def renamed_wire(name, names):
    """Wire `name` ("<plane name>/<index>") with its plane's name now (`names`: current_names), or
    as it is when that plane is not renamed (kept, gone, or not a wire name)."""
    key = wire_contour(name)
    now = (names or {}).get(key[0]) if key else None
    return f"{now}/{key[1]}" if now and now != key[0] else name


def renamed_text(text, design, names):
    """`text` (a reason, a warning) with the names of `design`'s wires whose plane was renamed
    (renamed_wire) written as they are called now. Every wire name is matched, longest first, and
    not followed by a digit, so neither "A/0" inside "Slice A/0" nor "Slice A/1" inside
    "Slice A/10" is taken for another wire."""
    wires = [str(w.get("name", "")) for w in design.get("wires") or []]
    now = {name: renamed_wire(name, names) for name in wires if name}
    if not text or all(a == b for a, b in now.items()):
        return text
    pattern = "|".join(re.escape(name) for name in sorted(now, key=len, reverse=True))
    return re.sub(f"(?:{pattern})(?![0-9])", lambda m: now[m.group(0)], text)


def _unit(v):
    length = math.sqrt(sum(float(x) * float(x) for x in v))
    return tuple(float(x) / length for x in v) if length > 0 else tuple(float(x) for x in v)


def plane_change(recorded, now):
    """"rotated" (the normal turned), "moved" (the plane moved along its normal) or None (the same
    plane) between two (origin, normal) pairs; `now` None: the handle has no normal ("rotated")."""
    if now is None:
        return "rotated"
    (o0, n0), (o1, n1) = recorded, now
    n0, n1 = _unit(n0), _unit(n1)
    if any(abs(a - b) > NORMAL_TOLERANCE for a, b in zip(n0, n1)):
        return "rotated"
    offset = sum((float(b) - float(a)) * n for a, b, n in zip(o0, o1, n0))
    return "moved" if abs(offset) > ORIGIN_TOLERANCE else None


def _same_value(a, b):
    if isinstance(a, bool) or isinstance(b, bool) or not isinstance(a, (int, float)) \
            or not isinstance(b, (int, float)):
        return a == b
    return abs(float(a) - float(b)) <= VALUE_TOLERANCE * max(abs(float(a)), abs(float(b)), 1e-12)


def changed_keys(recorded, now):
    """The keys whose values differ between two flat dicts (a key in one only differs), in the
    recorded dict's order, then the new ones."""
    keys = list(recorded) + [k for k in now if k not in recorded]
    return [k for k in keys if k not in recorded or k not in now or not _same_value(recorded[k], now[k])]


@dataclasses.dataclass(frozen=True)
class SceneNow:
    """What the scene holds now, for changes() to compare with what the design recorded (each field
    as changes() describes it)."""

    planes: dict
    ticked: object = None
    names: object = None
    model: object = None
    settings: object = None
    material: object = None
    mesh: object = None


def changes(design, now, inputs=None, labels=None, recorded=None):
    """What changed since `design` was optimized, as short phrases ("plane Slice B moved", "plane
    Slice C removed", "plane Slice D added", "contours ticked differently (Slice A #1 unticked)",
    "model changed", "settings changed (Max Bend)"); [] while it is current.

    now: a SceneNow of the scene's planes, ticks, plane names, model, settings, material and mesh:
    planes: {handle name: (origin, normal) or None (no normal)} of the slicing handles now: at
    least those the design's planes have now (`names`) and those named by the ticks (a name
    missing is a plane gone).
    ticked: {(plane name, contour index)} ticked now (a plane name may be one that is gone), or
    None when they cannot be read.
    names: current_names of the design's planes: a renamed plane is compared, and named, by its
    name now; None: each plane by its recorded name.
    inputs: what Optimize recorded ({"target": the model's name, "settings", "material"}; the key as saved), or None: then model,
    settings and material are not compared. model: the model's name now ("" for none);
    settings / material: the dicts props.solver_settings / material_of give now (settings None:
    the panel's values are not valid, e.g. the smallest bend above the largest).
    labels: {setting or material key: the name the panel shows} for the phrase.
    mesh: the digest of the model's triangles now (mesh_digest), MESH_CHANGED when they changed
    since the recorded digest but were not read again, None when not known (not compared).
    recorded: recorded_planes(design) when the caller keeps it (a panel redraws often)."""
    planes, ticked, names, model = now.planes, now.ticked, now.names, now.model
    settings, material, mesh = now.settings, now.material, now.mesh
    said = []
    before, ticks_before = recorded or recorded_planes(design)
    now = {name: (names or {}).get(name, name) for name in before}
    removed, present = set(), set()  # recorded names of the planes gone; names now of those kept
    for name, plane in before.items():
        if now[name] not in planes:
            removed.add(name)
            said.append(f"plane {name} removed")
            continue
        present.add(now[name])
        how = plane_change(plane, planes[now[name]])
        if how:
            said.append(f"plane {now[name]} {how}")
    if ticked is not None:
        added = set()
        for name in sorted({p for p, _i in ticked} - present):
            if name in planes:  # a tick whose plane is gone is not a plane added (the ticks differ)
                added.add(name)
                said.append(f"plane {name} added")
        old = {(now[p], i) for p, i in ticks_before if p not in removed}
        new = {t for t in ticked if t[0] not in added and (t[0] in present or t[0] not in removed)}
        if old != new:
            named = [f"{p} #{i} unticked" for p, i in sorted(old - new)] + [f"{p} #{i} ticked" for p, i in sorted(new - old)]
            more = f", {len(named) - MAX_NAMED} more" if len(named) > MAX_NAMED else ""
            said.append(f"contours ticked differently ({', '.join(named[:MAX_NAMED])}{more})")
    elif not said:  # the ticks cannot be read and no plane explains it
        said.append("contours ticked differently")
    if inputs:
        if model is not None and inputs.get("target") is not None and str(inputs["target"]) != str(model):
            said.append("model changed")
        elif mesh is not None and isinstance(inputs.get("mesh"), str) and mesh != inputs["mesh"]:
            said.append(f"model {model} edited or moved" if model else "model edited or moved")
        keys = []
        if settings is None:
            keys.append(None)
        elif isinstance(inputs.get("settings"), dict):
            keys += changed_keys(inputs["settings"], settings)
        if material is not None and isinstance(inputs.get("material"), dict):
            changed = changed_keys(inputs["material"], material)
            if "name" in changed:  # another material: its numbers are its own, the name says it
                changed = [k for k in changed if k in ("name", "wire_diameter")]
            elif "wire_diameter" in changed:  # a preset's numbers follow the diameter
                changed = [k for k in changed if k not in SCALED]
            keys += changed
        if keys:
            words = []
            for key in keys:
                word = (labels or {}).get(key, key) if key is not None else None
                if word and word not in words:
                    words.append(word)
            said.append("settings changed" + (f" ({', '.join(words)})" if words else ""))
    return said


def stale_text(said):
    """The Stability box's first line for the phrases of changes(), or "" while current."""
    return f"{PREFIX}{', '.join(said)}{SUFFIX}" if said else ""
