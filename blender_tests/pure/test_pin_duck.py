"""The pin duck, checked by running each G-code program through a small model of
a DIWire-class bend head written here from docs/machine-protocol.md (pin axis), not from the
writer: the bending pin stands up beside the wire and a head rotation that pushes the pin into the
wire bends it; to bend the other way the pin must get to the wire's other side, which it can only
do ducked (pin down), by swinging the head across the wire, then coming up again.

Head angles are in head-axis units (G91: the model adds the moves up). The pin's rest on the side
of positive bends is at angle 0 (where every program starts), the rest on the other side at
+swing (the profile's pin_swing_deg in head units), and the wire lies between the two, at swing / 2.
With the pin up, a move from a rest towards the wire is a bend of that side's sign, a move back to
the rest is the return; any other move with the pin up (a bend that swings away from the wire, or
a swing across the wire with the pin up) is a fault. With the pin down the head moves freely.

    /usr/bin/python3.11 blender_tests/run.py pure pin_duck
"""
import math
import unittest

import numpy as np

from helpers import random_walk
from wiresculpt import native
from wiresculpt.fab import bendlist

EPS = 1e-6


class HeadModel:
    """Tracks the pin (up/down), the head's angle and the pin's side of the wire over G-code lines."""

    def __init__(self, profile):
        self.bend_axis, self.pin_axis = profile["bend_axis"], profile["pin_axis"]
        self.units = profile["bend_units_per_deg"]
        self.swing = profile["pin_swing_deg"] * self.units
        self.wire = 0.5 * self.swing
        self.head = 0.0  # at the positive side's rest
        self.pin_up = True
        self.pin_side = 1  # the side of the wire the pin stands on while up
        self.ducked_at = None  # the head's angle when the pin went down
        self.stroke = None  # while a bend is out: the rest it returns to
        self.bends = []  # the sign of every bend stroke, in order
        self.ducks = 0

    def side_of(self, angle):
        """+1: a pin at head `angle` is on the side where positive moves bend (below the wire), -1: above."""
        return 1 if angle < self.wire else -1

    def rest(self):
        return 0.0 if self.pin_side > 0 else self.swing

    def run(self, line):
        words = line.split()
        if words[0] not in ("G0", "G1"):
            return
        for word in words[1:]:
            letter, value = word[0], float(word[1:])
            if letter == self.pin_axis:
                self._pin(value)
            elif letter == self.bend_axis:
                self._head(value)

    def _pin(self, move):
        assert self.stroke is None, "the pin moves while a bend is out"
        if move < 0:
            assert self.pin_up, "the pin goes down twice"
            self.pin_up, self.ducked_at = False, self.head
        else:
            assert not self.pin_up, "the pin goes up twice"
            before, after = self.side_of(self.ducked_at), self.side_of(self.head)
            assert after == -before, (
                f"the pin comes up on the side it went down (head {self.ducked_at:g} -> {self.head:g}, wire at {self.wire:g})")
            self.pin_up, self.ducked_at, self.pin_side = True, None, after
            assert abs(self.head - self.rest()) < EPS, f"the pin comes up off its rest (head {self.head:g})"
            self.ducks += 1

    def _head(self, move):
        if not self.pin_up:  # ducked: the head swings freely
            self.head += move
            return
        if self.stroke is None:  # from the rest: a bend, which must push the pin into the wire
            assert abs(self.head - self.rest()) < EPS, f"a bend starts off the rest (head {self.head:g})"
            assert move * self.pin_side > 0, (
                f"a bend of sign {'+' if move > 0 else '-'} starts with the pin on the "
                f"{'+' if self.pin_side > 0 else '-'} side: it swings away from the wire")
            self.bends.append(1 if move > 0 else -1)
            self.stroke = self.head
            self.head += move
        else:  # the return of the bend that is out
            assert abs(self.head + move - self.stroke) < EPS, f"the head does not return to its rest ({self.head + move:g})"
            self.head, self.stroke = self.stroke, None


