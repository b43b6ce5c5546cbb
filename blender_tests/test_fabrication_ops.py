"""The add-on's fabrication operators on a solved design: Export writes every file with the chosen
machine profile (its spring-back fit changes the commanded angles exactly as (target - b) / a),
Send to Machine streams a wire to a GRBL emulator on a pseudo-terminal, a dropped link is reported
with the last acknowledged line and the step in doubt, and Resume makes that step again from its
first line and finishes, skipping none; Cancel stops; the modal operator (worker thread, status bar, Cancel, Resume) under Xvfb.

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- fabrication_ops
"""
import csv
import glob
import math
import os
import shutil
import threading
import time
import unittest

import bpy

from helpers import ROOT, DesignSuite, GrblEmulator, gcode_lines, run_under_xvfb, step_start
from wiresculpt import native, pipeline
from wiresculpt.blend import results as scene_results
from wiresculpt.fab import export, streaming
from wiresculpt.core import calibration as cal
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.scene import PlaneSpec
from wiresculpt.core.settings import defaults

SPRINGBACK_A, SPRINGBACK_B = 0.92, -1.5  # measured = a * commanded + b (degrees)
MODES = ("G21", "G91", "G94")  # the program's mode lines, sent again before a resume
UI_SCRIPT = os.path.join(ROOT, "blender_tests", "ui_fabrication_modal.py")
FAST = {"settle": 0.05, "response_timeout": 2.0}


