"""The scene file of a headless run (docs/formats.md), read and validated.

Every problem is one ValueError whose sentence names the key (as a path such as
`planes[1].normal`) or the line at fault; nothing is guessed.
"""
import json
import math
import os
import unicodedata
from dataclasses import dataclass, field

from . import materials, settings as settings_table
from .figures import versus

TOP_KEYS = {"mesh", "size", "material", "planes", "settings", "machine_profile"}
PLANE_KEYS = {"name", "origin", "normal", "contours"}
MAX_COORDINATE = 1e6  # metres (or mesh units): beyond this a number is a typo, not a sculpture
MAX_SIZE = 100.0  # metres
MAX_PLANES = 64  # a sculpture of more wires than this is beyond the layering's search (docs/robustness.md)
# A plane's name becomes a Blender object's name in sculpture.blend (Blender keeps 63 bytes of
# UTF-8 and truncates the rest) and, with its wires' numbers, file names in svg/, dxf/, ...
MAX_NAME_BYTES = 63
# A normal component below this fraction of the largest is zero in all but representation: it is
# set to 0 as the scene is read, so [1e-300, 1, 0] is the plane [0, 1, 0] (docs/robustness.md).
NORMAL_ZERO = 1e-12
MAX_SCENE_BYTES = 16 * 1024 ** 2  # a scene of 64 planes and their cuts is a few kB; 100 MB names were solved


@dataclass
class PlaneSpec:
    name: str
    origin: tuple
    normal: tuple
    contours: object = "largest"


@dataclass
class Scene:
    path: str
    mesh: str  # absolute path
    size: object  # metres, or None: the mesh's units are metres
    material: dict
    planes: list
    settings: dict = field(default_factory=settings_table.defaults)
    machine_profile: object = None  # absolute path of a machine profile JSON, or None: the default


def _number(value, key, low=None, high=None, low_open=False):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f'scene key "{key}" must be a number, got {_json_shown(value)}')
    try:
        value = float(value)
    except OverflowError:  # an integer beyond any float (JSON allows 10^400)
        raise ValueError(f'scene key "{key}" must be a finite number, got an integer of about '
                         f'{int(value.bit_length() * 0.30103) + 1} digits') from None
    if not math.isfinite(value):
        raise ValueError(f'scene key "{key}" must be a finite number, got {value}')
    if low is not None and (value <= low if low_open else value < low):
        got, least = versus(value, low, 6, "g")
        raise ValueError(f'scene key "{key}" must be {"greater than" if low_open else "at least"} {least}, got {got}')
    if high is not None and value > high:
        got, most = versus(value, high, 6, "g")
        raise ValueError(f'scene key "{key}" must be at most {most}, got {got}')
    return value


def _vector(value, key):
    if not isinstance(value, list) or len(value) != 3:
        raise ValueError(f'scene key "{key}" must be a list of three numbers, got {_json_shown(value)}')
    return tuple(_number(x, f"{key}[{i}]", -MAX_COORDINATE, MAX_COORDINATE) for i, x in enumerate(value))


def clean_normal(normal):
    """The normal with every component below NORMAL_ZERO of the largest |component| set to 0."""
    largest = max(abs(c) for c in normal)
    return tuple(0.0 if abs(c) < NORMAL_ZERO * largest else c for c in normal)


def _shown(text, limit=40):
    """`text` for a message: control and invisible characters escaped (\\n, \\x00, \\u200b), cut to
    `limit` characters with the length said."""
    escaped = "".join(json.dumps(ch)[1:-1] if _hidden(ch) or ch in '"\\' else ch for ch in text[:limit])
    return f'"{escaped}"' + (f" ... ({len(text)} characters)" if len(text) > limit else "")


def _json_shown(value, limit=80):
    """A JSON value for a message, on one line, cut to `limit` characters."""
    text = json.dumps(value)
    return text if len(text) <= limit else text[:limit] + f"... ({len(text)} characters)"


def _path_shown(path):
    """A path for a message: as it is, or escaped when it holds a control character."""
    return path if not any(_hidden(ch) for ch in path) else _shown(path, 200)


def _hidden(ch):
    return unicodedata.category(ch) in ("Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp")


