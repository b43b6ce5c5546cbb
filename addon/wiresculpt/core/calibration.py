"""Calibration captures (Sec. 5.1-5.2): reading the CSV files with errors that name the line and
column, the fits (through the native module), custom materials and machine profiles as JSON, and
a small plot of each fit written as a PNG with numpy alone. Free of bpy: the add-on's operators,
the batch script and the tests all call it. Formats and rigs: docs/calibration.md.

CSV files (comma separated, one header row naming the columns in any order, extra columns
ignored, blank lines and lines starting with '#' skipped):

    cantilever   load_g, state, s_m, deflection_m   one row per (load, mark); state is
                 "loaded" or "unloaded"; s_m arc length from the clamp's edge (m); deflection_m
                 downward from the clamp's horizontal line (m)
    tilt         repeat, angle_deg                  one row per repeat
    spring-back  commanded_deg, measured_deg        one row per test bend
"""
import csv
import io
import json
import math
import os
import struct
import zlib

import numpy as np

from .. import native
from . import materials, sizes
from .files import write_atomic

CANTILEVER_COLUMNS = ("load_g", "state", "s_m", "deflection_m")
TILT_COLUMNS = ("repeat", "angle_deg")
SPRINGBACK_COLUMNS = ("commanded_deg", "measured_deg")
STATES = ("loaded", "unloaded")


class CaptureError(ValueError):
    """A malformed capture file: the message names the file's line (and column)."""

    def __init__(self, message, line=None, column=None):
        where = ""
        if line is not None:
            where = f"line {line}" + (f", column {column}" if column else "") + ": "
        super().__init__(where + message)
        self.line, self.column = line, column


# --- CSV ------------------------------------------------------------------------------------------

def _text(source):
    """The text of `source`: a path, or the CSV text itself when it contains a newline."""
    if isinstance(source, str) and "\n" in source:
        return source
    try:
        with open(source, encoding="utf-8-sig", newline="") as f:
            return f.read()
    except UnicodeDecodeError as exc:
        raise CaptureError(f"{os.path.basename(os.fspath(source))} is not a UTF-8 text (CSV) file") from exc


def read_table(source, columns):
    """Rows of a CSV with the named `columns`: {column: [str], "line": [int]}. CaptureError when a
    column is missing, a row has too few fields, or there are no data rows."""
    rows = list(csv.reader(io.StringIO(_text(source))))
    header, header_line, index = None, 0, {}
    out = {c: [] for c in columns}
    out["line"] = []
    for number, row in enumerate(rows, start=1):
        if not row or all(not cell.strip() for cell in row) or row[0].lstrip().startswith("#"):
            continue
        cells = [cell.strip() for cell in row]
        if header is None:
            header, header_line = [c.lower() for c in cells], number
            missing = [c for c in columns if c not in header]
            if missing:
                raise CaptureError(
                    f"missing column{'s' if len(missing) > 1 else ''} {', '.join(missing)} in the header "
                    f"(expected {', '.join(columns)}; found {', '.join(cells)})", header_line)
            index = {c: header.index(c) for c in columns}
            continue
        need = max(index.values()) + 1
        if len(cells) < need:
            absent = [c for c in columns if index[c] >= len(cells)]
            raise CaptureError(f"{len(cells)} field{'s' if len(cells) != 1 else ''}, but the header has "
                               f"{len(header)}; no value for {', '.join(absent)}", number)
        for c in columns:
            out[c].append(cells[index[c]])
        out["line"].append(number)
    if header is None:
        raise CaptureError(f"the file is empty: expected a header with {', '.join(columns)}")
    if not out["line"]:
        raise CaptureError("the file has a header but no data rows", header_line)
    return out


def _numbers(table, column, unit=""):
    values = []
    for text, line in zip(table[column], table["line"]):
        try:
            value = float(text)
        except ValueError:
            raise CaptureError(f"'{text}' is not a number" + (f" ({unit})" if unit else ""), line, column) from None
        if not math.isfinite(value):
            raise CaptureError(f"'{text}' is not a finite number", line, column)
        values.append(value)
    return values


