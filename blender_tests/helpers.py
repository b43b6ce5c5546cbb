"""Shared by the Blender suites: paths, running Blender in a subprocess, small mesh writers, a
circle, a GRBL emulator on a pseudo-terminal."""
import json
import math
import os
import random
import select
import signal
import subprocess
import sys
import tempfile
import threading
import time
import tty
import types
import unittest

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BATCH = os.path.join(ROOT, "scripts", "wiresculpt_batch.py")
# Inside Blender, the running Blender itself; from the bpy-free suites (plain Python), the one on PATH.
BLENDER = os.environ.get("BLENDER") or (sys.argv[0] if "blender" in os.path.basename(sys.argv[0]).lower()
                                        else "blender")
ADDON = os.path.join(ROOT, "addon")
if ADDON not in sys.path:
    sys.path.insert(0, ADDON)


# Blender imported as a Python module (the PyPI `bpy` wheel, run.py's `bpy` mode) has no blender
# executable to start and no window: the tests that need one are skipped there with these reasons
# (they run on the Blender executable, Debian's 3.4). run.py sets this.
BPY_MODULE = False
NO_EXECUTABLE = "starts a blender process; the bpy module has no blender executable"
NO_WINDOW = "needs a Blender window under Xvfb; the bpy module has none"


def run_blender(script, *args, env=None, timeout=300, preexec_fn=None):
    """Runs `script` in a fresh headless Blender with this process's environment updated by `env`
    (a None value removes the variable), `preexec_fn` run in the child before Blender starts (a
    resource limit); returns the CompletedProcess (text output)."""
    if BPY_MODULE:
        raise unittest.SkipTest(NO_EXECUTABLE)
    cmd = [BLENDER, "--background", "--factory-startup", "--python-exit-code", "1",
           "--python", script, "--", *args]
    merged = {k: v for k, v in {**os.environ, **(env or {})}.items() if v is not None}
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=merged, preexec_fn=preexec_fn)


def run_under_xvfb(script, marker, timeout=180, args=()):
    """Runs `script` in a Blender with a window under Xvfb (modal operators need the event loop),
    `args` after "--"; returns (CompletedProcess, the JSON after the last stdout line starting
    with `marker`, or None)."""
    if BPY_MODULE:
        raise unittest.SkipTest(NO_WINDOW)
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", BLENDER, "--factory-startup",
           "--python-exit-code", "1", "--python", script] + (["--", *args] if args else [])
    # its own process group: on a timeout Blender goes too, not only xvfb-run
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
    result = subprocess.CompletedProcess(cmd, proc.returncode, out, err)
    lines = [line for line in out.splitlines() if line.startswith(marker)]
    return result, json.loads(lines[-1][len(marker):]) if lines else None


class FakeLayout:
    """Records what a draw function asks for; enough of UILayout to run panel code (attributes
    such as `alert` may be set and are ignored)."""

    def __init__(self, log):
        self.log = log

    def __getattr__(self, name):
        def call(*args, **kwargs):
            self.log.append((name, args, kwargs))
            return FakeLayout(self.log)
        return call

    def __setattr__(self, name, value):
        if name == "log":
            object.__setattr__(self, name, value)


def draw(panel_class, context):
    """[(method, args, kwargs)] of what panel_class.draw asks of its layout."""
    log = []
    panel_class.draw(types.SimpleNamespace(layout=FakeLayout(log)), context)
    return log


def wiresculpt_lines(text):
    """The lines the batch script itself printed (Blender adds its own)."""
    return [line for line in text.splitlines() if line.startswith("wiresculpt:")]


def box_faces():
    """The 12 triangles of the box whose vertex i has coordinates chosen by the bits of i."""
    quads = [(0, 2, 6, 4), (1, 5, 7, 3), (0, 4, 5, 1), (2, 3, 7, 6), (0, 1, 3, 2), (4, 6, 7, 5)]
    return [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]


