"""The Machine panel and its operators, headless, against the pseudo-terminal GRBL emulator: Connect,
the status line, Hold and Resume, Home and Unlock, jogs in mm and degrees, one console line; the
"load the wire" step before each wire of Send All (the panel says the wire, its length as its
G-code's header and the stock; Continue sends it); the test bends fill the Calibration rows and
the typed angles fit the spring-back line; a dropped link's stop as a box of short lines whose
Resume button starts at the step and line it names. Figures by hand: a jog of 12.5 mm ends at
X 12.5; rows measured = 0.9 x commanded - 1 fit a = 0.9, b = -1.

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- machine_panel
"""
import math
import os
import time
import unittest

import bpy

from helpers import DesignSuite, GrblEmulator, draw, gcode_lines, step_start
from wiresculpt import native
from wiresculpt.blend import calibration as scene_calibration
from wiresculpt.core import machine_words as words
from wiresculpt.fab import export, grbl, streaming
from wiresculpt.ui import calibration as calibration_ui
from wiresculpt.ui import fabrication as fabrication_ui
from wiresculpt.ui import machine as machine_ui

FAST = {"settle": 0.05, "response_timeout": 2.0}


def ring_design(names=("Ring/0", "Ring/1"), n=12, side=0.04):
    """Wires that are regular n-gons walked from the cut (n bends of 360/n deg each)."""
    pts, x, y = [[0.0, 0.0]], 0.0, 0.0
    for k in range(n):
        x += side * math.cos(2 * math.pi * k / n)
        y += side * math.sin(2 * math.pi * k / n)
        pts.append([x, y])
    wires = [{"id": i, "name": name, "closed": True, "target": [p + [0.0] for p in pts[:-1]], "cut": 0,
              "rest": pts, "length": n * side} for i, name in enumerate(names)]
    return {"format": "wiresculpt-design", "version": 1, "units": "m",
            "material": {"name": "steel", "wire_diameter": 0.003, "bending_stiffness": 0.73, "max_torque": 1.77,
                         "friction": 0.32},
            "machine": {"min_segment": 0.015, "max_bend_deg": 120.0, "min_bend_deg": 1.0},
            "wires": wires, "crossings": [], "stable": True, "reason": "", "stages": {}}


def labels(log):
    return [kw.get("text", args[0] if args else "") for name, args, kw in log if name == "label"]


def shown(log):
    """The panel's text as one line: its labels joined (a wrapped sentence reads whole again)."""
    return " ".join(labels(log))


