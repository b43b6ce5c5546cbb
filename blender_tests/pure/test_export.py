"""Fabrication files of a solved design: every file at 1:1 in mm, checked by parsing it back."""
import csv
import math
import os
import re
import tempfile
import unittest
import xml.etree.ElementTree as ET

import numpy as np

from wiresculpt import native, pipeline
from wiresculpt.fab import export
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.scene import PlaneSpec
from wiresculpt.core.settings import defaults

from helpers import edge_lengths, sphere


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class ExportTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        V, F = sphere()
        planes = [PlaneSpec(n, (0, 0, 0), normal) for n, normal in
                  (("Equator", (0, 0, 1)), ("Meridian0", (1, 0, 0)), ("Meridian90", (0, 1, 0)))]
        cls.design = pipeline.run(V, F, planes, PRESETS["steel"], defaults())
        cls.tmp = tempfile.TemporaryDirectory()
        cls.result = export.export(cls.design, cls.tmp.name)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def rest_mm(self, name):
        wire = next(w for w in self.design["wires"] if w["name"] == name)
        return 1000.0 * np.asarray(wire["rest"])

    def test_every_wire_gets_its_files(self):
        self.assertTrue(self.design["stable"])
        self.assertEqual(self.result["errors"], [])
        for w in self.design["wires"]:
            stem = export.file_stem(w)
            for folder, ext in (("svg", "svg"), ("gcode", "gcode"), ("bends", "csv")):
                self.assertTrue(os.path.isfile(os.path.join(self.tmp.name, folder, f"{stem}.{ext}")))
        for extra in ("svg/sheet.svg", "dxf/sculpture.dxf"):
            self.assertTrue(os.path.isfile(os.path.join(self.tmp.name, extra)))
        leftovers = [n for _d, _s, files in os.walk(self.tmp.name) for n in files if n.endswith(".tmp")]
        self.assertEqual(leftovers, [])

    def test_file_names_stay_unique_and_old_files_go(self):
        self.assertEqual(export.file_stem({"id": 3, "name": "Equator/0"}), "03-Equator-0")
        names = ["\u5e73\u9762/0", "\u65ad\u9762/0", "Cut/1", "Cut-1"]  # collide once made safe
        stems = {export.file_stem({"id": i, "name": n}) for i, n in enumerate(names)}
        self.assertEqual(len(stems), len(names))
        with tempfile.TemporaryDirectory() as tmp:
            stale = os.path.join(tmp, "gcode", "99-gone.gcode")
            os.makedirs(os.path.dirname(stale))
            open(stale, "w").close()
            mine = os.path.join(tmp, "gcode", "notes.txt")
            open(mine, "w").close()
            export.export(self.design, tmp)
            self.assertFalse(os.path.exists(stale))
            self.assertTrue(os.path.exists(mine))

    def test_svg_is_one_to_one(self):
        for w in self.design["wires"]:
            root = ET.parse(os.path.join(self.tmp.name, "svg", export.file_stem(w) + ".svg")).getroot()
            self.assertTrue(root.get("width").endswith("mm"))
            line = next(e for e in root.iter() if e.tag.endswith("polyline") and "wire-path" in (e.get("class") or ""))
            pts = [tuple(map(float, p.split(","))) for p in line.get("points").split()]
            np.testing.assert_allclose(edge_lengths(pts), edge_lengths(self.rest_mm(w["name"])), atol=0.01)

    def test_dxf_is_one_to_one(self):
        import ezdxf

        doc = ezdxf.readfile(os.path.join(self.tmp.name, "dxf", "sculpture.dxf"))
        self.assertFalse(doc.audit().has_errors)
        polylines = list(doc.modelspace().query("POLYLINE"))
        self.assertEqual(len(polylines), len(self.design["wires"]))
        lengths = sorted(float(np.sum(edge_lengths([(v.dxf.location.x, v.dxf.location.y) for v in p.vertices]))) for p in polylines)
        expected = sorted(float(np.sum(edge_lengths(self.rest_mm(w["name"])))) for w in self.design["wires"])
        np.testing.assert_allclose(lengths, expected, atol=0.01)

    def test_gcode_feeds_make_the_wire_and_the_table_lists_every_bend(self):
        for w, summary in zip(self.design["wires"], self.result["wires"]):
            stem = export.file_stem(w)
            with open(os.path.join(self.tmp.name, "gcode", stem + ".gcode")) as f:
                feeds = [float(m) for m in re.findall(r"^G1 X(-?[0-9.]+)", f.read(), re.M)]
            rest_length = float(np.sum(edge_lengths(self.rest_mm(w["name"]))))
            self.assertAlmostEqual(sum(feeds), rest_length, delta=0.01)
            with open(os.path.join(self.tmp.name, "bends", stem + ".csv")) as f:
                rows = list(csv.DictReader(f))
            self.assertEqual(sum(1 for r in rows if float(r["bend_deg"]) != 0.0), summary["bend_count"])
            self.assertAlmostEqual(sum(float(r["feed_mm"]) for r in rows) + 0.0, rest_length, delta=0.01)


if __name__ == "__main__":
    unittest.main()
