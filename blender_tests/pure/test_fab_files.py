"""The fabrication files, read back by independent parsers: every SVG by xml.etree (and rendered
by rsvg-convert), every DXF by ezdxf (readfile + audit, no errors), the G-code and CSV as text.
The polylines must be found at 1:1 in millimetres within 0.01 mm.

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- fab_files
"""
import csv
import math
import os
import shutil
import struct
import subprocess
import tempfile
import time
import unittest
import xml.etree.ElementTree as ET

import numpy as np

from helpers import GrblEmulator, random_walk
from wiresculpt import native

SVG = "{http://www.w3.org/2000/svg}"
TOL_MM = 0.01


def square(a=0.06):
    return np.array([[0, 0], [a, 0], [a, a], [0, a], [0, 0]], dtype=float)


def polygon(n=9, r=0.08, centre=(0.3, 0.1)):
    return np.array([[centre[0] + r * math.cos(2 * math.pi * i / n), centre[1] + r * math.sin(2 * math.pi * i / n)]
                     for i in range(n + 1)])


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    return struct.unpack(">II", head[16:24])


def polyline_points_mm(element):
    return np.array([[float(v) for v in pair.split(",")] for pair in element.get("points").split()])


class FabFiles(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.w = native.require()
        cls.rsvg = shutil.which("rsvg-convert")
        import ezdxf  # python3-ezdxf (scripts/test installs it); Blender's Python sees dist-packages
        cls.ezdxf = ezdxf

    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="wiresculpt_fab_")
        self.addCleanup(shutil.rmtree, self.dir, True)
        self.wires = []
        walk = random_walk(7, start=(-0.2, 0.05), steps=(0.016, 0.05), turns_deg=(3, 100))
        for k, (name, pts) in enumerate([("A/0", square()), ("B/1", polygon()), ("C/2", walk)]):
            prog = self.w.make_bend_program(pts, {})
            self.wires.append({"name": name, "points": pts, "bend_points": prog["bend_vertices"],
                               "crossing_points": [0, len(pts) // 2]})

    def assert_same_shape_mm(self, found, wire_points_m, flip_y):
        """found (mm) equals the wire (m) * 1000 after a translation (and a y flip for SVG)."""
        expected = 1000.0 * np.asarray(wire_points_m)
        if flip_y:
            expected[:, 1] *= -1.0
        self.assertEqual(found.shape, expected.shape)
        offset = found[0] - expected[0]
        worst = np.abs(found - (expected + offset)).max()
        self.assertLess(worst, TOL_MM, f"polyline off by {worst} mm")
        return offset

    def render(self, path):
        self.assertIsNotNone(self.rsvg, "rsvg-convert (librsvg2-bin) is required; scripts/test installs it")
        png = path + ".png"
        run = subprocess.run([self.rsvg, "--dpi-x", "96", "--dpi-y", "96", path, "-o", png],
                             capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 0, run.stderr)
        return png_size(png)

    def check_svg(self, path, wires):
        root = ET.parse(path).getroot()
        self.assertEqual(root.tag, SVG + "svg")
        width, height = root.get("width"), root.get("height")
        self.assertTrue(width.endswith("mm") and height.endswith("mm"))
        W, H = float(width[:-2]), float(height[:-2])
        self.assertEqual([float(v) for v in root.get("viewBox").split()], [0.0, 0.0, W, H])
        paths = root.findall(f".//{SVG}polyline[@class='wire-path']")
        self.assertEqual(len(paths), len(wires))
        margin = 10.0
        for element, wire in zip(paths, wires):
            found = polyline_points_mm(element)
            self.assert_same_shape_mm(found, wire["points"], flip_y=True)
            self.assertGreaterEqual(found.min(), margin - TOL_MM)
            self.assertLessEqual(found[:, 0].max(), W - margin + TOL_MM)
            self.assertLessEqual(found[:, 1].max(), H - margin + TOL_MM)
        groups = root.findall(f"{SVG}g")
        for g, wire in zip(groups, wires):
            self.assertEqual(g.get("data-name"), wire["name"])
            self.assertEqual(len(g.findall(f"{SVG}line[@class='bend']")), len(wire["bend_points"]))
            self.assertEqual(len(g.findall(f"{SVG}circle[@class='crossing']")), len(wire["crossing_points"]))
            self.assertIn(wire["name"], g.find(f"{SVG}text").text)
        # The renderer understands the size in millimetres: 96 dpi -> W / 25.4 * 96 pixels.
        px_w, px_h = self.render(path)
        self.assertAlmostEqual(px_w, W / 25.4 * 96, delta=1.0)
        self.assertAlmostEqual(px_h, H / 25.4 * 96, delta=1.0)
        return W, H

    def test_svg_per_wire_and_sheet(self):
        for k, wire in enumerate(self.wires):
            path = os.path.join(self.dir, f"wire_{k}.svg")
            text = self.w.write_svg(path, [wire], sheet=False)
            with open(path) as f:
                self.assertEqual(f.read(), text)
            W, H = self.check_svg(path, [wire])
            pts = 1000.0 * wire["points"]
            self.assertAlmostEqual(W, np.ptp(pts[:, 0]) + 20.0, delta=1e-3)
            self.assertAlmostEqual(H, np.ptp(pts[:, 1]) + 20.0, delta=1e-3)
        sheet = os.path.join(self.dir, "sheet.svg")
        self.w.write_svg(sheet, self.wires)
        self.check_svg(sheet, self.wires)

    def test_dxf_opens_in_ezdxf_without_audit_errors(self):
        path = os.path.join(self.dir, "wires.dxf")
        self.w.write_dxf(path, self.wires)
        doc = self.ezdxf.readfile(path)
        self.assertEqual(doc.dxfversion, "AC1015")
        self.assertEqual(doc.header.get("$INSUNITS"), 4)
        auditor = doc.audit()
        self.assertEqual(len(auditor.errors), 0, [str(e) for e in auditor.errors])
        self.assertFalse(auditor.has_errors)
        msp = doc.modelspace()
        polylines = list(msp.query("LWPOLYLINE"))
        self.assertEqual(len(polylines), len(self.wires))
        layers = {p.dxf.layer for p in polylines}
        self.assertEqual(len(layers), len(self.wires))  # one layer per wire
        for poly, wire in zip(polylines, self.wires):
            self.assertIn(poly.dxf.layer, [layer.dxf.name for layer in doc.layers])
            found = np.array([[v[0], v[1]] for v in poly.get_points()])
            offset = self.assert_same_shape_mm(found, wire["points"], flip_y=False)
            self.assertLess(np.abs(offset).max(), TOL_MM)  # DXF keeps the wire's own coordinates

    def test_gcode_and_bend_table(self):
        profile = {"springback_a": 0.92, "springback_b_deg": -1.5}
        for k, wire in enumerate(self.wires):
            prog = self.w.make_bend_program(wire["points"], profile)
            gpath = os.path.join(self.dir, f"wire_{k}.gcode")
            text = self.w.write_gcode(gpath, wire["points"], profile, wire["name"], "steel 3 mm")
            with open(gpath) as f:
                self.assertEqual(f.read(), text)
            self.assertIn(f"; wire: {wire['name']}", text)
            self.assertIn("; material: steel 3 mm", text)
            lines = self.w.stream_lines(text)
            feeds = [float(l.split()[1][1:]) for l in lines if l.startswith("G1 X")]
            self.assertEqual(len(feeds), len(prog["steps"]))
            self.assertAlmostEqual(sum(feeds), 1000 * prog["wire_length"], delta=1e-3 * len(feeds))
            state = {}
            dry = self.w.stream_program("/dev/null-port", lines, profile, state, dry_run=True)
            self.assertEqual(dry["status"], "dry_run")
            cpath = os.path.join(self.dir, f"wire_{k}.csv")
            self.w.write_bend_table(cpath, wire["points"], profile)
            with open(cpath, newline="") as f:
                rows = list(csv.DictReader(f))
            self.assertEqual(list(rows[0].keys()), ["step", "feed_mm", "bend_deg", "commanded_deg"])
            self.assertEqual(len(rows), len(prog["steps"]))
            for row, step in zip(rows, prog["steps"]):
                self.assertAlmostEqual(float(row["feed_mm"]), step["feed_mm"], delta=1e-4)
                self.assertAlmostEqual(float(row["bend_deg"]), step["bend_deg"], delta=1e-4)
                b = float(row["bend_deg"])
                if b:  # the calibration fit applied to the command gives the target back
                    c = float(row["commanded_deg"])
                    self.assertAlmostEqual(0.92 * abs(c) - 1.5, abs(b), delta=1e-3)
        self.assertFalse([n for n in os.listdir(self.dir) if ".tmp-" in n])

    def test_default_profile_moves_its_pin_at_each_change_of_bend_side(self):
        """The default profile ducks its pin (Z) before every bend to the other side than the one
        before (the pin starts on the left, positive side); the change count is read off the
        polyline's turn signs, not off the program. A profile with "pin_axis": "" never moves Z
        and is otherwise the same program."""
        tested = 0
        for wire in self.wires:
            pts = np.asarray(wire["points"])
            if np.allclose(pts[0], pts[-1]):
                continue  # closed: the program's first bend depends on where it starts
            edges = np.diff(pts, axis=0)
            cross = edges[:-1, 0] * edges[1:, 1] - edges[:-1, 1] * edges[1:, 0]
            sides = [1 if c > 0 else -1 for c in cross if abs(c) > 1e-12]
            changes, side = 0, 1
            for s_ in sides:
                changes += s_ != side
                side = s_
            self.assertGreaterEqual(changes, 2, wire["name"])
            lines = self.w.stream_lines(self.w.write_gcode(None, pts, {}, wire["name"], "steel"))
            back = side != 1  # a program ending on the negative side ducks back before M2
            self.assertEqual(lines.count("G0 Z-5.0000"), changes + back)
            self.assertEqual(lines.count("G0 Z5.0000"), changes + back)
            for i, line in enumerate(lines):  # each duck swings the head across, then the bend or M2
                if line == "G0 Z-5.0000":
                    self.assertIn(lines[i + 1], ("G0 Y20.0000", "G0 Y-20.0000"))  # the default 20 deg swing
                    self.assertEqual(lines[i + 2], "G0 Z5.0000")
                    self.assertTrue(lines[i + 3].startswith("G1 Y") or lines[i + 3] == "M2", lines[i + 3])
            pinless = self.w.stream_lines(self.w.write_gcode(None, pts, {"pin_axis": ""}, wire["name"], "steel"))
            self.assertFalse([l for l in pinless if "Z" in l])
            self.assertEqual(pinless, [l for l in lines if not l.startswith("G0 ")])
            tested += 1
        self.assertGreaterEqual(tested, 1)

    def test_errors_name_the_path_and_leave_nothing(self):
        missing = os.path.join(self.dir, "no", "such", "folder", "w.svg")
        with self.assertRaises(ValueError) as ctx:
            self.w.write_svg(missing, self.wires[:1])
        self.assertIn("w.svg", str(ctx.exception))
        with self.assertRaises(ValueError) as ctx:
            self.w.make_bend_program(np.array([[0, 0], [0.01, 0], [0.02, 0.01]]), {})
        self.assertIn("step 1", str(ctx.exception))
        self.assertEqual(os.listdir(self.dir), [])


class StreamThroughBinding(unittest.TestCase):
    """stream_program from Python: the GIL is released while streaming and re-acquired for the
    progress callback; a small GRBL stand-in answers on a pseudo-terminal."""

    def test_stream_with_progress_callback_and_resume_state(self):
        w = native.require()
        lines = w.stream_lines(w.write_gcode(None, square(), {}, "A/0", "steel"))
        grbl = GrblEmulator(error_on=4)
        received, port = grbl.received, grbl.port
        try:
            fractions, state = [], {}
            started = time.monotonic()
            result = w.stream_program(port, lines, {}, state,
                                      progress=lambda stage, f: fractions.append(f) or True,
                                      control=w.StreamControl(), settle=0.05, response_timeout=1.0)
            self.assertLess(time.monotonic() - started, 5.0)
            self.assertEqual(result["status"], "error")
            self.assertEqual(result["failed_line"], 3)
            self.assertEqual(state["next_line"], 3)   # updated in place for the resume
            self.assertEqual(fractions[-1], 3 / len(lines))
            self.assertIn("line 4", result["message"])
            result = w.stream_program(port, lines, {}, state, settle=0.05, response_timeout=1.0)
            self.assertEqual(result["status"], "completed")
            self.assertEqual(state["next_line"], len(lines))
            modes = [l for l in lines[:3] if l in ("G21", "G91", "G94")]
            self.assertEqual(modes, ["G21", "G91", "G94"])
            # the mode lines are restored before resuming; only the rejected line went twice
            self.assertEqual(received, lines[:4] + modes + lines[3:])
            # Without a state each call starts a program afresh (no progress shared between calls).
            before = len(received)
            for _ in range(2):
                again = w.stream_program(port, lines, {}, settle=0.05, response_timeout=1.0)
                self.assertEqual((again["status"], again["next_line"]), ("completed", len(lines)))
            self.assertEqual(received[before:], lines + lines)
            # A callback that raises stops the stream (feed hold + reset) and the error reaches Python.
            fresh = {}
            with self.assertRaises(ZeroDivisionError):
                w.stream_program(port, lines, {}, fresh, progress=lambda stage, f: 1 / 0, settle=0.05)
            self.assertEqual(fresh["next_line"], 0)
        finally:
            grbl.close()

    def test_a_link_dropped_at_a_steps_g4_resumes_from_the_steps_first_line(self):
        """GRBL answers ok when it queues a line: a step's feed and bend are acknowledged at once and
        only its G4 P0 waits for the moves. A link dropped then leaves the step in doubt: the message
        names it, the state resumes from its first line, and the resume sends every line of it again."""
        w = native.require()
        lines = w.stream_lines(w.write_gcode(None, square(), {}, "A/0", "steel"))
        syncs = [i for i, line in enumerate(lines) if line == "G4 P0"]
        first, end = syncs[0] + 1, syncs[1]  # step 2, 0-based
        fast = dict(settle=0.05, response_timeout=1.0)
        state = {}
        with GrblEmulator(drop_on=end + 1) as grbl:  # the cable is pulled as step 2's G4 P0 arrives
            r = w.stream_program(grbl.port, lines, {}, state, **fast)
        self.assertEqual(r["status"], "disconnected")
        self.assertEqual(r["last_acknowledged"], end - 1)
        self.assertEqual((state["next_line"], state["confirmed"]), (first, first))
        self.assertIn(f"step 2 (lines {first + 1}-{end + 1}: feed 60.000 mm, bend 90.000 deg)", r["message"])
        self.assertIn(f"check the wire: the resume restarts the step from line {first + 1}", r["message"])
        with GrblEmulator() as again:
            r = w.stream_program(again.port, lines, {}, state, **fast)
        self.assertEqual(r["status"], "completed")
        self.assertEqual(again.received, ["G21", "G91", "G94"] + lines[first:])

    def test_strict_accounting_lenient_decoding_and_one_stream_per_port(self):
        """'ok ok' to one line stops before the next line is counted (the resume sends
        it); invalid UTF-8 in error: is a status, not UnicodeDecodeError; a second stream on a
        port in use is refused naming the holder."""
        w = native.require()
        lines = w.stream_lines(w.write_gcode(None, square(), {}, "A/0", "steel"))
        fast = dict(settle=0.05, response_timeout=1.0)
        with GrblEmulator(answers={3: b"ok\r\nok\r\n"}) as grbl:
            state = {}
            r = w.stream_program(grbl.port, lines, {}, state, **fast)
            self.assertEqual((r["status"], r["failed_line"], state["next_line"]), ("protocol_error", 3, 3))
            self.assertEqual(grbl.received, lines[:3])  # line 4 was never sent
            r = w.stream_program(grbl.port, lines, {}, state, **fast)
            self.assertEqual(r["status"], "completed")
            self.assertEqual(grbl.received[-(len(lines) - 3):], lines[3:])
        with GrblEmulator(double_ok=True) as grbl:
            r = w.stream_program(grbl.port, lines, {}, {}, **fast)
            self.assertEqual((r["status"], r["next_line"]), ("protocol_error", 1))
        with GrblEmulator(answers={2: b"error:\xff\xfe9\r\n"}) as grbl:
            r = w.stream_program(grbl.port, lines, {}, {}, **fast)
            self.assertEqual((r["status"], r["failed_line"]), ("error", 1))
            self.assertIn("error:\\xff\\xfe9", r["message"])
        with GrblEmulator(delay=0.3) as grbl:
            import threading
            first = {}
            worker = threading.Thread(target=lambda: first.update(w.stream_program(grbl.port, lines[:3], {}, {}, **fast)))
            worker.start()
            try:
                for _ in range(200):  # until the first stream holds the port (it has sent a line)
                    if grbl.received:
                        break
                    time.sleep(0.01)
                with self.assertRaises(ValueError) as ctx:
                    w.stream_program(grbl.port, lines, {}, {}, **fast)
                self.assertIn(f"is in use by process {os.getpid()}", str(ctx.exception))
            finally:
                worker.join(10)
            self.assertEqual(first["status"], "completed")
            self.assertEqual(grbl.received, lines[:3])  # nothing of the second stream arrived
        with self.assertRaises(ValueError) as ctx:
            w.stream_program("/dev/null-port", lines, {}, {}, settle=float("inf"))
        self.assertEqual(str(ctx.exception), "settle must be from 0 to 60 seconds, got inf")


if __name__ == "__main__":
    unittest.main()