def globe_design():
    """The three-wire globe solved by the pipeline (a sphere of 12.5 cm radius)."""
    from helpers import sphere

    V, F = sphere()
    planes = [PlaneSpec(n, (0, 0, 0), normal) for n, normal in
              (("Equator", (0, 0, 1)), ("Meridian0", (1, 0, 0)), ("Meridian90", (0, 1, 0)))]
    return pipeline.run(V, F, planes, PRESETS["steel"], defaults())


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class FabricationOperators(DesignSuite):
    @classmethod
    def make_design(cls):
        return globe_design()

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        fit = {"springback_a": SPRINGBACK_A, "springback_b_deg": SPRINGBACK_B, "rms_deg": 0.1,
               "max_residual_deg": 0.2, "samples": 5}
        cls.profile_path = cal.save_profile(cal.with_springback(cal.default_profile(), fit, "bench.csv"),
                                            os.path.join(cls.tmp.name, "bender.json"))
        cls.wire = cls.design["wires"][0]

    @classmethod
    def tearDownClass(cls):
        super().tearDownClass()
        bpy.context.scene.wiresculpt.property_unset("machine_profile")
        streaming.PENDING.clear()
        streaming.LAST.clear()

    def setUp(self):
        bpy.context.scene.wiresculpt.machine_profile = ""
        streaming.PENDING.clear()

    def export_to(self, name, profile_path=""):
        bpy.context.scene.wiresculpt.machine_profile = profile_path
        out = os.path.join(self.tmp.name, name)
        self.assertEqual(bpy.ops.wiresculpt.export_fabrication(directory=out), {'FINISHED'})
        return out

    def program(self, profile_path=""):
        """The wire's streamed lines, read by hand from the G-code file Export writes."""
        out = self.export_to("program", profile_path)
        return gcode_lines(os.path.join(out, "gcode", export.file_stem(self.wire) + ".gcode"))

    # --- Export ------------------------------------------------------------------------------

    def test_export_writes_every_file_and_the_profile_compensates_spring_back(self):
        self.assertTrue(self.design["stable"])
        plain = self.export_to("plain")
        out = self.export_to("calibrated", self.profile_path)
        for wire in self.design["wires"]:
            stem = export.file_stem(wire)
            for rel in (f"svg/{stem}.svg", f"gcode/{stem}.gcode", f"bends/{stem}.csv"):
                self.assertTrue(os.path.isfile(os.path.join(out, rel)), rel)
        for rel in ("templates/sheet.svg", "dxf/sculpture.dxf"):
            self.assertTrue(os.path.isfile(os.path.join(out, rel)), rel)
        self.assertEqual(glob.glob(os.path.join(out, "*", "*.tmp*")), [])
        bends = 0
        for wire in self.design["wires"]:
            stem = export.file_stem(wire)
            rows, plain_rows = read_rows(f"{out}/bends/{stem}.csv"), read_rows(f"{plain}/bends/{stem}.csv")
            self.assertEqual([r["bend_deg"] for r in rows], [r["bend_deg"] for r in plain_rows])
            for row, plain_row in zip(rows, plain_rows):
                target = float(row["bend_deg"])
                if target == 0.0:
                    continue
                bends += 1
                # measured = a * commanded + b on magnitudes: commanded = (|target| - b) / a
                expected = math.copysign((abs(target) - SPRINGBACK_B) / SPRINGBACK_A, target)
                self.assertAlmostEqual(float(row["commanded_deg"]), expected, delta=2e-4)
                self.assertAlmostEqual(float(plain_row["commanded_deg"]), target, delta=1e-4)
            with open(f"{out}/gcode/{stem}.gcode") as f:
                self.assertIn(f"measured = {SPRINGBACK_A:.4f} * commanded + {SPRINGBACK_B:.3f} deg", f.read())
        self.assertGreater(bends, 10)

    def test_export_shows_the_predicted_wires_as_ghosts_replaced_not_accumulated(self):
        from wiresculpt.blend import calibration as scene_calibration
        from wiresculpt.blend import preview

        scene = bpy.context.scene
        scene.pop(scene_calibration.RESULTS_KEY, None)
        self.addCleanup(lambda: scene.pop(scene_calibration.RESULTS_KEY, None))

        def ghosts():
            return {o[preview.PREVIEW_KEY]: o for o in scene.objects if preview.PREVIEW_KEY in o}
        names = sorted(w["name"] for w in self.design["wires"])
        for _ in range(2):  # the second export replaces the first one's ghosts
            self.export_to("ghosts")
            self.assertEqual(sorted(ghosts()), names)
        self.assertEqual(len([o for o in bpy.data.collections[preview.PREVIEW_COLLECTION].objects]), len(names))
        for wire in self.design["wires"]:
            obj = ghosts()[wire["name"]]
            self.assertEqual(obj.type, 'CURVE')
            pts = [tuple(obj.matrix_world @ p.co.xyz) for p in obj.data.splines[0].points]
            normal = [float(x) for x in wire["plane"]["normal"]]
            length = math.sqrt(sum(x * x for x in normal))
            for p in pts:  # on the wire's plane
                off = sum((p[k] - wire["plane"]["origin"][k]) * normal[k] for k in range(3)) / length
                self.assertLess(abs(off), 1e-6)
            # a rigid copy of the program's walk: its length is the wire's (float32 coordinates)
            walked = sum(math.dist(a, b) for a, b in zip(pts, pts[1:]))
            rest = wire["rest"]
            self.assertAlmostEqual(walked, sum(math.dist(a, b) for a, b in zip(rest, rest[1:])), delta=1e-5)
            # no fit loaded: the machine is modelled by the export profile, nothing drifts
            self.assertLess(obj["wiresculpt_preview_distance_mm"], 0.1)
        # a loaded spring-back fit 5 % below the (default, a = 1) profile: every wire drifts
        scene_calibration.store(scene, "springback", {"springback_a": 0.95, "springback_b_deg": 0.0, "rms_deg": 0.1,
                                                      "max_residual_deg": 0.1, "samples": 5})
        self.export_to("ghosts")
        self.assertEqual(sorted(ghosts()), names)
        for obj in ghosts().values():
            self.assertGreater(obj["wiresculpt_preview_distance_mm"], 1.0)
        rows, model = preview.figures(scene)  # what the Fabrication panel lists
        self.assertEqual([r[0] for r in rows], names)
        self.assertEqual([r[1] for r in rows], [ghosts()[n]["wiresculpt_preview_distance_mm"] for n in names])
        self.assertEqual(model, (0.95, 0.0))
        # a new design (Optimize writes the results) makes them stale: they go until the next export
        scene_results.write_results(scene, self.design)
        self.addCleanup(lambda: (scene_results.clear_results(scene), scene_results.store_design(self.design)))
        self.assertEqual(ghosts(), {})
        self.export_to("ghosts")
        self.assertEqual(sorted(ghosts()), names)
        scene_results.clear_results(scene)
        self.assertEqual(ghosts(), {})

    def test_export_reports_a_missing_profile_naming_the_file(self):
        bpy.context.scene.wiresculpt.machine_profile = os.path.join(self.tmp.name, "nowhere.json")
        with self.assertRaisesRegex(RuntimeError, "nowhere.json does not exist"):
            bpy.ops.wiresculpt.export_fabrication(directory=os.path.join(self.tmp.name, "x"))
        self.assertFalse(os.path.exists(os.path.join(self.tmp.name, "x")))

    def test_limits_are_the_stricter_of_design_and_profile_and_a_stricter_profile_is_reported(self):
        limits = self.design["machine"]
        # The saved default limits (degrees through radians and back) equal the design's: no note.
        self.assertEqual(export.machine_profile(self.design, cal.load_profile(self.profile_path))[1], [])
        looser = dict(cal.default_profile(), min_segment=limits["min_segment"] / 2,
                      max_bend_deg=limits["max_bend_deg"] + 10, min_bend_deg=limits["min_bend_deg"] / 2)
        machine, notes = export.machine_profile(self.design, looser)
        self.assertEqual(notes, [])
        for key in ("min_segment", "max_bend_deg", "min_bend_deg"):
            self.assertEqual(machine[key], limits[key])
        stricter = dict(looser, min_segment=limits["min_segment"] + 0.005, max_bend_deg=limits["max_bend_deg"] - 30)
        machine, notes = export.machine_profile(self.design, stricter)
        self.assertEqual(machine["min_segment"], limits["min_segment"] + 0.005)
        self.assertEqual(machine["max_bend_deg"], limits["max_bend_deg"] - 30)
        self.assertEqual(machine["min_bend_deg"], limits["min_bend_deg"])
        self.assertEqual(len(notes), 2)
        self.assertIn(f"min_segment {(limits['min_segment'] + 0.005) * 1000:g} mm", notes[0])
        self.assertIn(f"max_bend_deg {limits['max_bend_deg'] - 30:g}°", notes[1])
        # The stricter machine refuses the wires it cannot make; the summary names them and the note.
        out = os.path.join(self.tmp.name, "strict")
        result = export.export(self.design, out, dict(stricter, min_segment=0.2))
        level, text = export.summary(result, out)
        self.assertEqual(level, "ERROR")
        self.assertEqual(result["wires"], [])
        for wire in self.design["wires"]:
            self.assertIn(f"not bendable: wire {wire['name']}:", text)
        self.assertIn("min_segment 200 mm is stricter", text)

    # --- Send to Machine ---------------------------------------------------------------------

    def send(self, port, **kw):
        """Send with the wire loaded (the Continue of the "load the wire" step; test_machine_panel
        checks the step itself)."""
        return bpy.ops.wiresculpt.send_to_machine(wire=self.wire["name"], port=port, loaded=True, **FAST, **kw)

    def test_send_streams_the_whole_program_once(self):
        lines = self.program()
        with GrblEmulator() as grbl:
            self.assertEqual(self.send(grbl.port), {'FINISHED'})
        self.assertEqual(grbl.acknowledged, lines)
        self.assertEqual(grbl.received, lines)
        self.assertNotIn(self.wire["name"], streaming.PENDING)
        self.assertIn(f"({len(lines)} lines) acknowledged", streaming.LAST[self.wire["name"]][1])

    def test_dry_run_sends_nothing(self):
        self.program()
        self.latest = os.path.join(self.tmp.name, "program", "gcode", export.file_stem(self.wire) + ".gcode")
        with GrblEmulator() as grbl:
            self.assertEqual(self.send(grbl.port, dry_run=True), {'FINISHED'})
            time.sleep(0.1)
        self.assertEqual(grbl.received, [])
        self.assertIn(f"the program checks out ({len(gcode_lines(self.latest))} lines", streaming.LAST[self.wire["name"]][1])
        self.assertIn("nothing was sent", streaming.LAST[self.wire["name"]][1])

    def test_a_dropped_link_names_the_step_in_doubt_and_resume_makes_it_again(self):
        lines = self.program(self.profile_path)
        k = len(lines) // 2  # the k-th line (1-based) is in flight when the cable is pulled
        start = step_start(lines, k - 1)  # GRBL queued lines start..k-2: they may be lost
        self.assertLess(start, k - 1)
        bpy.context.scene.wiresculpt.machine_profile = self.profile_path
        with GrblEmulator(drop_on=k) as first:
            with self.assertRaises(RuntimeError) as ctx:
                self.send(first.port)
        message = str(ctx.exception)
        step = 1 + sum(1 for line in lines[:start] if line == "G4 P0")  # the step whose first line is start
        self.assertIn(f"Step {step} (lines {start + 1}-", message)
        self.assertIn(f"Resume restarts step {step} at line {start + 1}.", message)
        self.assertIn("check the wire", message)
        self.assertEqual(first.acknowledged, lines[:k - 1])
        self.assertEqual(first.received, lines[:k])
        # Nothing to resume on another wire; Resume under another profile is refused.
        other = self.design["wires"][1]["name"]
        with self.assertRaisesRegex(RuntimeError, f"nothing to resume for wire {other}"):
            bpy.ops.wiresculpt.send_to_machine(wire=other, port=first.port, resume=True, **FAST)
        bpy.context.scene.wiresculpt.machine_profile = ""
        with self.assertRaisesRegex(RuntimeError, "program changed"):
            self.send(first.port, resume=True)
        bpy.context.scene.wiresculpt.machine_profile = self.profile_path
        # The device comes back under another name (a new pseudo-terminal): resume there.
        with GrblEmulator() as second:
            self.assertEqual(self.send(second.port, resume=True), {'FINISHED'})
        modes = [line for line in lines[:k - 1] if line in MODES]
        self.assertEqual(modes, list(MODES))
        # the step in doubt is sent again from its first line, nothing after it is skipped
        self.assertEqual(second.acknowledged, modes + lines[start:])
        self.assertNotIn(self.wire["name"], streaming.PENDING)
        self.assertIn(f"resumed at line {start + 1}", streaming.LAST[self.wire["name"]][1])
        self.assertIsNone(streaming.PENDING.get(self.wire["name"]))

    def test_a_rejected_line_stops_there_and_resume_sends_it_again(self):
        lines = self.program()
        k = 9  # GRBL answers error:20 to the k-th line: it was not executed
        with GrblEmulator(error_on=k) as grbl:
            with self.assertRaises(RuntimeError) as ctx:
                self.send(grbl.port)
            message = str(ctx.exception)
            step = 1 + sum(1 for line in lines[:k - 1] if line == "G4 P0")
            self.assertIn(f"GRBL refused line {k} with error:20", message)
            self.assertIn(f"Line {k} was not run", message)
            self.assertIn(f"Resume continues step {step} at line {k}.", message)
            self.assertEqual(self.send(grbl.port, resume=True), {'FINISHED'})
        modes = [line for line in lines[:k - 1] if line in MODES]
        self.assertEqual(grbl.received, lines[:k] + modes + lines[k - 1:])
        self.assertEqual(grbl.acknowledged, lines[:k - 1] + modes + lines[k - 1:])

    def test_cancel_stops_the_machine_and_resume_continues(self):
        lines = self.program()
        k = 6  # cancelled while the k-th line (1-based) waits for its answer
        with GrblEmulator(delay=0.2) as grbl:
            def cancel_in_flight():
                while len(grbl.received) < k:
                    time.sleep(0.005)
                self.assertTrue(streaming.cancel())  # what the Cancel operator and Esc call

            canceller = threading.Thread(target=cancel_in_flight, daemon=True)
            canceller.start()
            self.assertEqual(self.send(grbl.port), {'CANCELLED'})
            canceller.join(5)
            time.sleep(0.3)
        self.assertEqual(grbl.received, lines[:k])
        self.assertEqual(grbl.acknowledged, lines[:k - 1])
        self.assertEqual(grbl.realtime, ["!", "\x18"])  # feed hold, then soft reset
        start = step_start(lines, k - 1)  # the soft reset dropped the step's queued moves
        self.assertEqual(streaming.PENDING[self.wire["name"]].next_line, start)
        step = 1 + sum(1 for line in lines[:start] if line == "G4 P0")
        done = f"Done: steps 1-{step - 1} of" if step > 1 else "Done: no step of"
        self.assertIn(f"Cancelled: feed hold and soft reset sent. {done}", streaming.LAST[self.wire["name"]][1])
        self.assertIn(f"Resume restarts step {step} at line {start + 1}.", streaming.LAST[self.wire["name"]][1])
        self.assertFalse(streaming.running())
        self.assertFalse(streaming.cancel())
        with GrblEmulator() as again:
            self.assertEqual(self.send(again.port, resume=True), {'FINISHED'})
        modes = [line for line in lines[:k - 1] if line in MODES]
        self.assertEqual(again.acknowledged, modes + lines[start:])

    def test_bad_port_and_missing_wire_are_one_clear_message(self):
        with self.assertRaisesRegex(RuntimeError, "could not open serial port '/dev/no-such-bender'"):
            self.send("/dev/no-such-bender")
        self.assertNotIn(self.wire["name"], streaming.PENDING)
        with self.assertRaisesRegex(RuntimeError, "no wire 'Nope/7'"):
            bpy.ops.wiresculpt.send_to_machine(wire="Nope/7", port="/dev/null", **FAST)
        with self.assertRaisesRegex(RuntimeError, "no serial port chosen"):
            bpy.ops.wiresculpt.send_to_machine(wire=self.wire["name"], port="", loaded=True)
        with self.assertRaisesRegex(RuntimeError, "no serial port chosen"):  # nor asked to load the wire
            bpy.ops.wiresculpt.send_to_machine(wire=self.wire["name"], port="")


