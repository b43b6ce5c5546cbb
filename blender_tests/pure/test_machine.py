"""The Machine panel's protocol (fab/grbl.py) against the pseudo-terminal GRBL emulator
(helpers.GrblEmulator): the status report, feed hold and resume, home, unlock, jogs in the
profile's units, a console line, and the stream run on the panel's open link. The figures are
known by hand: a jog of 12.5 mm at 4 units/mm ends at X 50; a feed hold keeps the position where
the queued moves stood.

    /usr/bin/python3.11 blender_tests/run.py pure machine
"""
import time
import unittest

from helpers import GrblEmulator
from wiresculpt import native
from wiresculpt.fab import grbl, streaming


def until(predicate, timeout=3.0, machine=None):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if machine is not None:
            machine.poll(0.02)
        else:
            time.sleep(0.02)
        if predicate():
            return True
    return False


class StatusReport(unittest.TestCase):
    def test_grbl_11_with_machine_position(self):
        s = grbl.parse_status("<Hold:0|MPos:12.500,-30.000,5.000|FS:0,0>")
        self.assertEqual((s["state"], s["substate"], s["mpos"]), ("Hold", 0, (12.5, -30.0, 5.0)))

    def test_work_position_with_offset_gives_the_machine_position(self):
        s = grbl.parse_status("<Idle|WPos:1.000,2.000,3.000|FS:0,0|WCO:10.000,20.000,30.000>")
        self.assertEqual(s["mpos"], (11.0, 22.0, 33.0))

    def test_grbl_09(self):
        s = grbl.parse_status("<Run,MPos:1.000,2.000,3.000,WPos:0.000,0.000,0.000>")
        self.assertEqual((s["state"], s["mpos"], s["wpos"]), ("Run", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0)))

    def test_other_lines_are_no_report(self):
        for text in ("ok", "error:9", "[MSG:Caution: Unlocked]", "<>", "<Idle"):
            self.assertIsNone(grbl.parse_status(text), text)

    def test_position_in_the_profiles_units(self):
        profile = dict(native.default_machine_profile(), feed_units_per_mm=4.0, bend_units_per_deg=2.0,
                       left_is_positive=False)
        feed, bend = grbl.machine_position(grbl.parse_status("<Idle|MPos:50.000,-60.000,0.000|FS:0,0>"), profile)
        self.assertAlmostEqual(feed, 12.5)
        self.assertAlmostEqual(bend, 30.0)  # Y -60 with 2 units/deg, left negative: 30 deg left


class JogAndConsole(unittest.TestCase):
    def test_jog_lines_in_axis_units(self):
        profile = dict(native.default_machine_profile(), feed_units_per_mm=4.0, bend_units_per_deg=2.0,
                       feed_speed_mm_s=20.0, bend_speed_deg_s=90.0)
        # 12.5 mm at 4 units/mm = X50; F = 20 mm/s * 60 * 4 = 4800 units/min
        self.assertEqual(grbl.jog_line(grbl.FEED, 12.5, profile), "$J=G91 G21 X50.0000 F4800.0")
        # -15 deg at 2 units/deg = Y-30; F = 90 * 60 * 2 = 10800
        self.assertEqual(grbl.jog_line(grbl.BEND, -15.0, profile), "$J=G91 G21 Y-30.0000 F10800.0")
        with self.assertRaises(ValueError):
            grbl.jog_line(grbl.FEED, 0.0, profile)

    def test_console_line_faults(self):
        self.assertIsNone(grbl.line_fault("$$"))
        self.assertIsNone(grbl.line_fault("?"))
        self.assertEqual(grbl.line_fault(""), grbl.LINE_EMPTY)
        self.assertEqual(grbl.line_fault("G1 X" + "1" * 80), grbl.LINE_TOO_LONG)
        self.assertEqual(grbl.line_fault("G1 X1!"), grbl.LINE_REALTIME)
        self.assertEqual(grbl.line_fault("G1 X1\t"), grbl.LINE_NOT_PRINTABLE)


class TestBends(unittest.TestCase):
    def test_commanded_angles_are_the_known_ones(self):
        lines, machine, commanded, length = grbl.test_bend_program()
        self.assertEqual([round(c, 6) for c in commanded[:6]], list(grbl.TEST_ANGLES))
        # the G-code's bend moves (Y, G1, away from neutral) are exactly the angles, uncompensated
        outs = [float(l.split()[1][1:]) for l in lines if l.startswith("G1 Y") and not l.startswith("G1 Y-")]
        self.assertEqual([round(v, 4) for v in outs], list(grbl.TEST_ANGLES))
        self.assertAlmostEqual(length, 7 * grbl.TEST_FEED, places=9)
        # a profile with a spring-back line does not compensate the test piece
        lines2, _m, commanded2, _l = grbl.test_bend_program(dict(native.default_machine_profile(),
                                                                 springback_a=1.1, springback_b_deg=2.0))
        self.assertEqual(lines2, lines)


