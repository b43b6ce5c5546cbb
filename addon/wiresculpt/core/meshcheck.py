"""Sanity checks on a mesh file and its vertices, before any work (bpy-free): what an importer
would silently drop or choke on (OBJ faces naming missing vertices, a PLY header that promises
more than the file holds), and vertices no sculpture has (NaN/inf, absurd magnitudes, a model in
millimetres read as metres). Each problem is one ValueError sentence naming the file, line or
vertex. The limits are in docs/robustness.md.
"""
import json
import os
import unicodedata

import numpy as np

from .figures import versus
from .sizes import mesh_size

MAX_MESH_COORDINATE = 1e9  # any unit: beyond it the numbers are garbage, not a model
MAX_UNSCALED_EXTENT = 10.0  # metres: a larger model without "size" is almost surely in millimetres
MAX_FILE_BYTES = 2 * 1024 ** 3


def _obj_index(token, count):
    """The 0-based vertex index of an OBJ face token ("7", "7/2", "-1//3"), or None if invalid."""
    head = token.split("/", 1)[0]
    try:
        k = int(head)
    except ValueError:
        return None
    if k > 0:
        return k - 1 if k <= count else None
    if k < 0:
        return count + k if -k <= count else None
    return None


def check_obj(path):
    """ValueError when faces of the OBJ file name vertices that do not exist (Blender's importer
    drops such faces without a word)."""
    vertices, bad, first = 0, 0, None
    with open(path, "rb") as f:
        for number, raw in enumerate(f, 1):
            line = raw.strip()
            if line.startswith(b"v "):
                vertices += 1
            elif line.startswith(b"f "):
                tokens = line.split()[1:]
                indices = [_obj_index(t.decode("ascii", "replace"), vertices) for t in tokens]
                if len(tokens) < 3 or None in indices:
                    bad += 1
                    first = first or number
    if bad:
        raise ValueError(f"mesh file {path}: {bad} face{'s' if bad != 1 else ''} name vertices that do not exist "
                         f"(the first at line {first}); fix the file's face indices")


_PLY_SIZES = {"char": 1, "uchar": 1, "int8": 1, "uint8": 1, "short": 2, "ushort": 2, "int16": 2, "uint16": 2,
              "int": 4, "uint": 4, "int32": 4, "uint32": 4, "float": 4, "float32": 4, "double": 8, "float64": 8}


def check_ply(path):
    """ValueError when the PLY header does not match the file: a format or element the importer
    cannot read, or fewer rows (ASCII) or bytes (binary, fixed-size rows) than it declares."""
    with open(path, "rb") as f:
        data = f.read(MAX_FILE_BYTES)
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise ValueError(f"mesh file {path}: not a PLY file (no 'ply' ... 'end_header' header)")
    try:
        header = data[:end].decode("ascii").splitlines()
    except UnicodeDecodeError:
        raise ValueError(f"mesh file {path}: its PLY header is not ASCII text") from None
    body = data[end + len(b"end_header"):]
    body = body[body.find(b"\n") + 1:] if b"\n" in body else b""
    fmt, elements = None, []
    for line in header[1:]:
        words = line.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format" and len(words) >= 2:
            fmt = words[1]
        elif words[0] == "element" and len(words) == 3:
            try:
                count = int(words[2])
            except ValueError:
                count = -1
            if count < 0:
                raise ValueError(f"mesh file {path}: PLY element '{words[1]}' has a bad count '{words[2]}'")
            elements.append([words[1], count, []])
        elif words[0] == "property" and elements:
            elements[-1][2].append(words[1:])
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise ValueError(f"mesh file {path}: unknown PLY format '{fmt}'")
    if fmt == "ascii":
        rows = sum(1 for line in body.splitlines() if line.strip())
        declared = sum(count for _name, count, _props in elements)
        if rows < declared:
            raise ValueError(f"mesh file {path}: its PLY header declares {declared} rows "
                             f"({', '.join(f'{c} {n}' for n, c, _p in elements)}) but the file holds {rows}")
        return
    need = 0
    for name, count, props in elements:
        if any(p and p[0] == "list" for p in props):
            # rows of lists vary in size: at least one byte per row for the list's length
            need += count
            continue
        try:
            need += count * sum(_PLY_SIZES[p[0]] for p in props)
        except (KeyError, IndexError):
            raise ValueError(f"mesh file {path}: PLY element '{name}' has a property type the importer "
                             "cannot read") from None
    if len(body) < need:
        raise ValueError(f"mesh file {path}: its PLY header declares at least {need} bytes of data but the file "
                         f"holds {len(body)}")


def check_file(path):
    """The checks of the file's format (by extension) before an importer reads it."""
    ext = os.path.splitext(path)[1].lower()
    if ext == ".obj":
        check_obj(path)
    elif ext == ".ply":
        check_ply(path)