def read_cantilever(source):
    """{"load_g", "loaded" (bools), "s", "deflection" (m), "lines"} of a cantilever capture."""
    t = read_table(source, CANTILEVER_COLUMNS)
    loaded = []
    for text, line in zip(t["state"], t["line"]):
        state = text.lower()
        if state not in STATES:
            raise CaptureError(f"state must be 'loaded' or 'unloaded', got '{text}'", line, "state")
        loaded.append(state == "loaded")
    load = _numbers(t, "load_g", "grams")
    for value, line in zip(load, t["line"]):
        if value < 0:
            raise CaptureError(f"a load of {value:g} g: loads are grams >= 0", line, "load_g")
    return {"load_g": load, "loaded": loaded, "s": _numbers(t, "s_m", "metres"),
            "deflection": _numbers(t, "deflection_m", "metres"), "lines": t["line"]}


def read_tilt(source):
    """{"repeat": [str], "angle_deg": [float], "lines"} of a tilt capture."""
    t = read_table(source, TILT_COLUMNS)
    return {"repeat": t["repeat"], "angle_deg": _numbers(t, "angle_deg", "degrees"), "lines": t["line"]}


def read_springback(source):
    """{"commanded_deg", "measured_deg", "lines"} of a spring-back table."""
    t = read_table(source, SPRINGBACK_COLUMNS)
    return {"commanded_deg": _numbers(t, "commanded_deg", "degrees"),
            "measured_deg": _numbers(t, "measured_deg", "degrees"), "lines": t["line"]}


# --- plausibility: numbers that parse but are probably not what was meant -------------------------

def cantilever_warnings(capture, overhang=0.30):
    """Sentences on a cantilever capture that fits but says little or was typed in other units:
    one loaded load only (k_b then rests on one frame, with nothing to check its linearity), and
    deflections larger than the wire could bend (millimetres typed as metres)."""
    out = []
    loads = sorted({g for g, loaded in zip(capture["load_g"], capture["loaded"]) if loaded and g > 0})
    if len(loads) < 2:
        out.append(f"only one load ({loads[0]:g} g) was captured: k_b rests on one frame; capture two or more "
                   "loads to see that the deflection grows in proportion" if loads else
                   "no loaded frame with a load above 0 g: k_b cannot be measured")
    for s, d, line in zip(capture["s"], capture["deflection"], capture["lines"]):
        if abs(d) > max(abs(s), 1e-9) or abs(d) > overhang:
            out.append(f"line {line}: a deflection of {d:g} m at {s:g} m along the wire is more than the wire can "
                       "bend there: were millimetres typed in the metres column deflection_m?")
            break
    return out


def tilt_warnings(angles_deg):
    """Tilt angles that look like radians (all below 1.6, the largest under 1.57 = 90° in radians)."""
    if angles_deg and max(angles_deg) < 1.6:
        a = max(angles_deg)
        return [f"the tilt angles are all below 1.6 (largest {a:g}): if they are radians, {a:g} rad is "
                f"{math.degrees(a):.1f}°; the column angle_deg takes degrees"]
    return []


def springback_warnings(commanded_deg):
    """Commanded angles no bender turns (beyond 180°) or all tiny (radians typed as degrees)."""
    out = []
    big = [c for c in commanded_deg if abs(c) > 180]
    if big:
        out.append(f"a commanded angle of {big[0]:g}° is beyond 180°, which a bend head cannot turn: "
                   "check the commanded_deg column")
    if commanded_deg and max(abs(c) for c in commanded_deg) < 3.2:
        out.append("every commanded angle is below 3.2: if they are radians, convert them to degrees")
    return out


# --- fits -------------------------------------------------------------------------------------------

def linear_density(material):
    """kg/m of a round wire of the material (0 when it has no density)."""
    if not material or not material.get("density"):
        return 0.0
    return material["density"] * math.pi * 0.25 * material["wire_diameter"] ** 2