class AgainstTheEmulator(unittest.TestCase):
    def machine(self, grbl_emulator, profile=None):
        m = grbl.Machine(grbl_emulator.port, profile, settle=0.0)
        self.addCleanup(m.close)
        return m

    def test_status_home_and_unlock(self):
        with GrblEmulator(alarm=True, home_time=0.6) as emu:
            m = self.machine(emu)
            self.assertEqual(m.query()["state"], "Alarm")
            refused = m.wait(m.send("G1 X5 F600"), 2.0)
            self.assertEqual((refused.answer, refused.code), (grbl.ERROR, 9))
            unlock = m.wait(m.send("$X"), 2.0)
            self.assertEqual(unlock.answer, grbl.OK)
            self.assertEqual(unlock.info, ["[MSG:Caution: Unlocked]"])
            self.assertEqual(m.query()["state"], "Idle")
            jog = m.wait(m.send("$J=G91 G21 X10.0000 F600.0"), 2.0)
            self.assertEqual(jog.answer, grbl.OK)
            self.assertTrue(until(lambda: m.status and m.status["mpos"] == (10.0, 0.0, 0.0), machine=m))
            home = m.send("$H")
            # while the homing cycle runs GRBL reports Home and the $H waits for its ok
            self.assertTrue(until(lambda: (m.query(0.2) or {}).get("state") == "Home", timeout=0.4))
            self.assertFalse(home.done)
            m.wait(home, 3.0)
            self.assertEqual(home.answer, grbl.OK)
            self.assertEqual(m.query()["mpos"], (0.0, 0.0, 0.0))
            self.assertEqual(emu.homed, 1)
            self.assertGreater(emu.status_queries, 3)

    def test_feed_hold_and_resume(self):
        with GrblEmulator(move_time=0.4) as emu:
            m = self.machine(emu)
            for line in ("G91", "G1 X10 F600", "G1 X10 F600", "G1 X10 F600"):
                self.assertEqual(m.wait(m.send(line), 2.0).answer, grbl.OK)
            self.assertEqual(m.query()["state"], "Run")
            self.assertTrue(m.realtime(b"!"))
            self.assertTrue(until(lambda: m.status and m.status["state"] == "Hold", machine=m))
            held = m.query()["mpos"]
            time.sleep(0.9)  # longer than two moves: nothing moves in a feed hold
            self.assertEqual(m.query()["mpos"], held)
            self.assertLess(held[0], 30.0)
            self.assertTrue(m.realtime(b"~"))
            self.assertTrue(until(lambda: m.status and m.status["state"] == "Idle", timeout=3.0, machine=m))
            self.assertEqual(m.status["mpos"], (30.0, 0.0, 0.0))
            self.assertEqual(emu.realtime, ["!", "~"])

    def test_console_realtime_and_a_dropped_link(self):
        with GrblEmulator(drop_on=2) as emu:
            m = self.machine(emu)
            self.assertEqual(m.wait(m.send("$$"), 2.0).answer, grbl.OK)
            self.assertEqual(m.send("?").answer, grbl.OK)  # a realtime byte, no line
            self.assertTrue(until(lambda: m.status is not None, machine=m))
            lost = m.wait(m.send("$G"), 2.0)
            self.assertEqual(lost.answer, grbl.LOST)
            self.assertTrue(m.lost)
            self.assertEqual(emu.received, ["$$", "$G"])

    def test_a_line_never_answered(self):
        with GrblEmulator(answers={1: b""}) as emu:
            m = self.machine(emu)
            self.assertEqual(m.wait(m.send("$I"), 0.3).answer, grbl.NO_ANSWER)
            self.assertFalse(m.busy())

    def test_stream_on_the_open_link_keeps_the_position(self):
        with GrblEmulator() as emu:
            m = self.machine(emu)
            m.wait(m.send("$J=G91 G21 X7.0000 F600.0"), 2.0)
            lines = ["G21", "G91", "G94", "G1 X5.0000 F1200.0", "G4 P0", "M2"]
            state = {}
            r = native.stream_program(m.link, lines, {}, state, response_timeout=2.0)
            self.assertEqual((r["status"], state["next_line"]), ("completed", 6))
            self.assertEqual(m.query()["mpos"], (12.0, 0.0, 0.0))  # not reset by reopening: 7 + 5
            self.assertEqual(emu.received[1:], lines)

    def test_a_streams_feed_hold_freezes_the_machine_and_resume_finishes(self):
        import threading

        with GrblEmulator(move_time=0.3) as emu:
            m = self.machine(emu)
            lines = ["G21", "G91", "G94"] + ["G1 X10.0000 F1200.0"] * 6 + ["G4 P0", "M2"]
            state = {}
            job = streaming.StreamJob("W", emu.port, lines, native.validate_machine_profile({}), state,
                                      response_timeout=5.0, link=m.link)
            worker = threading.Thread(target=job.run)
            worker.start()
            self.assertTrue(until(lambda: len(emu.received) >= 8))
            streaming.hold(job)  # the panel's Hold during a stream on its link: at once, inside the step
            self.assertTrue(until(lambda: emu.state() == "Hold:0"))
            held = list(emu.position)
            time.sleep(0.7)  # over two moves' time: nothing moves in the hold
            self.assertEqual(emu.position, held)
            self.assertLess(held[0], 60.0)
            streaming.go_on(job)
            worker.join(10)
            self.assertIsNone(job.error)
            self.assertEqual(job.result["status"], "completed")
            self.assertEqual(emu.position, [60.0, 0.0, 0.0])  # 6 x 10 mm, none lost, none twice
            self.assertEqual(emu.realtime[0], "!")
            self.assertEqual(set(emu.realtime), {"!", "~"})  # the streamer may add its own hold and resume
            self.assertEqual(m.query()["state"], "Idle")


if __name__ == "__main__":
    unittest.main()