def _name(name, key):
    """A plane's name, checked: a non-empty string of at most MAX_NAME_BYTES bytes of UTF-8, with no
    control or invisible character and no path separator (/ separates the plane from the contour
    in wire names such as "A/0")."""
    if not isinstance(name, str) or not name.strip():
        raise ValueError(f'scene key "{key}" must be a non-empty string')
    size = len(name.encode("utf-8", "surrogatepass"))
    if size > MAX_NAME_BYTES:
        raise ValueError(f'scene key "{key}" is {size} bytes long ({_shown(name)}); a plane name may have at most '
                         f'{MAX_NAME_BYTES} bytes of UTF-8 (Blender\'s limit for object names)')
    bad = next((ch for ch in name if _hidden(ch)), None)
    if bad is not None:
        raise ValueError(f'scene key "{key}" ({_shown(name)}) holds the control character {_shown(bad)[1:-1]} '
                         f'(U+{ord(bad):04X}); use printable characters')
    for sep in ("/", "\\"):
        if sep in name:
            raise ValueError(f'scene key "{key}" ({_shown(name)}) holds "{_shown(sep)[1:-1]}"; a plane name may not '
                             'hold / or \\ (/ separates the plane from the contour in wire names such as "A/0")')
    return name


def _unknown(keys, allowed, where):
    extra = sorted(set(keys) - allowed)
    if extra:
        place = f" in {where}" if where else ""
        raise ValueError(f'unknown scene key {_shown(extra[0])}{place}; expected one of: {", ".join(sorted(allowed))}')


def _material(value):
    if value is None:
        return dict(materials.PRESETS["steel"])
    if isinstance(value, str):
        if value not in materials.PRESETS:
            raise ValueError(f'scene key "material": unknown preset "{value}"; use one of: '
                             f'{", ".join(sorted(materials.PRESETS))} or an object')
        return dict(materials.PRESETS[value])
    if not isinstance(value, dict):
        raise ValueError('scene key "material" must be a preset name or an object')
    _unknown(value, {"name", *materials.FIELDS}, "material")
    out = {"name": str(value.get("name", "custom"))}
    for key, (_unit, low, high) in materials.FIELDS.items():
        if key in value:
            out[key] = _number(value[key], f"material.{key}", low, high, low_open=True)
        elif key in materials.REQUIRED:
            raise ValueError(f'scene key "material.{key}" is missing')
    return out


def _plane(value, index, names):
    key = f"planes[{index}]"
    if not isinstance(value, dict):
        raise ValueError(f'scene key "{key}" must be an object with "origin" and "normal"')
    _unknown(value, PLANE_KEYS, key)
    for required in ("origin", "normal"):
        if required not in value:
            raise ValueError(f'scene key "{key}.{required}" is missing')
    name = value.get("name", chr(ord("A") + index) if index < 26 else f"P{index}")
    _name(name, f"{key}.name")
    if name in names:
        raise ValueError(f'scene key "{key}.name": the name "{name}" is used by two planes')
    names.add(name)
    origin = _vector(value["origin"], f"{key}.origin")
    normal = _vector(value["normal"], f"{key}.normal")
    if math.sqrt(sum(c * c for c in normal)) < 1e-12:
        raise ValueError(f'scene key "{key}.normal" (plane {name}) is zero; give a direction such as [0, 0, 1]')
    normal = clean_normal(normal)
    contours = value.get("contours", "largest")
    if isinstance(contours, list):
        for i, k in enumerate(contours):
            if isinstance(k, bool) or not isinstance(k, int) or k < 0:
                raise ValueError(f'scene key "{key}.contours[{i}]" must be a contour index (0, 1, ...), got {_json_shown(k)}')
    elif contours not in ("largest", "all"):
        raise ValueError(f'scene key "{key}.contours" must be "largest", "all" or a list of indices, got {_json_shown(contours)}')
    return PlaneSpec(name, origin, normal, contours)


def _cuts(value):
    """settings.cuts: {wire name: index into the wire's target} for closed wires."""
    if not isinstance(value, dict):
        raise ValueError('scene key "settings.cuts" must be an object such as {"A/0": 12}')
    for name, index in value.items():
        if len(name.encode("utf-8", "surrogatepass")) > MAX_NAME_BYTES + 8 or any(_hidden(ch) for ch in name):
            raise ValueError(f'scene key "settings.cuts" names the wire {_shown(name)}, which no plane can have '
                             f'(a wire name is a plane name of at most {MAX_NAME_BYTES} bytes, "/" and the contour\'s '
                             'number, with no control character)')
        if isinstance(index, bool) or not isinstance(index, int) or index < 0:
            raise ValueError(f'scene key "settings.cuts.{name}" must be a vertex index (0, 1, ...), got {_json_shown(index)}')
    return dict(value)