def operators(log):
    return [(args[0], kw.get("text")) for name, args, kw in log if name == "operator"]


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class MachinePanel(DesignSuite):
    @classmethod
    def make_design(cls):
        return ring_design()

    @classmethod
    def tearDownClass(cls):
        grbl.disconnect()
        super().tearDownClass()

    def setUp(self):
        streaming.forget()
        grbl.disconnect()
        self.ws = bpy.context.scene.wiresculpt
        self.ws.machine_profile = ""

    def connect(self, emulator):
        self.ws.fab_port = emulator.port
        self.assertEqual(bpy.ops.wiresculpt.machine_connect(settle=0.0), {'FINISHED'})
        self.addCleanup(grbl.disconnect)
        return grbl.SESSION

    def test_panel_draws_without_and_with_a_connection(self):
        log = draw(machine_ui.VIEW3D_PT_wiresculpt_machine, bpy.context)
        self.assertIn(("wiresculpt.machine_connect", None), operators(log))
        with GrblEmulator() as emu:
            session = self.connect(emu)
            session.query()
            log = draw(machine_ui.VIEW3D_PT_wiresculpt_machine, bpy.context)
            drawn = shown(log)
            self.assertIn("Idle · feed 0.000 mm · bend +0.00°", drawn)  # wrapped labels, read whole
            ops = [o for o, _t in operators(log)]
            for op in ("wiresculpt.machine_realtime", "wiresculpt.machine_command", "wiresculpt.machine_jog",
                       "wiresculpt.machine_console", "wiresculpt.machine_test_bends"):
                self.assertIn(op, ops)

    def test_status_hold_resume_home_unlock_jog_and_console(self):
        with GrblEmulator(alarm=True, move_time=0.6) as emu:
            session = self.connect(emu)
            self.assertEqual(bpy.ops.wiresculpt.machine_realtime(command="STATUS"), {'FINISHED'})
            self.assertEqual(session.status["state"], "Alarm")
            with self.assertRaisesRegex(RuntimeError, r"error:9 \(G-code locked out"):
                bpy.ops.wiresculpt.machine_jog(axis=grbl.FEED, direction=1.0)
            self.assertEqual(bpy.ops.wiresculpt.machine_command(command="UNLOCK"), {'FINISHED'})
            self.assertEqual(session.log[-1].info, ["[MSG:Caution: Unlocked]"])
            self.ws.machine_jog_feed = 12.5
            self.ws.machine_jog_bend = 30.0
            self.assertEqual(bpy.ops.wiresculpt.machine_jog(axis=grbl.FEED, direction=1.0), {'FINISHED'})
            self.assertEqual(bpy.ops.wiresculpt.machine_jog(axis=grbl.BEND, direction=-1.0), {'FINISHED'})
            self.assertEqual(emu.received[-2:], ["$J=G91 G21 X12.5000 F1200.0", "$J=G91 G21 Y-30.0000 F5400.0"])
            # the jogs are queued in GRBL, 0.6 s each: a feed hold keeps them where they are
            self.assertEqual(bpy.ops.wiresculpt.machine_realtime(command="HOLD"), {'FINISHED'})
            time.sleep(0.1)
            self.assertEqual(session.query()["state"], "Hold")
            held = session.status["mpos"]
            time.sleep(0.7)
            self.assertEqual(session.query()["mpos"], held)
            self.assertEqual(bpy.ops.wiresculpt.machine_realtime(command="RESUME"), {'FINISHED'})
            end = time.monotonic() + 3
            while session.query()["state"] != "Idle" and time.monotonic() < end:
                time.sleep(0.05)
            feed, bend = grbl.machine_position(session.status, session.profile)
            self.assertEqual((round(feed, 3), round(bend, 3)), (12.5, -30.0))
            self.assertEqual(bpy.ops.wiresculpt.machine_command(command="HOME"), {'FINISHED'})
            self.assertEqual(session.query()["mpos"], (0.0, 0.0, 0.0))
            self.assertEqual(emu.homed, 1)
            self.ws.machine_console = "$G"
            self.assertEqual(bpy.ops.wiresculpt.machine_console(), {'FINISHED'})
            self.assertEqual(emu.received[-1], "$G")
            self.ws.machine_console = "G1 X1!"
            with self.assertRaisesRegex(RuntimeError, "realtime commands"):
                bpy.ops.wiresculpt.machine_console()
            log = draw(machine_ui.VIEW3D_PT_wiresculpt_machine, bpy.context)
            self.assertIn("$G  →  ok", shown(log))
            self.assertEqual(emu.realtime, ["!", "~"])

    def test_commands_need_a_connection(self):
        with self.assertRaisesRegex(RuntimeError, "Connect to the machine first"):
            bpy.ops.wiresculpt.machine_command(command="HOME")

    def test_send_all_asks_to_load_each_wire_and_streams_on_the_open_link(self):
        out = os.path.join(self.tmp.name, "files")
        self.assertEqual(bpy.ops.wiresculpt.export_fabrication(directory=out), {'FINISHED'})
        programs = {w["name"]: gcode_lines(os.path.join(out, "gcode", export.file_stem(w) + ".gcode"))
                    for w in self.design["wires"]}
        with GrblEmulator() as emu:
            session = self.connect(emu)
            self.assertEqual(bpy.ops.wiresculpt.send_all(), {'FINISHED'})
            load = streaming.LOAD
            self.assertEqual(load.wire, "Ring/0")
            # the length the machine feeds: the G-code header's, 12 sides of 40 mm
            self.assertAlmostEqual(load.facts["length_mm"], 480.0, places=6)
            log = draw(fabrication_ui.VIEW3D_PT_wiresculpt_fabrication, bpy.context)
            self.assertIn("Load wire Ring/0 (1 of 2): 480 mm of 3 mm steel, from stock of 1000 mm "
                          "(the default machine profile). Feed its end to the bend head, then Continue.", shown(log))
            self.assertIn(("wiresculpt.send_to_machine", "Continue"), operators(log))
            self.assertEqual(emu.received, [])  # nothing is sent before Continue
            # Continue: the first wire, then the panel asks for the second
            self.assertEqual(bpy.ops.wiresculpt.send_to_machine(wire="Ring/0", loaded=True, **FAST), {'FINISHED'})
            self.assertEqual(streaming.LOAD.wire, "Ring/1")
            self.assertEqual(streaming.LOAD.facts["index"], 2)
            self.assertEqual(bpy.ops.wiresculpt.send_to_machine(wire="Ring/1", loaded=True, **FAST), {'FINISHED'})
            self.assertIsNone(streaming.LOAD)
            self.assertEqual(emu.received, programs["Ring/0"] + programs["Ring/1"])
            self.assertFalse(session.lost)
            self.assertEqual(session.query()["state"], "Idle")  # the same link, still open

    def test_no_stream_starts_on_the_link_while_a_line_waits_for_its_answer(self):
        with GrblEmulator(answers={1: b""}) as emu:  # the first line is never answered
            session = self.connect(emu)
            waiting = session.send("$I")
            with self.assertRaisesRegex(RuntimeError, "still waits for GRBL's answer"):
                bpy.ops.wiresculpt.send_to_machine(wire="Ring/0", loaded=True, **FAST)
            end = time.monotonic() + 3
            while not emu.received and time.monotonic() < end:  # the emulator's thread reads it
                time.sleep(0.01)
            self.assertEqual(emu.received, ["$I"])
            session.wait(waiting, 0.1)  # given up: the link is free again
            self.assertEqual(bpy.ops.wiresculpt.send_to_machine(wire="Ring/0", loaded=True, **FAST), {'FINISHED'})

    def test_send_without_continue_only_asks(self):
        with GrblEmulator() as emu:
            self.ws.fab_port = emu.port
            self.assertEqual(bpy.ops.wiresculpt.send_to_machine(wire="Ring/1", **FAST), {'FINISHED'})
            self.assertEqual(streaming.LOAD.wire, "Ring/1")
            time.sleep(0.1)
            self.assertEqual(emu.received, [])
            self.assertEqual(bpy.ops.wiresculpt.load_cancel(), {'FINISHED'})
            self.assertIsNone(streaming.LOAD)

    def test_a_dropped_link_is_a_box_with_a_resume_from_step_button(self):
        out = os.path.join(self.tmp.name, "drop")
        self.assertEqual(bpy.ops.wiresculpt.export_fabrication(directory=out), {'FINISHED'})
        wire = self.design["wires"][0]
        lines = gcode_lines(os.path.join(out, "gcode", export.file_stem(wire) + ".gcode"))
        k = 22  # the cable is pulled when the 22nd line arrives: lines 20 and 21 (step 5's feed and bend) are queued
        start = step_start(lines, k - 1)
        self.assertLess(start, k - 1)  # so step 5 is in doubt
        dwells = [i for i, line in enumerate(lines) if line == "G4 P0"]
        step = 1 + sum(1 for i in dwells if i < start)  # by hand: the step whose first line is `start`
        step_end = next(i for i in dwells if i >= start)
        with GrblEmulator(drop_on=k) as emu:
            with self.assertRaises(RuntimeError) as ctx:
                bpy.ops.wiresculpt.send_to_machine(wire=wire["name"], port=emu.port, loaded=True, **FAST)
        report = str(ctx.exception)
        self.ws.fab_wire = wire["name"]
        log = draw(fabrication_ui.VIEW3D_PT_wiresculpt_fabrication, bpy.context)
        text = shown(log)
        self.assertTrue(all(len(line) <= 60 for line in labels(log)), labels(log))  # wrapped to the sidebar
        box = (f"Wire {wire['name']} stopped. The link to {emu.port} dropped (or GRBL restarted). "
               f"Done: steps 1-{step - 1} of {len(dwells)}. "
               f"Step {step} (lines {start + 1}-{step_end + 1}: feed 40.0 mm, bend +30.0°) may be half made: "
               f"check the wire before resuming. Resume restarts step {step} at line {start + 1}.")
        self.assertIn(box, text)
        self.assertIn(("wiresculpt.send_to_machine", f"Resume from Step {step}"), operators(log))
        self.assertEqual(report.strip().removeprefix("Error: "), box)  # the report says the box, nothing else
        # the button's Resume makes the step again on a new link, to the end
        with GrblEmulator() as again:
            self.assertEqual(bpy.ops.wiresculpt.send_to_machine(wire=wire["name"], port=again.port, resume=True,
                                                                **FAST), {'FINISHED'})
        self.assertEqual(again.acknowledged, ["G21", "G91", "G94"] + lines[start:])

    def test_test_bends_fill_the_rows_and_the_typed_angles_fit_spring_back(self):
        scene = bpy.context.scene
        scene.wiresculpt_calibration.springback_rows.clear()
        scene.pop(scene_calibration.RESULTS_KEY, None)
        with GrblEmulator() as emu:
            self.ws.fab_port = emu.port
            self.assertEqual(bpy.ops.wiresculpt.machine_test_bends(), {'FINISHED'})
            self.assertEqual(streaming.LOAD.kind, "test")
            log = draw(machine_ui.VIEW3D_PT_wiresculpt_machine, bpy.context)
            self.assertIn("Load a straight test piece: 280 mm of 3 mm steel. It gets 6 bends commanded "
                          "15, 30, 45, 60, 90, 120°.", shown(log))
            self.assertEqual(bpy.ops.wiresculpt.send_to_machine(test=True, loaded=True, **FAST), {'FINISHED'})
        lines, _m, _c, _l = grbl.test_bend_program()
        self.assertEqual(emu.received, lines)
        rows = scene.wiresculpt_calibration.springback_rows
        self.assertEqual([r.commanded_deg for r in rows], list(grbl.TEST_ANGLES))
        log = draw(calibration_ui.VIEW3D_PT_wiresculpt_calibration, bpy.context)
        self.assertIn(("wiresculpt.calibration_fit_rows", None), operators(log))
        for r in rows:  # the bench measures 0.9 x commanded - 1
            r.measured_deg = 0.9 * r.commanded_deg - 1.0
        self.assertEqual(bpy.ops.wiresculpt.calibration_fit_rows(), {'FINISHED'})
        fit = scene_calibration.results(scene)["springback"]
        self.assertAlmostEqual(fit["springback_a"], 0.9, places=9)
        self.assertAlmostEqual(fit["springback_b_deg"], -1.0, places=7)
        self.assertEqual(fit["samples"], 6)
        scene.pop(scene_calibration.RESULTS_KEY, None)

    def test_a_test_piece_stopped_by_a_dropped_link_resumes_from_the_machine_panel(self):
        scene = bpy.context.scene
        scene.wiresculpt_calibration.springback_rows.clear()
        lines, _m, _c, _l = grbl.test_bend_program()
        k = 10  # lines 8-9 (step 2's feed and bend out) queued when the cable is pulled
        start = step_start(lines, k - 1)
        self.assertLess(start, k - 1)
        with GrblEmulator(drop_on=k) as emu:
            self.ws.fab_port = emu.port
            with self.assertRaisesRegex(RuntimeError, "The test piece stopped"):
                bpy.ops.wiresculpt.send_to_machine(test=True, loaded=True, **FAST)
        self.assertEqual(len(scene.wiresculpt_calibration.springback_rows), 0)  # not bent: no rows yet
        log = draw(machine_ui.VIEW3D_PT_wiresculpt_machine, bpy.context)
        self.assertIn(("wiresculpt.send_to_machine", "Resume from Step 2"), operators(log))
        with GrblEmulator() as again:
            self.ws.fab_port = again.port
            self.assertEqual(bpy.ops.wiresculpt.send_to_machine(test=True, resume=True, **FAST), {'FINISHED'})
        self.assertEqual(again.acknowledged, ["G21", "G91", "G94"] + lines[start:])
        self.assertEqual([r.commanded_deg for r in scene.wiresculpt_calibration.springback_rows],
                         list(grbl.TEST_ANGLES))
        log = draw(machine_ui.VIEW3D_PT_wiresculpt_machine, bpy.context)
        self.assertIn("The test piece done: all 7 steps", shown(log))

    def test_stop_words_are_short_lines_with_one_numbering(self):
        facts = {"wire": "W", "port": "/dev/ttyUSB0", "status": "error", "code": 20, "failed_line": 84,
                 "resume_line": 84, "resume_step": 12, "steps": 30, "done_steps": 11, "in_doubt": False,
                 "step_lines": (84, 90), "feed_mm": 40.0, "bend_deg": 90.0, "total_lines": 200, "why": ""}
        shown = words.stop_lines(facts)
        self.assertEqual(shown, ["Wire W stopped.", "GRBL refused line 84 with error:20 (an unsupported G-code).",
                                 "Done: steps 1-11 of 30.", "Line 84 was not run: fix it, then resume.",
                                 "Resume continues step 12 at line 84."])
        self.assertEqual(words.resume_button(facts), "Resume from Step 12")
        # past the last step (the pin back and M2) there is no step to name: the line
        self.assertEqual(words.resume_button(dict(facts, resume_step=31, resume_line=199)), "Resume at Line 199")


if __name__ == "__main__":
    unittest.main()
