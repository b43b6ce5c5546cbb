"""The compiled solver, or the reason it cannot be loaded: the one door to `_wiresculpt`.

Everything else in the add-on reaches the native module through the wrappers below, one per
function the module registers (native/python/module.cpp), in the potpourri3d manner: each checks
the shapes and types of its arrays and raises ValueError before anything crosses into C++ (a bad
array is a ValueError naming it, never a crash inside the module), then calls the module through
require(). When the module is missing, LOAD_ERROR holds a sentence the panel shows to the user
instead of failing to register, and every wrapper raises RuntimeError with it.

The results are the module's dicts, in the design document's own key names (docs/formats.md):
the stages copy them without renaming.
"""
import ctypes
import importlib.machinery
import os
import re
import struct
import sys
from collections.abc import Iterator

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def built_for():
    """The Pythons the compiled modules beside this file were built for, e.g. ["3.11"], from their
    file names (_wiresculpt.cpython-311-x86_64-linux-gnu.so)."""
    try:
        names = os.listdir(HERE)
    except OSError:
        return []
    try:  # the extension zip of Windows (and macOS) carries the module as wheels in wheels/
        names += os.listdir(os.path.join(HERE, "wheels"))
    except OSError:
        pass
    # _wiresculpt.cpython-311-x86_64-linux-gnu.so, _wiresculpt.cp311-win_amd64.pyd, ...-cp311-cp311-win_amd64.whl
    tags = (re.match(r"(?:_wiresculpt\.cpython-|_wiresculpt\.cp|wiresculpt_solver-[^-]+-cp)(\d)(\d+)", n) for n in names)
    return sorted({f"{t.group(1)}.{t.group(2)}" for t in tags if t}, key=lambda v: tuple(map(int, v.split("."))))


def platform_of(name):
    """The platform a module or wheel file is built for, from its name; None for other files."""
    if not re.match(r"(_wiresculpt\.|wiresculpt_solver-)", name):
        return None
    if re.search(r"win_amd64|\.pyd$", name):
        return "Windows x64"
    if re.search(r"darwin|macosx", name):
        return "macOS"
    if re.search(r"linux", name):
        return "Linux x86_64"
    return None


def running_platform():
    """This computer's platform, named as platform_of names them."""
    if sys.platform == "win32":
        return "Windows x64"
    if sys.platform == "darwin":
        return "macOS"
    return "Linux x86_64"


def built_platforms(folder=HERE):
    """The platforms of the modules beside this file and of the wheels in wheels/, e.g. ["Linux x86_64"]."""
    names = []
    for where in (folder, os.path.join(folder, "wheels")):
        try:
            names += os.listdir(where)
        except OSError:
            pass
    return sorted({p for p in map(platform_of, names) if p})


def host_name():
    """ "Blender 4.0.2" inside Blender (bpy already imported), else "this Python"."""
    bpy = sys.modules.get("bpy")
    version = getattr(getattr(bpy, "app", None), "version_string", None)
    return f"Blender {version}" if version else "this Python"


# The Blender releases whose own builds embed each Python (a Linux distribution's Blender uses the
# system's Python instead: Debian 12's Blender 3.4 runs 3.11). 3.11 and 3.13 were checked against
# the Python tags of PyPI's bpy wheels (cp311 for 4.2.0 to 5.0.1, cp313 for 5.1.0 to 5.3.0); 3.10
# for 3.1 to 4.0 and 3.11 for 4.1 from Blender's release notes. No Blender release embeds 3.12.
BLENDERS = {"3.10": "Blender 3.4 to 4.0", "3.11": "Blender 4.1 to 5.0", "3.13": "Blender 5.1 and later"}


def _listed(items):
    """ "a", "a and b", "a, b and c"."""
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


# Why the solver did not load, as a code (load_cause); explain_load_error words it.
OTHER_PLATFORM = "other_platform"  # the zip has the solver for other platforms only
OTHER_PYTHON = "other_python"  # the zip has the solver for other Pythons only
MISSING_LIBRARY = "missing_library"  # a shared library the module needs cannot be found or loaded
NOT_BUILT = "not_built"  # no module for any Python
OTHER = "other"  # something else: the import error's own text is said