def weight_density(material=None, include_weight=True):
    """kg/m of the wire's own weight the cantilever fit counts: the one rule of the Calibration
    panel and of fit_cantilever. With include_weight (the panel's *Wire's Own Weight*, ticked by
    default) the weight of `material` (the Material & Machine panel's; None: the steel preset, the
    panel's default material), else 0."""
    if not include_weight:
        return 0.0
    return linear_density(materials.PRESETS["steel"] if material is None else material)


def fit_cantilever(source, overhang=0.30, linear_density=None, plastic_tolerance=0.001, material=None,
                   include_weight=True):
    """k_b (Eq. 13) and the plastic limit of a cantilever capture (a path or CSV text). The wire's
    own weight is counted as the Calibration panel counts it (weight_density(material,
    include_weight)) unless `linear_density` (kg/m) is given."""
    if linear_density is None:
        linear_density = weight_density(material, include_weight)
    c = read_cantilever(source)
    singles = {}
    for load, loaded, line in zip(c["load_g"], c["loaded"], c["lines"]):
        singles.setdefault((load, loaded), []).append(line)
    for (load, loaded), lines in singles.items():
        if len(lines) < 3:
            state = "loaded" if loaded else "unloaded"
            raise CaptureError(f"the {load:g} g {state} frame has {len(lines)} mark{'s' if len(lines) > 1 else ''}; "
                               "at least 3 points along the wire are needed", lines[0])
    fit = native.fit_cantilever(c["load_g"], c["loaded"], c["s"], c["deflection"], c["lines"],
                                overhang=overhang, linear_density=linear_density,
                                plastic_tolerance=plastic_tolerance)
    fit.update(overhang=overhang, linear_density=linear_density, plastic_tolerance=plastic_tolerance,
               warnings=cantilever_warnings(c, overhang))
    return fit


def fit_friction(source):
    t = read_tilt(source)
    fit = native.fit_friction(t["angle_deg"], t["lines"])
    fit["warnings"] = tilt_warnings(t["angle_deg"])
    return fit


def fit_springback(source):
    t = read_springback(source)
    fit = native.fit_springback(t["commanded_deg"], t["measured_deg"], t["lines"])
    fit["warnings"] = springback_warnings(t["commanded_deg"])
    return fit


# --- materials as JSON ------------------------------------------------------------------------------

MATERIAL_FORMAT = "wiresculpt-material"