def box_vertices(lo, hi):
    return [tuple(hi[k] if (i >> k) & 1 else lo[k] for k in range(3)) for i in range(8)]


def write_obj(path, vertices, faces):
    with open(path, "w") as f:
        f.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in vertices)
        f.writelines("f " + " ".join(str(i + 1) for i in t) + "\n" for t in faces)


def write_stl(path, vertices, faces):
    with open(path, "w") as f:
        f.write("solid box\n")
        for t in faces:
            f.write(" facet normal 0 0 0\n  outer loop\n")
            f.writelines("   vertex %r %r %r\n" % vertices[i] for i in t)
            f.write("  endloop\n endfacet\n")
        f.write("endsolid box\n")


def write_ply(path, vertices, faces):
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\n")
        f.write(f"element vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\n")
        f.write(f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
        f.writelines(f"{x!r} {y!r} {z!r}\n" for x, y, z in vertices)
        f.writelines("3 " + " ".join(map(str, t)) + "\n" for t in faces)


def gcode_lines(path):
    """The lines a G-code file streams, read by hand: no `;` comment, no blank line."""
    with open(path) as f:
        return [line.strip() for line in f if line.strip() and not line.lstrip().startswith(";")]


def polyline_length(points, closed):
    n = len(points)
    edges = range(n if closed else n - 1)
    return sum(math.dist(points[i], points[(i + 1) % n]) for i in edges)


def step_start(lines, acknowledged):
    """Where a resume starts after a stop that can lose GRBL's queued moves (a dropped link, a
    cancel), when the first `acknowledged` lines were answered ok: after the last acknowledged
    `G4 P0` (the end of the last step known made), or after the leading mode lines."""
    start = 0
    for j, line in enumerate(lines[:acknowledged]):
        if line == "G4 P0" or (start == j and line in ("G21", "G91", "G94")):
            start = j + 1
    return start


class GrblEmulator:
    """A small GRBL on a pseudo-terminal pair (os.openpty), answering in a thread: `ok` to every
    line, `error:20` to the `error_on`-th line received (1-based), silence and a pulled cable
    (the master end closed) on the `drop_on`-th, `delay` seconds before each answer. GRBL's
    realtime bytes (! ~ Ctrl-X) are recorded apart, as GRBL acts on them outside the line stream;
    a soft reset (Ctrl-X) while a line waits for its answer discards that line unanswered.

    `answers` maps a line's number (1-based) to the raw bytes sent instead of `ok` (b"ok\\r\\nok\\r\\n"
    for a device that doubles its answer, b"error:\\xff9\\r\\n" for invalid UTF-8); `double_ok`
    doubles every `ok`.

    The machine, as GRBL 1.1 keeps it: a machine position (X, Y, Z in axis units) moved by G0/G1
    lines (G90/G91 as sent) and `$J=` jogs, each move taking `move_time` seconds in a planner
    queue (0: done at once, the moves of the earlier tests); `?` answers at once with
    `<State|MPos:x,y,z|FS:0,0>` (state Idle, Run, Jog, Hold:0, Home or Alarm); `!` (feed hold)
    freezes a running queue (Hold:0) and `~` (cycle start) runs it on; `$H` homes (`home_time` s in
    state Home, then every axis at 0 and `ok`); `alarm=True` starts locked as a GRBL with homing
    switches does (G-code and jogs get `error:9`, `$X` unlocks with `[MSG:Caution: Unlocked]`,
    `$H` unlocks by homing). A `G4` or `M2` is answered only when the queue has run, as GRBL does.

    received: every line as it arrived; acknowledged: the lines answered `ok`, in order;
    status_queries: how many `?` arrived; position: the machine position now."""

    def __init__(self, error_on=None, drop_on=None, delay=0.0, answers=None, double_ok=False, move_time=0.0,
                 home_time=0.0, alarm=False):
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        self.port = os.ttyname(self.slave)
        self.error_on, self.drop_on, self.delay = error_on, drop_on, delay
        self.answers, self.double_ok = dict(answers or {}), double_ok
        self.move_time, self.home_time = move_time, home_time
        self.received, self.acknowledged, self.realtime = [], [], []
        self.status_queries = 0
        self.position = [0.0, 0.0, 0.0]
        self.relative = False
        self.held = False
        self.alarm = alarm
        self.homed = 0  # $H cycles run
        self._queue = []  # [seconds left, target position or None, kind ("move", "jog", "home"), answer or None]
        self._deferred = None  # (line, bytes): a G4/M2 answered when the queue has run
        self.dropped = False
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    # --- the machine ---

    def state(self):
        if self.alarm:
            return "Alarm"
        if self._queue:
            if self.held:
                return "Hold:0"
            return {"home": "Home", "jog": "Jog"}.get(self._queue[0][2], "Run")
        return "Idle"

    def report(self):
        x, y, z = self.position
        return f"<{self.state()}|MPos:{x:.3f},{y:.3f},{z:.3f}|FS:0,0>\r\n".encode()

    def _target(self, words, relative):
        target = list(self._queue[-1][1]) if self._queue and self._queue[-1][1] is not None else list(self.position)
        for k, axis in enumerate("XYZ"):
            if axis in words:
                target[k] = target[k] + words[axis] if relative else words[axis]
        return target

    @staticmethod
    def _words(text):
        words, k = {}, 0
        text = text.upper().replace(" ", "")
        while k < len(text):
            letter, k = text[k], k + 1
            start = k
            while k < len(text) and (text[k].isdigit() or text[k] in ".-+"):
                k += 1
            try:
                value = float(text[start:k])
            except ValueError:
                value = 0.0
            if letter.isalpha():
                words.setdefault(letter, value)
                if letter == "G":
                    words.setdefault("G_all", []).append(value)
        return words

    def _machine(self, line):
        """The answer to a line the machine model acts on (bytes), None for the plain `ok`, or
        False when it is answered later (a sync line, a homing cycle)."""
        upper = line.upper().replace(" ", "")
        if upper == "$X":
            self.alarm = False
            return b"[MSG:Caution: Unlocked]\r\nok\r\n"
        if upper == "$H":
            self.alarm = False
            self._queue.append([self.home_time, [0.0, 0.0, 0.0], "home", b"ok\r\n"])
            return False
        if upper.startswith("$J="):
            if self.alarm:
                return b"error:9\r\n"
            words = self._words(upper[3:])
            relative = 91.0 in words.get("G_all", []) or (self.relative and 90.0 not in words.get("G_all", []))
            self._queue.append([self.move_time, self._target(words, relative), "jog", None])
            return None
        if upper.startswith("$"):
            return None
        words = self._words(upper)
        gs = words.get("G_all", [])
        if self.alarm and (any(a in words for a in "XYZ") or 4.0 in gs or "M" in words):
            return b"error:9\r\n"
        if 91.0 in gs:
            self.relative = True
        if 90.0 in gs:
            self.relative = False
        if any(a in words for a in "XYZ"):
            self._queue.append([self.move_time, self._target(words, self.relative), "move", None])
        if (4.0 in gs or words.get("M") in (2.0, 30.0)) and self._queue:
            return False  # a sync line: answered when the queue has run
        return None

    def _run(self, seconds):
        """The queue run on for `seconds` (not while held); answers what completes."""
        while self._queue and not self.held:
            head = self._queue[0]
            if head[0] > seconds:
                head[0] -= seconds
                return
            seconds -= head[0]
            self._queue.pop(0)
            if head[1] is not None:
                self.position = list(head[1])
            if head[2] == "home":
                self.homed += 1
            if head[3] is not None:
                os.write(self.master, head[3])
        if not self._queue and self._deferred is not None:
            line, answer = self._deferred
            self._deferred = None
            self.acknowledged.append(line)
            os.write(self.master, answer)

    # --- the link ---

    def _answer(self, line):
        self.received.append(line)
        if self.drop_on is not None and len(self.received) == self.drop_on:
            self.dropped = True
            os.close(self.master)  # the cable is pulled: the slave end hangs up
            return False
        if self.delay and self._reset_within(self.delay):
            return True  # a soft reset discards the line before it is answered, as GRBL does
        ok = b"ok\r\nok\r\n" if self.double_ok else b"ok\r\n"
        if len(self.received) in self.answers:
            os.write(self.master, self.answers[len(self.received)])
        elif self.error_on is not None and len(self.received) == self.error_on:
            os.write(self.master, b"error:20\r\n")
        else:
            with self._lock:
                answer = self._machine(line)
            if answer is False:
                if self._queue and self._queue[-1][2] == "home":
                    self.acknowledged.append(line)
                else:
                    self._deferred = (line, ok)
                self._run(0.0)
                return True
            if answer is not None:
                if answer.endswith(b"ok\r\n"):
                    self.acknowledged.append(line)
                os.write(self.master, answer)
                return True
            self.acknowledged.append(line)
            os.write(self.master, ok)
            self._run(0.0)
        return True

    def _read(self, timeout):
        """Reads what arrived within `timeout` s into the line buffer, realtime bytes apart;
        True when a soft reset (Ctrl-X) was among them."""
        ready, _, _ = select.select([self.master], [], [], timeout)
        if not ready:
            return False
        reset = False
        for byte in os.read(self.master, 256):
            if byte == ord("?"):
                self.status_queries += 1
                os.write(self.master, self.report())
            elif byte in b"!~\x18":
                self.realtime.append(chr(byte))
                reset = reset or byte == 0x18
                if byte == ord("!") and self._queue:
                    self.held = True
                elif byte == ord("~"):
                    self.held = False
                elif byte == 0x18:
                    if self._queue:
                        self.alarm = True  # a reset while moving loses position: GRBL locks
                    self._queue, self._deferred, self.held = [], None, False
            else:
                self._buffer += bytes((byte,))
        return reset

    def _reset_within(self, seconds):
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            if self._read(left):
                self._buffer = b""
                return True
        return False

    def _serve(self):
        self._buffer = b""
        last = time.monotonic()
        while not self._stop.is_set():
            try:
                self._read(0.01)
                now = time.monotonic()
                self._run(now - last)
                last = now
                while b"\n" in self._buffer and self._deferred is None:
                    line, self._buffer = self._buffer.split(b"\n", 1)
                    if not self._answer(line.decode(errors="replace").strip()):
                        return
            except OSError:
                return

    def close(self):
        self._stop.set()
        self._thread.join(2)
        for fd in ((self.slave,) if self.dropped else (self.master, self.slave)):
            try:
                os.close(fd)
            except OSError:
                pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

def circle(normal, radius=0.1, n=64):
    """n points of the circle of `radius` metres about the origin in the plane of `normal`."""
    normal = np.asarray(normal, float)
    u = np.cross(normal, [0.0, 0.0, 1.0] if abs(normal[2]) < 0.9 else [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    t = np.linspace(0, 2 * math.pi, n, endpoint=False)
    return radius * (np.outer(np.cos(t), u) + np.outer(np.sin(t), v))


# --- shapes -------------------------------------------------------------------------------------

def sphere(radius=0.125, segments=48, rings=24):
    V = [(0.0, 0.0, radius)]
    for r in range(1, rings):
        th = math.pi * r / rings
        V += [(radius * math.sin(th) * math.cos(2 * math.pi * s / segments),
               radius * math.sin(th) * math.sin(2 * math.pi * s / segments), radius * math.cos(th)) for s in range(segments)]
    V.append((0.0, 0.0, -radius))
    at = lambda r, s: 1 + (r - 1) * segments + s % segments
    F = [(0, at(1, s), at(1, s + 1)) for s in range(segments)]
    for r in range(1, rings - 1):
        for s in range(segments):
            F += [(at(r, s), at(r + 1, s), at(r + 1, s + 1)), (at(r, s), at(r + 1, s + 1), at(r, s + 1))]
    F += [(len(V) - 1, at(rings - 1, s + 1), at(rings - 1, s)) for s in range(segments)]
    return np.array(V), np.array(F)


def edge_lengths(points):
    p = np.asarray(points, dtype=float)
    return np.linalg.norm(np.diff(p, axis=0), axis=1)


def random_walk(seed, n=14, start=(0.0, 0.0), steps=(0.02, 0.05), turns_deg=(5, 100)):
    """A 2D wire of n segments ((n+1, 2) m) from `start`: each segment's length drawn from `steps`,
    then a turn left or right by an angle drawn from `turns_deg`; one seed, one wire."""
    rng = random.Random(seed)
    p, h, pts = np.array(start, dtype=float), rng.uniform(0, 2 * math.pi), []
    pts.append(p.copy())
    for _ in range(n):
        p = p + rng.uniform(*steps) * np.array([math.cos(h), math.sin(h)])
        pts.append(p.copy())
        h += math.radians(rng.choice([-1, 1]) * rng.uniform(*turns_deg))
    return np.array(pts)


def _planes():
    from wiresculpt.core.scene import PlaneSpec

    return [PlaneSpec(n, (0, 0, 0), normal) for n, normal in (("A", (0, 0, 1)), ("B", (1, 0, 0)), ("C", (0, 1, 0)))]


PLANES = _planes()  # three great circles through the origin


def settings(**kw):
    """The default settings with no cuts (core/settings.defaults()), updated by `kw`."""
    from wiresculpt.core.settings import defaults

    s = defaults()
    s["cuts"] = {}
    s.update(kw)
    return s


def sphere_design(run_settings=None):
    """The design pipeline.run makes of sphere() (radius 0.125 m) cut by PLANES, three great
    circles, in steel wire (a copy of its preset), with `run_settings` (the defaults when None)."""
    from wiresculpt import pipeline
    from wiresculpt.core.materials import PRESETS
    from wiresculpt.core.settings import defaults

    V, F = sphere()
    return pipeline.run(V, F, PLANES, dict(PRESETS["steel"]), defaults() if run_settings is None else run_settings)


# --- inside Blender (bpy is imported where it is used, so the bpy-free suites can import this) ---

GLOBE_OBJ = os.path.join(ROOT, "scripts", "examples", "globe", "globe.obj")
GLOBE_RADIUS = 0.125  # globe.obj has radius 1; scaled like the example's size 0.25


def register_addon():
    import wiresculpt

    if wiresculpt._modules:
        wiresculpt.unregister()
    wiresculpt.register()


def clear_scene():
    import bpy

    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.curves, bpy.data.collections,
                       bpy.data.texts, bpy.data.materials, bpy.data.cameras):
        for block in list(collection):
            collection.remove(block)
    ws = bpy.context.scene.wiresculpt
    ws.contours.clear()
    ws.model = None
    ws.assembly_step = 0


def add_handle(rotation=(0.0, 0.0, 0.0), location=(0.0, 0.0, 0.0)):
    import bpy

    assert bpy.ops.wiresculpt.add_plane() == {'FINISHED'}
    handle = bpy.context.view_layer.objects.active
    handle.location = location
    handle.rotation_euler = rotation
    return handle


def save_and_reload(name="sculpture.blend"):
    """Saves the open file into a temporary folder, opens an empty file, then the saved one again
    (a maker closing and reopening it); the folder is removed afterwards."""
    import bpy

    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, name)
        bpy.ops.wm.save_as_mainfile(filepath=path)
        bpy.ops.wm.read_homefile(use_empty=True)
        bpy.ops.wm.open_mainfile(filepath=path)


def mesh_model(name, V, F):
    """A mesh object `name` of vertices V (n, 3) and triangles F (t, 3), linked into the scene and
    set as the model."""
    import bpy

    me = bpy.data.meshes.new(name)
    me.from_pydata(V.tolist(), [], F.tolist())
    obj = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.update()
    bpy.context.scene.wiresculpt.model = obj
    return obj


def globe_target():
    """globe.obj at radius GLOBE_RADIUS as the model, no slicing plane yet."""
    import bpy

    from wiresculpt.blend.mesh import import_mesh

    _V, _F, objects = import_mesh(GLOBE_OBJ)
    objects[0].scale = (GLOBE_RADIUS,) * 3
    bpy.context.view_layer.update()
    bpy.context.scene.wiresculpt.model = objects[0]


# The hinged globe's five planes as (rotation, location): "Slice E" (x = 0.8 R) crosses only the
# plane y = 0, on one line (planes z = c1 and x = c2 cut circles of the unit sphere that cross iff
# c1^2 + c2^2 < 1, and Slice A/B are at z = +-0.7).
HINGE = (((0, 0, 0), (0, 0, 0.7 * GLOBE_RADIUS)), ((0, 0, 0), (0, 0, -0.7 * GLOBE_RADIUS)),
         ((0, math.pi / 2, 0), (-0.3 * GLOBE_RADIUS, 0, 0)), ((math.pi / 2, 0, 0), (0, 0, 0)),
         ((0, math.pi / 2, 0), (0.8 * GLOBE_RADIUS, 0, 0)))


def hinge_scene():
    """The hinged globe: globe_target with the HINGE planes, sliced."""
    import bpy

    globe_target()
    for rotation, location in HINGE:
        add_handle(rotation, location)
    bpy.context.view_layer.update()
    assert bpy.ops.wiresculpt.slice() == {'FINISHED'}


def placements():
    """{handle name: its plane's placement} of the scene's slicing handles."""
    import bpy

    from wiresculpt.blend.handles import handle_plane, handles

    depsgraph = bpy.context.evaluated_depsgraph_get()
    return {h.name: handle_plane(h, depsgraph)[1:] for h in handles(bpy.context.scene)}


def globe(rotations=((0, 0, 0), (0, math.pi / 2, 0), (math.pi / 2, 0, 0))):
    """The bundled example: globe.obj at radius 0.125 m, handles through its centre with normals
    z, x and y (by default), sliced."""
    import bpy

    from wiresculpt.blend.mesh import import_mesh

    _V, _F, objects = import_mesh(GLOBE_OBJ)
    model = objects[0]
    model.scale = (GLOBE_RADIUS,) * 3
    bpy.context.view_layer.update()
    bpy.context.scene.wiresculpt.model = model
    for rotation in rotations:
        add_handle(rotation)
    assert bpy.ops.wiresculpt.slice() == {'FINISHED'}
    return model


class BlenderCase(unittest.TestCase):
    """A suite inside Blender: the add-on registered, the scene cleared before each test."""

    @classmethod
    def setUpClass(cls):
        register_addon()

    @classmethod
    def tearDownClass(cls):
        import wiresculpt

        clear_scene()
        wiresculpt.unregister()

    def setUp(self):
        clear_scene()


class DesignSuite(unittest.TestCase):
    """A suite inside Blender on one solved design: the add-on registered, cls.design (made by
    cls.make_design()) stored in the scene, cls.tmp a temporary folder; after the suite the stored
    design's text and the folder are removed (the add-on stays registered)."""

    @classmethod
    def make_design(cls):
        raise NotImplementedError

    @classmethod
    def setUpClass(cls):
        from wiresculpt.blend import results

        register_addon()
        cls.design = cls.make_design()
        results.store_design(cls.design)
        cls.tmp = tempfile.TemporaryDirectory()

    @classmethod
    def tearDownClass(cls):
        import bpy
        from wiresculpt.blend import results

        text = bpy.data.texts.get(results.DESIGN_TEXT)
        if text is not None:
            bpy.data.texts.remove(text)
        cls.tmp.cleanup()