def run(lines, profile):
    model = HeadModel(profile)
    for line in lines:
        model.run(line)
    return model


def zigzag(signs, a=0.03):
    """A polyline whose turns have the given signs (+1 left), each of 45 degrees."""
    pts, heading = [np.zeros(2)], 0.0
    pts.append(pts[-1] + a * np.array([math.cos(heading), math.sin(heading)]))
    for s in signs:
        heading += s * math.pi / 4
        pts.append(pts[-1] + a * np.array([math.cos(heading), math.sin(heading)]))
    return np.array(pts)


class PinDuck(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.w = native.require()

    def check(self, points, given):
        profile = dict(native.validate_machine_profile(given))
        program = native.make_bend_program(points, given)
        lines = native.stream_lines(native.write_gcode(None, points, given, "W/0", "steel"))
        model = run(lines, profile)
        self.assertTrue(model.pin_up)
        self.assertIsNone(model.stroke)
        self.assertEqual(model.pin_side, 1)  # ends where the next program starts
        self.assertLess(abs(model.head), EPS)
        # the bend strokes' signs are the bend list's BEND signs, one for one
        listed = [1 if float(l.split()[1]) > 0 else -1 for l in
                  bendlist.bend_list(program, profile["left_is_positive"]).splitlines() if l.startswith("BEND")]
        self.assertEqual(model.bends, listed)
        return model, listed

    def test_both_sides_in_turn(self):
        signs = [1, -1, -1, 1, -1, 1, 1, -1]
        model, listed = self.check(zigzag(signs), {})
        self.assertEqual(listed, signs)  # left bends positive by default
        changes = sum(1 for a, b in zip([1] + signs, signs) if a != b)
        self.assertEqual(model.ducks, changes + (signs[-1] != 1))  # and one back to the start

    def test_left_is_negative_other_axes_and_units(self):
        given = {"left_is_positive": False, "bend_axis": "B", "feed_axis": "A", "pin_axis": "C",
                 "bend_units_per_deg": 2.0, "pin_swing_deg": 35.0}
        signs = [1, 1, -1, 1, -1, -1]
        model, listed = self.check(zigzag(signs), given)
        self.assertEqual(listed, [-s for s in signs])
        self.assertEqual(model.swing, 70.0)

    def test_a_first_negative_bend_ducks_first(self):
        lines = native.stream_lines(native.write_gcode(None, zigzag([-1, -1]), {}, "W/0", "steel"))
        moves = [l for l in lines if l.startswith("G0")]
        self.assertEqual(moves, ["G0 Z-5.0000", "G0 Y20.0000", "G0 Z5.0000",  # to the negative side
                                 "G0 Z-5.0000", "G0 Y-20.0000", "G0 Z5.0000"])  # and back at the end
        self.check(zigzag([-1, -1]), {})

    def test_random_wires(self):
        for seed in range(6):
            walk = random_walk(seed, n=12)
            model, listed = self.check(walk, {})
            self.assertTrue(listed)

    def test_the_model_catches_the_old_program(self):
        """A program without the duck (pin down, pin up, no swing) fails in the model."""
        profile = dict(native.validate_machine_profile({}))
        with self.assertRaises(AssertionError):
            run(["G0 Z-5.0000", "G0 Z5.0000", "G1 Y-50.0000 F5400.0"], profile)
        with self.assertRaises(AssertionError):  # no duck at all: the bend swings away from the wire
            run(["G1 Y-50.0000 F5400.0"], profile)

    def test_no_pin_axis_writes_no_duck(self):
        lines = native.stream_lines(native.write_gcode(None, zigzag([1, -1, 1]), {"pin_axis": ""}, "W/0", "steel"))
        self.assertFalse([l for l in lines if l.startswith("G0")])


if __name__ == "__main__":
    unittest.main()