@unittest.skipUnless(shutil.which("xvfb-run"), "xvfb-run is not installed")
@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class ModalSend(unittest.TestCase):
    """Send to Machine as the panel runs it (INVOKE: worker thread, modal timer, status bar)."""

    @classmethod
    def setUpClass(cls):
        cls.result, cls.seen = run_under_xvfb(UI_SCRIPT, "MODAL ")

    def setUp(self):
        output = self.result.stdout[-3000:] + self.result.stderr[-3000:]
        self.assertIsNotNone(self.seen, output)
        self.assertNotIn("error", self.seen, output)

    def test_runs_modal_shows_progress_and_cancels(self):
        self.assertEqual(self.seen["invoke"], ["RUNNING_MODAL"])
        self.assertTrue(self.seen["running"])
        self.assertRegex(self.seen["status"], r"sending .* line \d+ of \d+ .*Esc to cancel")
        self.assertEqual(self.seen["cancel_op"], ["FINISHED"])
        self.assertLess(self.seen["acknowledged_at_cancel"], self.seen["lines"])
        self.assertEqual(self.seen["in_flight_at_cancel"], 1)
        # the soft reset drops the queued moves: the resume starts at the step in doubt
        self.assertEqual(self.seen["pending_next_line"], self.seen["step_start_at_cancel"])
        self.assertLessEqual(self.seen["pending_next_line"], self.seen["acknowledged_at_cancel"])
        self.assertEqual(self.seen["realtime"][-2:], ["!", "\x18"])

    def test_resume_modal_finishes_with_every_line_once(self):
        self.assertEqual(self.seen["resume_invoke"], ["RUNNING_MODAL"])
        self.assertTrue(self.seen["once"])
        self.assertFalse(self.seen["pending_after"])
        self.assertFalse(self.seen["running_after"])


if __name__ == "__main__":
    unittest.main()
