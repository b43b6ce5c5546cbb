"""A closed wire's overlap allowance (profile key closed_overlap, metres): the
bend program of a closed wire feeds that much more straight wire after its last bend, so the
loop's ends overlap; an open wire is unchanged; the template draws the overlap; a value out of
range is one message naming the key. The feeds are read back from the files (CSV, bend list,
G-code) and summed here."""
import csv
import json
import math
import os
import re
import tempfile
import unittest
import xml.etree.ElementTree as ET

from wiresculpt import native
from wiresculpt.core import calibration as cal
from wiresculpt.fab import export

from test_preview import ELL, OCTAGON, design_of

SVG = "{http://www.w3.org/2000/svg}"


def feeds(folder, stem):
    """(CSV feeds, bend-list FEEDs, G-code feed-axis moves) summed, mm."""
    with open(os.path.join(folder, "bends", stem + ".csv"), newline="") as f:
        table = sum(float(r["feed_mm"]) for r in csv.DictReader(f))
    with open(os.path.join(folder, "bendlist", stem + ".txt")) as f:
        listed = sum(float(line.split()[1]) for line in f if line.startswith("FEED"))
    with open(os.path.join(folder, "gcode", stem + ".gcode")) as f:
        moved = sum(float(m.group(1)) for line in f if not line.startswith(";")
                    for m in [re.search(r"\bX(-?[0-9.]+)", line)] if m)
    return table, listed, moved


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class OverlapTest(unittest.TestCase):
    def export(self, profile):
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        result = export.export(design_of([OCTAGON, ELL], [True, False]), tmp.name, profile)
        self.assertEqual(result["errors"], [])
        return tmp.name

    def test_the_closed_wire_feeds_exactly_the_allowance_more(self):
        plain = self.export(None)
        overlapped = self.export({"closed_overlap": 0.02})
        # the octagon: 8 sides of 40 mm, plus 20 mm; the L (open) keeps its 30 + 50 mm
        for stem, before, after in (("00-W-0", 320.0, 340.0), ("01-W-1", 80.0, 80.0)):
            for a, b in zip(feeds(plain, stem), feeds(overlapped, stem)):
                self.assertAlmostEqual(a, before, delta=0.01)
                self.assertAlmostEqual(b, after, delta=0.01)
        # the overlap is straight on: the same bends, in the same order
        for stem in ("00-W-0", "01-W-1"):
            with open(os.path.join(plain, "bends", stem + ".csv")) as f, \
                    open(os.path.join(overlapped, "bends", stem + ".csv")) as g:
                self.assertEqual([r["bend_deg"] for r in csv.DictReader(f)], [r["bend_deg"] for r in csv.DictReader(g)])

    def test_the_template_draws_the_overlap(self):
        folder = self.export({"closed_overlap": 0.02})
        root = ET.parse(os.path.join(folder, "templates", "00-W-0.svg")).getroot()
        band = root.find(f".//{SVG}g[@class='overlap']")
        self.assertIsNotNone(band)
        self.assertAlmostEqual(float(band.get("data-mm")), 20.0, places=3)
        self.assertIn("overlap 20.0 mm", "".join(band.itertext()))
        pts = [[float(v) for v in p.split(",")] for p in band.find(f"{SVG}polyline").get("points").split()]
        self.assertAlmostEqual(sum(math.dist(a, b) for a, b in zip(pts, pts[1:])), 20.0, delta=1e-3)
        open_root = ET.parse(os.path.join(folder, "templates", "01-W-1.svg")).getroot()
        self.assertIsNone(open_root.find(f".//{SVG}g[@class='overlap']"))

    def test_a_value_out_of_range_is_one_message_naming_the_key(self):
        for bad in (-0.01, 0.5, "20 mm", float("nan"), True):
            with self.assertRaisesRegex(ValueError, "closed_overlap must be a length in metres between 0 and 0.2"):
                cal.validate_profile(dict(cal.default_profile(), closed_overlap=bad))
            with tempfile.TemporaryDirectory() as folder:
                with self.assertRaisesRegex(ValueError, "closed_overlap"):
                    export.export(design_of([OCTAGON], [True]), folder, {"closed_overlap": bad})
                self.assertEqual(os.listdir(folder), [])
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "bender.json")
            with open(path, "w") as f:
                json.dump({"format": cal.PROFILE_FORMAT, "version": 1, "closed_overlap": 20}, f)
            with self.assertRaisesRegex(ValueError, "bender.json.*closed_overlap"):
                cal.load_profile(path)
            saved = cal.save_profile(dict(cal.default_profile(), closed_overlap=0.015), path)
            self.assertEqual(cal.load_profile(saved)["closed_overlap"], 0.015)


if __name__ == "__main__":
    unittest.main()
