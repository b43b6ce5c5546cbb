"""The bend list for DIWire-class machines (fab/bendlist.py), read back the way FabMo's Bend List
app reads it (github.com/FabMo/fabmo-bendlist-app, js/bend.js: its line rules and its pin ducking,
rewritten here from that source, not from ours) and bent on paper: walking the FEEDs and the BENDs
(spring-back applied to the commanded angle) redraws the wire's rest shape."""
import math
import os
import re
import tempfile
import unittest

import numpy as np

from helpers import random_walk
from wiresculpt import native
from wiresculpt.fab import bendlist


def fabmo_parse(text):
    """[(command, argument)] as the app's parser reads the text (its first matching rule per
    line); AssertionError on a line it would reject. REPEAT is not expected in our lists."""
    out = []
    for i, raw in enumerate(text.split("\n")):
        line = raw.strip().lower()
        bend = re.search(r"bend\s+(-?\d+(?:\.\d+)?)", line)
        feed = re.search(r"feed\s+(-?\d+(?:\.\d+)?)", line)
        unit = re.search(r"unit\s+((?:inch|inches|mm|millimeter))", line)
        if bend:
            out.append(("bend", float(bend.group(1))))
            self_check = re.fullmatch(r"bend -?\d+(\.\d+)?", line)  # nothing else on the line
        elif feed:
            out.append(("feed", float(feed.group(1))))
            self_check = re.fullmatch(r"feed \d+(\.\d+)?", line)
        elif unit:
            out.append(("unit", unit.group(1)))
            self_check = True
        elif re.search(r"repeat\s+(\d+):", line) or "end" in line or re.search(r"//|'", line):
            raise AssertionError(f"line {i + 1} {raw!r} would be read as REPEAT, END or a comment")
        elif line == "":
            self_check = True
        else:
            raise AssertionError(f"line {i + 1} {raw!r}: the app reports a syntax error")
        if not self_check:
            raise AssertionError(f"line {i + 1} {raw!r} holds more than its command")
    return out


def fabmo_ducks(commands):
    """How many times the app's compiler ducks the pin: at every BEND whose side differs from the
    previous bend's (its current angle starts at 0, which counts as the negative side)."""
    current, ducks = 0.0, 0
    for cmd, arg in commands:
        if cmd == "bend":
            if (current <= 0) != (arg <= 0):
                ducks += 1
            current = arg
    return ducks


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class BendList(unittest.TestCase):
    A, B = 0.93, -1.8  # spring-back: measured = A * commanded + B (degrees, magnitudes)

    def check(self, pts, left_is_positive):
        w = native.module
        profile = {"springback_a": self.A, "springback_b_deg": self.B, "left_is_positive": left_is_positive}
        program = w.make_bend_program(pts, profile)
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "wire.txt")
            text = bendlist.write_bend_list(path, program, left_is_positive)
            with open(path, encoding="ascii") as f:
                self.assertEqual(f.read(), text)
        commands = fabmo_parse(text)
        self.assertEqual(commands[0], ("unit", "mm"))
        # bent on paper: start at the first point along the first edge; left turns counter-clockwise
        side = 1.0 if left_is_positive else -1.0
        first = pts[1] - pts[0]
        heading, at, drawn = math.atan2(first[1], first[0]), pts[0].copy(), [pts[0].copy()]
        for cmd, arg in commands[1:]:
            if cmd == "feed":
                at = at + arg / 1000.0 * np.array([math.cos(heading), math.sin(heading)])
                drawn.append(at.copy())
            else:
                commanded = side * arg  # the head's move back to a left (+) or right (-) command
                measured = self.A * abs(commanded) + self.B
                heading += math.radians(math.copysign(measured, commanded))
        drawn = np.array(drawn)
        self.assertEqual(drawn.shape, pts.shape)
        self.assertLess(np.abs(drawn - pts).max() * 1000.0, 0.1)  # mm
        # the pin: the app ducks at each change of side, which the polyline's turns say
        edges = np.diff(pts, axis=0)
        turns = edges[:-1, 0] * edges[1:, 1] - edges[:-1, 1] * edges[1:, 0]
        heads = [side * t for t in turns if abs(t) > 1e-12]
        expected, current = 0, 0.0
        for h in heads:
            expected += (current <= 0) != (h <= 0)
            current = h
        self.assertEqual(fabmo_ducks(commands), expected)
        return commands, expected

    def test_random_walks_are_redrawn_from_the_list(self):
        ducks = 0
        for seed in range(6):
            for left in (True, False):
                _commands, d = self.check(random_walk(seed), left)
                ducks += d
        self.assertGreater(ducks, 10)

    def test_square_and_the_numbers(self):
        a = 0.05
        pts = np.array([[0, 0], [a, 0], [a, a], [0, a], [0, 0.0]])
        commands, ducks = self.check(pts, True)
        self.assertEqual([c for c, _ in commands], ["unit", "feed", "bend", "feed", "bend", "feed", "bend", "feed"])
        expected = (90 - self.B) / self.A
        for cmd, arg in commands:
            if cmd == "bend":
                self.assertAlmostEqual(arg, expected, places=3)
        self.assertEqual(ducks, 1)  # the first bend is positive: once to the positive side, then no change

    def test_parser_rules_refuse_what_the_app_misreads(self):
        with self.assertRaises(AssertionError):
            fabmo_parse("UNIT MM\n; the end\n")
        with self.assertRaises(AssertionError):
            fabmo_parse("FEED 1e-3\n")


if __name__ == "__main__":
    unittest.main()