def check_vertices(V, path, size):
    """ValueError for vertices no sculpture has, before the mesh is scaled or solved: a non-finite
    coordinate (named by vertex index), a coordinate beyond MAX_MESH_COORDINATE, or, without
    `size`, a bounding box over 10 m (a model in millimetres read as metres)."""
    V = np.asarray(V, dtype=np.float64)
    bad = np.flatnonzero(~np.isfinite(V).all(axis=1))
    if bad.size:
        raise ValueError(f"mesh vertex {int(bad[0])} has a non-finite coordinate (NaN or Inf)")
    if V.size:
        far = np.flatnonzero(np.abs(V).max(axis=1) > MAX_MESH_COORDINATE)
        if far.size:
            i = int(far[0])
            at, most = versus(float(np.abs(V[i]).max()), MAX_MESH_COORDINATE, 6, "g")
            raise ValueError(f"mesh vertex {i} is at {at} from the origin, beyond {most}: mesh file {path} does "
                             f"not hold a model's coordinates")
        extent = mesh_size(V)
        if size is None and extent > MAX_UNSCALED_EXTENT:
            across, most = versus(extent, MAX_UNSCALED_EXTENT, 6, "g")
            raise ValueError(f"your mesh looks like millimetres: mesh file {path} is {across} units across, "
                             f'read as metres that is over {most} m; set "size" to the '
                             "sculpture's size in metres")
    return True


# File systems whose files are the kernel's, not a user's: no run writes its outputs there.
PSEUDO_FILESYSTEMS = {"proc", "sysfs", "devtmpfs", "devpts", "cgroup", "cgroup2", "debugfs", "tracefs",
                      "securityfs", "pstore", "bpf", "configfs", "fusectl", "mqueue", "hugetlbfs", "efivarfs",
                      "binfmt_misc", "autofs", "selinuxfs", "nsfs", "rpc_pipefs"}
MAX_COMPONENT_BYTES = 255  # NAME_MAX of Linux's file systems
MAX_PATH_BYTES = 4095  # PATH_MAX less the terminating zero


def _mount_type(path):
    """The file-system type of the mount holding `path` (an existing path), from
    /proc/self/mounts; None when that cannot be read."""
    try:
        with open("/proc/self/mounts", encoding="utf-8", errors="replace") as f:
            mounts = [line.split()[1:3] for line in f if len(line.split()) >= 3]
    except OSError:
        return None
    real = os.path.realpath(path)
    best, kind = "", None
    for point, fs in mounts:
        point = point.replace("\\040", " ")
        inside = real == point or real.startswith(point.rstrip("/") + "/")
        if inside and len(point) >= len(best):
            best, kind = point, fs
    return kind


def check_output_folder(out):
    """ValueError naming --out unless `out` is a folder a run can write (or create): not empty, a
    UTF-8 name, no component over 255 bytes (nor the path over 4095), not on a pseudo-file system
    (/proc, /sys, /dev ...), an existing folder that is writable, or a path whose nearest existing
    parent is a writable folder. Creates nothing."""
    raw = out if isinstance(out, bytes) else os.fsencode(out)
    if not raw:
        raise ValueError("--out is empty; give the folder the outputs go to (e.g. --out out/globe)")
    try:
        out = raw.decode("utf-8")
    except UnicodeDecodeError:
        shown = raw.decode("utf-8", "backslashreplace")
        raise ValueError(f"--out {shown}: the folder name is not UTF-8; choose a name in UTF-8") from None
    if any(unicodedata.category(ch) in ("Cc", "Zl", "Zp") for ch in out):
        shown = "".join(json.dumps(ch)[1:-1] if unicodedata.category(ch) in ("Cc", "Zl", "Zp") else ch for ch in out)
        raise ValueError(f"--out {shown}: the folder name holds a control character; choose another name")
    path = os.path.abspath(out)
    if len(os.fsencode(path)) > MAX_PATH_BYTES:
        raise ValueError(f"--out {out[:60]}...: the path is {len(os.fsencode(path))} bytes long, over the "
                         f"{MAX_PATH_BYTES} a path may have")
    for part in path.split(os.sep):
        size = len(os.fsencode(part))
        if size > MAX_COMPONENT_BYTES:
            raise ValueError(f"--out {out[:60]}...: the folder name {part[:20]}... is {size} bytes long; a name in a "
                             f"path may have at most {MAX_COMPONENT_BYTES} bytes")
    existing = path
    while not os.path.lexists(existing):
        existing = os.path.dirname(existing)
    kind = _mount_type(existing)
    if kind in PSEUDO_FILESYSTEMS:
        raise ValueError(f"--out {out}: {existing} is on the kernel's {kind} file system, not a place for files; "
                         "choose a folder on a disk")
    if os.path.lexists(path):
        if not os.path.isdir(path):
            raise ValueError(f"--out {out}: exists and is not a folder")
        if not os.access(path, os.W_OK | os.X_OK):
            raise ValueError(f"--out {out}: the folder is not writable")
        return
    parent = os.path.dirname(path)
    while not os.path.lexists(parent):
        parent = os.path.dirname(parent)
    if not os.path.isdir(parent):
        raise ValueError(f"--out {out}: cannot be created, {parent} is not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ValueError(f"--out {out}: cannot be created, {parent} is not writable")