def validate_material(material, where="material"):
    """The material with float fields, or ValueError naming the field (materials.FIELDS bounds)."""
    if not isinstance(material, dict):
        raise ValueError(f"{where}: expected an object with {', '.join(materials.REQUIRED)}")
    name = str(material.get("name", "")).strip()
    if not name:
        raise ValueError(f"{where}: a material needs a name")
    out = {"name": name}
    for key, (unit, low, high) in materials.FIELDS.items():
        if key not in material:
            if key in materials.REQUIRED:
                raise ValueError(f"{where}: '{key}' ({unit}) is missing")
            continue
        value = material[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ValueError(f"{where}: '{key}' must be a number ({unit}), got {value!r}")
        if not low < value <= high:
            raise ValueError(f"{where}: '{key}' = {value:g} is outside ({low:g}, {high:g}] {unit}".rstrip())
        out[key] = float(value)
    if isinstance(material.get("calibration"), dict):
        out["calibration"] = material["calibration"]
    return out


def material_file_name(name):
    safe = "".join(ch if ch.isalnum() or ch in "-_." else "-" for ch in name.strip()).strip("-.")
    return (safe or "material") + ".json"


def save_material(material, folder):
    """Writes the material to folder/materials/<name>.json (atomically); returns the path."""
    m = validate_material(material)
    if m["name"].lower() in materials.PRESETS:
        raise ValueError(f"'{m['name']}' is a preset's name: give the calibrated material its own name")
    path = os.path.join(folder, "materials", material_file_name(m["name"]))
    write_atomic(path, json.dumps({"format": MATERIAL_FORMAT, "version": 1, **m}, indent=2) + "\n")
    return path


def load_material(path):
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{os.path.basename(path)}: not JSON (line {exc.lineno}: {exc.msg})") from None
    return validate_material(data, os.path.basename(path))


def list_materials(folder=None):
    """{name: material}: the presets (Table 1), then the custom materials saved in `folder`.
    Unreadable files are skipped and reported in the "errors" list of the second value."""
    out = {name: dict(p) for name, p in materials.PRESETS.items()}
    errors = []
    directory = os.path.join(folder, "materials") if folder else None
    if directory and os.path.isdir(directory):
        for entry in sorted(os.listdir(directory)):
            if not entry.endswith(".json"):
                continue
            try:
                m = load_material(os.path.join(directory, entry))
            except (OSError, ValueError) as exc:
                errors.append(str(exc))
                continue
            if m["name"] not in out:
                out[m["name"]] = m
    return out, errors


def calibrated_material(name, base, cantilever=None, friction=None):
    """A new material named `name` from `base` (diameter, density and anything not calibrated)
    with the cantilever fit's k_b and plastic torque and the tilt fit's friction."""
    m = {k: base[k] for k in ("wire_diameter", "bending_stiffness", "max_torque", "friction", "density") if k in base}
    m["name"] = name
    note = {}
    if cantilever:
        m["bending_stiffness"] = cantilever["bending_stiffness"]
        if cantilever.get("plastic_found") and cantilever.get("max_torque", 0) > 0:
            m["max_torque"] = cantilever["max_torque"]
        note["cantilever"] = {k: cantilever[k] for k in (
            "position_rms", "torque_rms", "plastic_load_g", "plastic_reached", "lever_arm", "frames_used",
            "overhang") if k in cantilever}
    if friction:
        m["friction"] = friction["friction"]
        note["tilt"] = {k: friction[k] for k in ("spread", "repeats", "mean_angle_deg")}
    if note:
        m["calibration"] = note
    return validate_material(m)


# --- machine profiles as JSON -----------------------------------------------------------------------

PROFILE_FORMAT = "wiresculpt-machine-profile"
# The keys of the native profile dict (bind_fab's default_machine_profile), its edge units.
PROFILE_KEYS = ("name", "min_segment", "max_bend_deg", "min_bend_deg", "max_commanded_deg",
                "left_is_positive", "springback_a", "springback_b_deg", "feed_speed_mm_s",
                "bend_speed_deg_s", "seconds_per_bend", "feed_axis", "bend_axis", "pin_axis",
                "feed_units_per_mm", "bend_units_per_deg", "pin_travel", "pin_swing_deg", "baud", "data_bits",
                "stop_bits", "parity", "flow_control")


def default_profile():
    """The DIWire-class default (l_min 1.5 cm, 1 deg minimum bend) from the native module."""
    return dict(native.default_machine_profile())


def machine_dict(profile):
    """The keys the native functions take (the fit's statistics and file markers dropped)."""
    return {k: profile[k] for k in PROFILE_KEYS if k in profile}


def with_springback(profile, fit, source=""):
    out = dict(profile)
    out["springback_a"] = fit["springback_a"]
    out["springback_b_deg"] = fit["springback_b_deg"]
    out["springback_fit"] = {"rms_deg": fit["rms_deg"], "max_residual_deg": fit["max_residual_deg"],
                             "samples": fit["samples"], "source": os.path.basename(source) if source else ""}
    return out


FILE_MARKERS = ("format", "version")  # written by save_profile, dropped by load_profile
# Checked here, not by the native module: the wire stock's length (m, default core.sizes.STOCK_LENGTH)
# and the paper the print templates are tiled onto ("A4", the default, or "Letter"; fab/tiles.py).
# The overlap allowance of a closed wire (m, default 0, at most CLOSED_OVERLAP_MAX): extra straight
# wire fed past the cut so the loop's ends overlap (fab/export.py, docs/machine-protocol.md).
PYTHON_KEYS = ("stock_length", "paper", "closed_overlap")
CLOSED_OVERLAP_MAX = 0.2
PAPERS = ("A4", "Letter")
PROFILE_FILE_KEYS = FILE_MARKERS + ("springback_fit",) + PYTHON_KEYS  # not native machine settings


def closed_overlap(profile, where="machine profile"):
    """m: the profile's overlap allowance for closed wires (0 when absent); ValueError naming the
    key when it is not a length between 0 and CLOSED_OVERLAP_MAX."""
    value = (profile or {}).get("closed_overlap", 0.0)
    if (isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value)
            or not 0 <= value <= CLOSED_OVERLAP_MAX):
        raise ValueError(f"{where}: closed_overlap must be a length in metres between 0 and {CLOSED_OVERLAP_MAX:g} "
                         f"(e.g. 0.02 for 20 mm of overlap), got {value!r}")
    return float(value)