def elf_dependencies(path):
    """(the DT_NEEDED names, the DT_RUNPATH / DT_RPATH entries) of the 64-bit little-endian ELF
    shared object at `path`, read from its dynamic section; None when it is not one or cannot be
    read."""
    try:
        with open(path, "rb") as f:
            data = f.read()
        if data[:4] != b"\x7fELF" or data[4] != 2 or data[5] != 1:  # ELFCLASS64, ELFDATA2LSB
            return None
        phoff, = struct.unpack_from("<Q", data, 0x20)
        phentsize, phnum = struct.unpack_from("<HH", data, 0x36)
        loads, dynamic = [], None
        for i in range(phnum):
            kind, _flags, offset, vaddr, _paddr, filesz = struct.unpack_from("<IIQQQQ", data, phoff + i * phentsize)
            if kind == 1:  # PT_LOAD
                loads.append((vaddr, offset, filesz))
            elif kind == 2:  # PT_DYNAMIC
                dynamic = (offset, filesz)
        if dynamic is None:
            return [], []
        entries = []
        for k in range(dynamic[1] // 16):
            tag, value = struct.unpack_from("<qQ", data, dynamic[0] + 16 * k)
            if tag == 0:  # DT_NULL
                break
            entries.append((tag, value))
        strtab = next(v for t, v in entries if t == 5)  # DT_STRTAB, an address: its offset in the file
        table = next(strtab - vaddr + offset for vaddr, offset, size in loads if vaddr <= strtab < vaddr + size)

        def string(index):
            return data[table + index:data.index(b"\0", table + index)].decode("utf-8", "replace")
        return ([string(v) for t, v in entries if t == 1],  # DT_NEEDED
                [string(v) for t, v in entries if t in (15, 29)])  # DT_RPATH, DT_RUNPATH
    except (OSError, struct.error, StopIteration, ValueError):
        return None


def missing_library(path):
    """The name of the first shared library the ELF object at `path` needs that cannot be found or
    loaded (looked for in its run path, `$ORIGIN` expanded, else by the system's loader through
    ctypes), following a bundled library's own needs; None when each one loads or `path` cannot be
    read. The loader's error text is not read: which library fails is found by trying each."""
    found = elf_dependencies(path)
    if found is None:
        return None
    needed, runpath = found
    origin = os.path.dirname(os.path.abspath(path))
    folders = [d.replace("${ORIGIN}", origin).replace("$ORIGIN", origin)
               for entry in runpath for d in entry.split(":") if d]
    for name in needed:
        local = next((os.path.join(d, name) for d in folders if os.path.isfile(os.path.join(d, name))), None)
        try:
            ctypes.CDLL(local or name)
        except OSError:
            return (missing_library(local) or name) if local else name
    return None


def module_file():
    """The path of the compiled module beside this file for the running Python (its extension
    suffixes), or None when there is none."""
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        path = os.path.join(HERE, "_wiresculpt" + suffix)
        if os.path.isfile(path):
            return path
    return None


def load_cause(builds, python, missing=None, platforms=None, running=None):
    """(code, figures) of why the solver did not load: OTHER_PLATFORM ({"platforms", "running"})
    when the zip's modules are all for `platforms` other than the `running` one, OTHER_PYTHON
    ({"builds", "python"}) when the zip's `builds` lack the running `python`, MISSING_LIBRARY
    ({"library"}) when `missing` names a library the module cannot load, NOT_BUILT when there are
    no builds, else OTHER."""
    if platforms and running not in platforms:
        return OTHER_PLATFORM, {"platforms": list(platforms), "running": running}
    if builds and python not in builds:
        return OTHER_PYTHON, {"builds": list(builds), "python": python}
    if missing:
        return MISSING_LIBRARY, {"library": missing}
    if not builds:
        return NOT_BUILT, {}
    return OTHER, {}


def explain_load_error(exc, builds, python=None, host=None, missing=None, platforms=None, running=None):
    """One sentence saying why the solver did not load and what to do: the platforms the zip
    carries the solver for against this computer's, the Pythons against the one running (with the
    Blenders that embed them), or the shared library `missing` that cannot be loaded
    (missing_library), from load_cause's code."""
    python = python or f"{sys.version_info[0]}.{sys.version_info[1]}"
    host = host or host_name()
    running = running or running_platform()
    code, figures = load_cause(builds, python, missing, platforms, running)
    if code == OTHER_PLATFORM:
        return (f"The wiresculpt solver did not load: this zip has the solver for {_listed(figures['platforms'])}; "
                f"{host} runs on {running}: install the zip made for {running} (scripts/package writes one "
                "per platform), or build from source with scripts/package on that computer.")
    if code == OTHER_PYTHON:
        blenders = [BLENDERS[b] for b in builds if b in BLENDERS]
        where = f"a Blender whose Python is {' or '.join(builds)}" + (f" ({', '.join(blenders)})" if blenders else "")
        return (f"The wiresculpt solver did not load: this zip has the solver for Python {_listed(builds)}; "
                f"{host} uses {python}: install it in {where}, or build the zip from source with "
                f"scripts/package on a machine that has Python {python} and its headers.")
    if code == MISSING_LIBRARY:
        return (f"The wiresculpt solver did not load: the library {figures['library']} is missing. The "
                f"packaged zip carries it in libs/ beside the module: install the zip again (Preferences > "
                "Add-ons > Install, or Get Extensions > Install from Disk for the extension), or install it on "
                "the system, or build from source with scripts/package.")
    if code == NOT_BUILT:
        return ("The wiresculpt solver (_wiresculpt) is not built: build it with scripts/setup, or "
                "install the packaged zip (scripts/package).")
    return f"The wiresculpt solver (_wiresculpt) did not load in {host}: {exc}"


try:
    from . import _wiresculpt as module
    LOAD_ERROR = ""
except ImportError as exc:  # not built, built for another Python or platform, or a library missing
    try:  # the extension's wheel (blender_manifest.toml "wheels"), which Blender installs for it
        from wiresculpt_solver import _wiresculpt as module
        LOAD_ERROR = ""
    except ImportError:
        module = None
        LOAD_ERROR = explain_load_error(exc, built_for(), missing=missing_library(module_file()) if module_file() else None,
                                        platforms=built_platforms())


class _NeverRaised(Exception):
    """Stands for _wiresculpt.Cancelled when the module is missing (nothing can raise it then)."""


# Raised by the module's stages when their progress callback returns False.
Cancelled = module.Cancelled if module is not None else _NeverRaised


def available():
    return module is not None


def require():
    """The loaded module; RuntimeError with the reason when it is missing."""
    if module is None:
        raise RuntimeError(LOAD_ERROR)
    return module


# --- argument checks (the module's own wording, so a message reads the same from either side) ----

def as_points(array, what, columns=3):
    """A C-contiguous float64 (n, columns) array, or ValueError naming `what`."""
    expected = f"{what}: expected an (n, {columns}) array of numbers, got"
    a = np.asarray(array)
    if a.size and a.dtype.kind not in "iuf":
        raise ValueError(f"{expected} an array of {a.dtype}")
    if a.ndim != 2 or a.shape[1] != columns:
        raise ValueError(f"{expected} shape {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float64)


def as_triangles(array, vertex_count, what="faces"):
    """A C-contiguous int32 (n, 3) array of valid vertex indices, or ValueError."""
    a = np.asarray(array)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{what} must be an array of shape (n, 3), got {a.shape}")
    if a.size and not np.issubdtype(a.dtype, np.integer):
        raise ValueError(f"{what} must hold integer vertex indices, got {a.dtype}")
    if a.size and (a.min() < 0 or a.max() >= vertex_count):
        bad = int(np.argmax((a < 0).any(axis=1) | (a >= vertex_count).any(axis=1)))
        raise ValueError(f"triangle {bad} of {what} refers to a vertex outside 0..{vertex_count - 1}")
    return np.ascontiguousarray(a, dtype=np.int32)


def _list(value, what):
    """`value` itself when it is a list, tuple or 1-D array, else ValueError in the module's words."""
    if isinstance(value, (str, bytes, dict)) or not hasattr(value, "__len__"):
        raise ValueError(f"{what}: expected a list, got {type(value).__name__}")
    return value


def _point_item(item, i, what, key, columns):
    """`item` with its `key` (when it is a dict holding one) made an (n, columns) float64 array."""
    if isinstance(item, dict) and key in item:
        return dict(item, **{key: as_points(item[key], f"{what}[{i}]['{key}']", columns)})
    return item


def _with_points(items, what, key, columns=3):
    """A list of dicts whose `key` (when present) is made an (n, columns) float64 array."""
    return [_point_item(item, i, what, key, columns) for i, item in enumerate(_list(items, what))]


def _iter_with_points(items, what, key, columns=3):
    """_with_points of an iterator, one item at a time as it is read."""
    return (_point_item(item, i, what, key, columns) for i, item in enumerate(items))


# --- geometry and slicing --------------------------------------------------------------------------

def plane_frame(normal):
    """(n, u, v) of a plane with this normal, float64 (3,) arrays, the solver's own frame
    (Plane::make): n unit, u the world axis least aligned with n projected into the plane,
    v = n x u. ValueError for a zero or non-finite normal."""
    n = np.asarray(normal, dtype=np.float64)
    if n.shape != (3,):
        raise ValueError(f"normal: expected 3 numbers, got shape {n.shape}")
    return require().plane_frame(n)


def largest_box_side(polylines):
    """The largest side of the bounding box of all points of `polylines` ((n, 3) arrays, metres):
    core.design.model_size's number in one native call (0.0 without points)."""
    return require().largest_box_side(_list(polylines, "polylines"))


def slice_mesh(vertices, faces, planes, weld_tolerance=-1.0):
    """Slice a triangle mesh by planes.

    vertices: (#V, 3) metres; faces: (#F, 3) indices; planes: [(name, origin, normal)].
    Returns {"contours": [per plane: [{"points", "closed", "length"}]], "mesh": statistics}.
    """
    V = as_points(vertices, "vertices")
    F = as_triangles(faces, len(V))
    specs = []
    for name, origin, normal in planes:
        specs.append((str(name), tuple(float(x) for x in origin), tuple(float(x) for x in normal)))
    return require().slice_mesh(V, F, specs, float(weld_tolerance))


# --- the solver's stages ---------------------------------------------------------------------------

def layering(wires, settings=None, progress=None):
    """Crossings, hooks and assembly order (Sec. 4.1-4.2). wires: [{"name", "origin", "normal",
    "points" (n, 3) m, "closed"}]; settings and the result: see _wiresculpt.layering. The network's
    crossings come back with the design's keys (`contour_vertices`, `metric`)."""
    return require().layering(_with_points(wires, "wires", "points"), {} if settings is None else settings, progress)


def check_assembly(wires, hooks, steps, settings=None, progress=None):
    """Eq. 1 for every prefix of `steps` with `hooks` (one per crossing of the wires' network)."""
    return require().check_assembly(_with_points(wires, "wires", "points"), _list(hooks, "hooks"),
                                    _list(steps, "steps"), {} if settings is None else settings, progress)


def optimize_target_shape(points, closed, crossings, options=None, progress=None):
    """One wire's target shape in its plane frame (Sec. 4.3). points: (n, 2) m."""
    return require().optimize_target_shape(as_points(points, "points", 2), closed, _list(crossings, "crossings"),
                                           {} if options is None else options, progress)


def optimize_target_shapes(problems, progress=None, threads=2):
    """optimize_target_shape of each problem ({"points", "closed", "crossings", "options", and
    optionally "plane": {"origin", "u", "v"}}), on up to `threads` (1 or 2) native threads: the
    results in the problems' order, each as if solved alone (a problem with a plane also gets
    "target", its points in space as a list of [x, y, z], and "length", metres).
    `problems`: a list, or an iterator read one problem at a time (with 2 threads the other thread
    solves the first while the iterator makes the next: a generator that prepares each wire)."""
    if isinstance(problems, Iterator):
        return require().optimize_target_shapes(_iter_with_points(problems, "problems", "points", 2), progress,
                                                threads)
    return require().optimize_target_shapes(_with_points(problems, "problems", "points", 2), progress, threads)


def forces_and_rest(wires, crossings, steps, material, settings=None, progress=None):
    """Forces, cuts, rest shapes and load capacity (Sec. 4.4), in the design's key names.
    wires: [{"name", "origin", "normal", "target" (n, 3) m, "closed", "cut"}]."""
    return require().forces_and_rest(_with_points(wires, "wires", "target"), _list(crossings, "crossings"),
                                     _list(steps, "steps"), material, {} if settings is None else settings,
                                     progress)


# The causes of structure3d's result (native/include/wiresculpt/structure3d.hpp, Structure3dCause).
STRUCTURE3D_CAUSES = ("none", "mechanism", "no_equilibrium", "moved_away", "iteration_cap")


def structure3d(wires, ties=None, loads=None, clamps=None, pins=None, table=None, options=None, progress=None):
    """The 3D equilibrium of the assembled structure (discrete elastic rods tied at their crossings).
    wires: [{"name", "rest" (n, 3) m, "start" (n, 3) m, "normal" (3)}]; nodes are [wire, vertex];
    ties: [{"a", "b", "offset"}]; loads: [{"node", "force" N}]; clamps, pins: [node];
    table: {"z0", "nodes", "stiffness", "smoothing", "hold_horizontal"} or None.
    Returns {"converged", "cause" (STRUCTURE3D_CAUSES), "message", "residual", "iterations",
    "wires": [{"points" (n, 3), "angles", "max_distance", "max_distance_vertex"}],
    "tie_forces" (force on node a, N), "clamps", "pins", "table": [{"node", "force", "moment"}]}."""
    items = [_point_item(_point_item(item, i, "wires", "rest", 3), i, "wires", "start", 3)
             for i, item in enumerate(_list(wires, "wires"))]
    return require().structure3d(items, ties, loads, clamps, pins, table, options, progress)


def structure3d_tie_response(wires, ties, clamps, cases, options=None):
    """The stress-free structure's linear response (each wire's rest is its start): for each load
    case (a list of {"node", "force" N}), the force each tie carries on its node a (N), as
    structure3d's `tie_forces` would in the linear range. wires, ties, clamps as structure3d's."""
    items = [_point_item(_point_item(item, i, "wires", "rest", 3), i, "wires", "start", 3)
             for i, item in enumerate(_list(wires, "wires"))]
    return require().structure3d_tie_response(items, ties, clamps, cases, options)


def pyramid_fit(force, pyramid):
    """Whether `force` (3) lies in the cone of the four rows of `pyramid` (4, 3), e.g. a crossing's
    contact pyramid: {"coefficients", "distance" N, "inside"}."""
    return require().pyramid_fit(force, as_points(pyramid, "pyramid"))


# --- fabrication -----------------------------------------------------------------------------------

def default_machine_profile():
    """The default machine profile (edge units: m, deg, mm/s, deg/s)."""
    return require().default_machine_profile()


def validate_machine_profile(profile):
    """The profile checked, defaults filled in; ValueError names the key at fault."""
    return require().validate_machine_profile(profile)


def make_bend_program(points, profile=None, machine=None):
    """Feeds and bends that make a 2D wire; points (n, 2) m from the cut. `machine`: the profile
    whose spring-back line models the real machine for "predicted" and "preview_distance" (None:
    `profile`)."""
    return require().make_bend_program(as_points(points, "points", 2), {} if profile is None else profile,
                                       machine)


def bend_program_problems(points, profile=None):
    """Everything that keeps a 2D wire from being bent (make_bend_program's refusals, all listed)."""
    return require().bend_program_problems(as_points(points, "points", 2), {} if profile is None else profile)


def write_svg(path, wires, sheet=None, options=None):
    """1:1 SVG template; wires [{"name", "points" (n, 2) m, ...}]. Returns the text."""
    return require().write_svg(path, _with_points(wires, "wires", "points", 2), sheet,
                               {} if options is None else options)


def write_dxf(path, wires, labels=False, layout="as_given", gap_mm=20.0):
    """DXF R2000 in mm, one layer and one LWPOLYLINE per wire; layout "as_given",
    "start_at_origin" or "side_by_side" (gap_mm apart). Returns the text."""
    return require().write_dxf(path, _with_points(wires, "wires", "points", 2), labels, layout, gap_mm)


def write_machine_svg(path, wire, stroke_mm=0.5):
    """The machine SVG of one wire {"name", "points" (n, 2) m}: one path in mm from its first
    point. Returns the text."""
    if isinstance(wire, dict) and "points" in wire:
        wire = dict(wire, points=as_points(wire["points"], "wire['points']", 2))
    return require().write_machine_svg(path, wire, stroke_mm)


def write_gcode(path, points, profile=None, wire_name="", material="", sync_each_step=True):
    """GRBL G-code for one wire; points (n, 2) m from the cut. Returns the text."""
    return require().write_gcode(path, as_points(points, "points", 2), {} if profile is None else profile,
                                 wire_name, material, sync_each_step)


def write_bend_table(path, points, profile=None):
    """CSV step,feed_mm,bend_deg,commanded_deg. Returns the text."""
    return require().write_bend_table(path, as_points(points, "points", 2), {} if profile is None else profile)


def write_file_atomic(path, text):
    """Temporary file in the same folder, then rename."""
    return require().write_file_atomic(str(path), text)


def stream_lines(gcode):
    """The lines of G-code text to stream (comments and blank lines removed)."""
    return require().stream_lines(gcode)


def list_ports():
    """Serial ports: [{"name", "description"}]."""
    return require().list_ports()


def stream_control():
    """A fresh StreamControl (pause / resume / abort a running stream_program from another thread)."""
    return require().StreamControl()


def open_link(port, profile=None):
    """An open SerialLink on `port` with the profile's serial settings (write, read, close), kept
    between commands and usable as stream_program's port. ValueError naming the port."""
    return require().SerialLink(port, {} if profile is None else profile)


def stream_program(port, lines, profile=None, state=None, progress=None, control=None, dry_run=False,
                   response_timeout=30.0, settle=2.0):
    """Streams G-code lines to a GRBL bender; `state["next_line"]` resumes; `port` is a port's name
    (opened, settled, closed) or an open SerialLink (open_link). See _wiresculpt."""
    return require().stream_program(port, _list(lines, "lines"), {} if profile is None else profile, state,
                                    progress=progress, control=control, dry_run=dry_run,
                                    response_timeout=response_timeout, settle=settle)


# --- calibration -----------------------------------------------------------------------------------

def fit_cantilever(load_g, loaded, s, deflection, lines=None, **options):
    """Bending stiffness and plastic limit from a cantilever capture (Sec. 5.2); options as
    _wiresculpt.fit_cantilever (overhang, linear_density, plastic_tolerance, gravity, nodes,
    smoothing_degree, noise_correction)."""
    return require().fit_cantilever(_list(load_g, "load_g"), _list(loaded, "loaded"), _list(s, "s"),
                                    _list(deflection, "deflection"), lines, **options)


def simulate_cantilever(bending_stiffness, length=0.30, tip_load_g=0.0, linear_density=0.0, gravity=9.81,
                        segments=150):
    """The rod model clamped at the origin under a tip load: (segments+1, 2) m."""
    return require().simulate_cantilever(bending_stiffness, length, tip_load_g, linear_density, gravity, segments)


def fit_friction(angles_deg, lines=None):
    """mu = tan(alpha) over the tilt repeats."""
    return require().fit_friction(_list(angles_deg, "angles_deg"), lines)


def fit_springback(commanded_deg, measured_deg, lines=None):
    """measured = a * commanded + b (|angles|)."""
    return require().fit_springback(_list(commanded_deg, "commanded_deg"), _list(measured_deg, "measured_deg"),
                                    lines)
