"""The design document (`design.json`, FORMATS.md): built as a plain dict, written atomically.

Only stages that ran put values in it: a key a stage owns is absent until that stage exists, and
`pending_stages` names the stages that did not run.
"""
import json
import re

from .files import write_atomic

FORMAT = "wiresculpt-design"
VERSION = 1


def new_design(material, settings):
    return {
        "format": FORMAT,
        "version": VERSION,
        "units": "m",
        "material": dict(material),
        "torque_fraction": settings["torque_fraction"],
        "machine": {
            "min_segment": settings["min_segment"],
            "max_bend_deg": settings["max_bend_deg"],
            "min_bend_deg": settings["min_bend_deg"],
        },
        "wires": [],
        "stable": False,
        "reason": "",
        "stages": {},
    }


def wire_entry(wire_id, name, origin, normal, closed, contour):
    """A wire as sliced: `contour` (n, 3) in metres; later stages add target, rest, cut, length."""
    return {
        "id": wire_id,
        "name": name,
        "plane": {"origin": [float(x) for x in origin], "normal": [float(x) for x in normal]},
        "closed": bool(closed),
        "contour": [[float(x) for x in p] for p in contour],
    }


# An innermost list spread over lines (JSON strings cannot hold a raw newline, so this only
# matches real lists): written on one line, so a polyline reads one point per line.
_INNER_LIST = re.compile(r"\[\n\s+([^\[\]{}]*?)\n\s*\]")


def dumps(design):
    text = json.dumps(design, indent=1, allow_nan=False)
    return _INNER_LIST.sub(lambda m: "[" + " ".join(m.group(1).split()) + "]", text) + "\n"


def write_design(path, design):
    write_atomic(path, dumps(design))