def validate_profile(profile, where="machine profile"):
    """The profile, checked by the native module: ValueError naming the key at fault (an unknown
    key, a wrong type, a value out of range), prefixed with `where`."""
    if not isinstance(profile, dict):
        raise ValueError(f"{where}: expected a JSON object")
    stock = profile.get("stock_length", sizes.STOCK_LENGTH)
    if isinstance(stock, bool) or not isinstance(stock, (int, float)) or not 0 < stock < 100:
        raise ValueError(f"{where}: stock_length must be a length in metres between 0 and 100, got {stock!r}")
    closed_overlap(profile, where)
    paper = profile.get("paper", "A4")
    if not isinstance(paper, str) or paper.upper() not in (p.upper() for p in PAPERS):
        raise ValueError(f"{where}: paper must be one of {', '.join(PAPERS)}, got {paper!r}")
    try:
        native.validate_machine_profile({k: v for k, v in profile.items() if k not in PROFILE_FILE_KEYS})
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None
    return profile


def save_profile(profile, path):
    p = {k: v for k, v in profile.items() if k not in FILE_MARKERS}
    validate_profile(p)
    write_atomic(path, json.dumps({"format": PROFILE_FORMAT, "version": 1, **p}, indent=2) + "\n")
    return path


def load_profile(path):
    """The default profile updated by the file's keys (a file may give only some). ValueError
    starting with the file's name when it is not JSON, not an object, or a key is at fault."""
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{os.path.basename(path)}: not JSON (line {exc.lineno}: {exc.msg})") from None
    except UnicodeDecodeError:
        raise ValueError(f"{os.path.basename(path)}: not a UTF-8 text (JSON) file") from None
    if not isinstance(data, dict):
        raise ValueError(f"{os.path.basename(path)}: expected a JSON object")
    profile = default_profile()
    profile.update({k: v for k, v in data.items() if k not in FILE_MARKERS})
    return validate_profile(profile, os.path.basename(path))


# --- plots (PNG with numpy alone) -------------------------------------------------------------------

BACKGROUND = (255, 255, 255)
AXES = (90, 90, 90)
GRID = (228, 228, 228)
PALETTE = [(31, 119, 180), (255, 127, 14), (44, 160, 44), (214, 39, 40), (148, 103, 189),
           (140, 86, 75), (227, 119, 194), (127, 127, 127), (188, 189, 34), (23, 190, 207)]
GREY = (185, 185, 185)


def png_bytes(rgb):
    """An (h, w, 3) uint8 array as PNG bytes (8-bit RGB, no interlace)."""
    rgb = np.ascontiguousarray(rgb, dtype=np.uint8)
    h, w, _ = rgb.shape
    raw = np.concatenate([np.zeros((h, 1), np.uint8), rgb.reshape(h, w * 3)], axis=1).tobytes()

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