def _settings(value):
    out = settings_table.defaults()
    out["cuts"] = {}
    if value is None:
        return out
    if not isinstance(value, dict):
        raise ValueError('scene key "settings" must be an object')
    _unknown(value, set(settings_table.SETTINGS) | {"cuts"}, "settings")
    for key, raw in value.items():
        if key == "cuts":
            out["cuts"] = _cuts(raw)
            continue
        _default, low, high, unit, _text = settings_table.SETTINGS[key]
        if unit == "choice":
            if raw not in settings_table.CHOICES[key]:
                raise ValueError(f'scene key "settings.{key}" must be one of '
                                 f'{", ".join(json.dumps(c) for c in settings_table.CHOICES[key])}, got {_json_shown(raw)}')
            out[key] = raw
        elif unit == "bool":
            if not isinstance(raw, bool):
                raise ValueError(f'scene key "settings.{key}" must be true or false, got {_json_shown(raw)}')
            out[key] = raw
        elif unit == "int":
            if isinstance(raw, bool) or not isinstance(raw, int):
                raise ValueError(f'scene key "settings.{key}" must be a whole number, got {_json_shown(raw)}')
            out[key] = int(_number(raw, f"settings.{key}", low, high))
        else:
            out[key] = None if raw is None and _default is None else _number(raw, f"settings.{key}", low, high)
    if out["min_bend_deg"] >= out["max_bend_deg"]:
        raise ValueError('scene key "settings.min_bend_deg" must be smaller than "settings.max_bend_deg"')
    return out


def parse_scene(data, path="scene.json"):
    """A validated Scene from the decoded JSON `data` of the file at `path`."""
    if not isinstance(data, dict):
        raise ValueError(f"{path}: the scene must be a JSON object")
    _unknown(data, TOP_KEYS, "")
    if "mesh" not in data:
        raise ValueError('scene key "mesh" is missing: give the path of an OBJ, STL or PLY file')
    if not isinstance(data["mesh"], str) or not data["mesh"]:
        raise ValueError('scene key "mesh" must be a file path')
    mesh = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(path)), data["mesh"]))
    if not os.path.isfile(mesh):
        raise ValueError(f'scene key "mesh": file not found: {_path_shown(mesh)}')
    size = data.get("size")
    if size is not None:
        size = _number(size, "size", 0.0, MAX_SIZE, low_open=True)
    settings = _settings(data.get("settings"))
    planes = data.get("planes")
    if settings["plane_search"] == "auto" and isinstance(planes, list):
        pass  # "auto" proposes the planes: an empty list is allowed, given planes are still checked
    elif not isinstance(planes, list) or not planes:
        raise ValueError('scene key "planes" must be a non-empty list of planes (or set "settings.plane_search" '
                         'to "auto" to have them proposed)')
    if len(planes) > MAX_PLANES:
        raise ValueError(f'scene key "planes" has {len(planes)} planes; at most {MAX_PLANES} are allowed')
    names = set()
    parsed = [_plane(p, i, names) for i, p in enumerate(planes)]
    profile = data.get("machine_profile")
    if profile is not None:
        if not isinstance(profile, str) or not profile:
            raise ValueError('scene key "machine_profile" must be the path of a machine profile JSON file')
        profile = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(path)), profile))
        if not os.path.isfile(profile):
            raise ValueError(f'scene key "machine_profile": file not found: {_path_shown(profile)}')
    return Scene(os.path.abspath(path), mesh, size, _material(data.get("material")), parsed,
                 settings, profile)


def load_scene(path):
    """Reads and validates the scene file at `path`."""
    try:
        with open(path, encoding="utf-8") as f:
            size = os.fstat(f.fileno()).st_size
            if size > MAX_SCENE_BYTES:
                raise ValueError(f"scene file {path} is {size / 1024 ** 2:.0f} MB; a scene file is at most "
                                 f"{MAX_SCENE_BYTES // 1024 ** 2} MB (its planes, settings and cuts take a few kB)")
            text = f.read()
    except OSError as exc:
        raise ValueError(f"cannot read scene file {path}: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"scene file {path} is not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at offset "
                         f"{exc.start}); save it as UTF-8") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path} line {exc.lineno}: not valid JSON ({exc.msg})") from None
    except RecursionError:  # thousands of nested [ or {: no scene is that deep
        raise ValueError(f"{path}: not a scene, its JSON is nested too deeply") from None
    except ValueError as exc:  # an integer of over 4300 digits (Python's limit for reading one)
        raise ValueError(f"{path}: not valid JSON ({str(exc).split(':')[0]})") from None
    return parse_scene(data, path)