class Canvas:
    """A small plot: data coordinates mapped into a margin box; lines, dots, a grid."""

    def __init__(self, xlim, ylim, width=480, height=320, margin=24):
        self.img = np.empty((height, width, 3), np.uint8)
        self.img[:] = BACKGROUND
        self.w, self.h, self.m = width, height, margin
        (x0, x1), (y0, y1) = xlim, ylim
        self.x0, self.x1 = x0, x1 if x1 > x0 else x0 + 1.0
        self.y0, self.y1 = y0, y1 if y1 > y0 else y0 + 1.0
        for k in range(1, 5):
            self.line([self.x0 + k * (self.x1 - self.x0) / 5] * 2, [self.y0, self.y1], GRID)
            self.line([self.x0, self.x1], [self.y0 + k * (self.y1 - self.y0) / 5] * 2, GRID)
        self.line([self.x0, self.x1, self.x1, self.x0, self.x0], [self.y0, self.y0, self.y1, self.y1, self.y0], AXES)

    def _px(self, x, y):
        px = self.m + (np.asarray(x, float) - self.x0) / (self.x1 - self.x0) * (self.w - 2 * self.m)
        py = self.h - self.m - (np.asarray(y, float) - self.y0) / (self.y1 - self.y0) * (self.h - 2 * self.m)
        return px, py

    def _plot(self, px, py, colour, r=0):
        ix, iy = np.rint(px).astype(int), np.rint(py).astype(int)
        for dx in range(-r, r + 1):
            for dy in range(-r, r + 1):
                jx, jy = ix + dx, iy + dy
                ok = (jx >= 0) & (jx < self.w) & (jy >= 0) & (jy < self.h)
                self.img[jy[ok], jx[ok]] = colour

    def line(self, x, y, colour, width=1):
        px, py = self._px(x, y)
        for a in range(len(px) - 1):
            n = int(max(abs(px[a + 1] - px[a]), abs(py[a + 1] - py[a]))) + 2
            t = np.linspace(0.0, 1.0, n)
            self._plot(px[a] + t * (px[a + 1] - px[a]), py[a] + t * (py[a + 1] - py[a]), colour, width // 2)

    def dots(self, x, y, colour, r=2):
        px, py = self._px(x, y)
        self._plot(px, py, colour, r)

    def png(self):
        return png_bytes(self.img)


def _limits(values, pad=0.05):
    v = np.asarray([x for x in values if math.isfinite(x)] or [0.0, 1.0], float)
    lo, hi = float(v.min()), float(v.max())
    span = hi - lo or max(abs(hi), 1.0)
    return lo - pad * span, hi + pad * span


def plot_cantilever(fit):
    """Deflection (down) against s: measured marks (dots) and the fitted model (lines), one colour
    per used load; unused frames (beyond the plastic limit, unloaded) grey."""
    frames = fit["frames"]
    s_all = [0.0] + [s for f in frames for s in f["s"]]
    w_all = [0.0] + [w for f in frames for w in f["deflection"]] + [w for f in frames for w in f["simulated"]]
    canvas = Canvas(_limits(s_all), _limits([-w for w in w_all]))
    colour = 0
    for f in frames:
        s, w = np.asarray(f["s"]), np.asarray(f["deflection"])
        if f["used"]:
            c = PALETTE[colour % len(PALETTE)]
            colour += 1
            canvas.line(np.concatenate([[0.0], s]), -np.concatenate([[0.0], f["simulated"]]), c, width=2)
            canvas.dots(s, -w, c, r=2)
        else:
            canvas.dots(s, -w, GREY, r=1)
    return canvas.png()


def plot_springback(table, fit):
    c = np.abs(table["commanded_deg"])
    m = np.abs(table["measured_deg"])
    canvas = Canvas(_limits(np.concatenate([[0.0], c])), _limits(np.concatenate([[0.0], m])))
    xs = np.array([0.0, float(c.max())])
    canvas.line(xs, fit["springback_a"] * xs + fit["springback_b_deg"], PALETTE[3], width=2)
    canvas.line([0.0, float(c.max())], [0.0, float(c.max())], GREY)
    canvas.dots(c, m, PALETTE[0], r=2)
    return canvas.png()


def plot_friction(table, fit):
    mu = np.tan(np.radians(table["angle_deg"]))
    k = np.arange(1, len(mu) + 1, dtype=float)
    canvas = Canvas((0.0, len(mu) + 1.0), _limits(np.concatenate([mu, [fit["friction"]]]), pad=0.3))
    canvas.line([0.0, len(mu) + 1.0], [fit["friction"]] * 2, PALETTE[3], width=2)
    for off in (-1, 1):
        canvas.line([0.0, len(mu) + 1.0], [fit["friction"] + off * fit["spread"]] * 2, GREY)
    canvas.dots(k, mu, PALETTE[0], r=3)
    return canvas.png()


def write_plot(path, png):
    write_atomic(path, png)
    return path
