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
            for folder, ext in (("svg", "svg"), ("dxf", "dxf"), ("templates", "svg"), ("gcode", "gcode"), ("bends", "csv"),
                                ("bendlist", "txt")):
                self.assertTrue(os.path.isfile(os.path.join(self.tmp.name, folder, f"{stem}.{ext}")))
        for extra in ("templates/sheet.svg", "dxf/sculpture.dxf"):
            self.assertTrue(os.path.isfile(os.path.join(self.tmp.name, extra)))
        leftovers = [n for _d, _s, files in os.walk(self.tmp.name) for n in files if n.endswith(".tmp")]
        self.assertEqual(leftovers, [])

    def test_templates_are_tiled_onto_pages(self):
        from wiresculpt.fab import tiles

        pages = os.path.join(self.tmp.name, "templates", "pages")
        for w in self.design["wires"]:
            stem = export.file_stem(w)
            root = ET.parse(os.path.join(self.tmp.name, "templates", stem + ".svg")).getroot()
            expected = tiles.layout(float(root.get("width")[:-2]), float(root.get("height")[:-2]))["tiles"]
            found = sorted(n for n in os.listdir(pages) if n.startswith(stem + "-"))
            self.assertEqual(found, sorted(f"{stem}-{t['name']}.svg" for t in expected))
            for name in found:
                self.assertIn(os.path.join(pages, name), self.result["files"])
                page = ET.parse(os.path.join(pages, name)).getroot()
                self.assertEqual((page.get("width"), page.get("height")), ("210.000mm", "297.000mm"))
        level, text = export.summary(self.result, self.tmp.name)
        self.assertIn(f"{len(os.listdir(pages))} {os.path.join('templates', 'pages')}", text)
        with tempfile.TemporaryDirectory() as tmp:  # Letter on request; an unknown paper is refused
            export.export(self.design, tmp, paper="Letter")
            page = ET.parse(os.path.join(tmp, "templates", "pages", os.listdir(os.path.join(tmp, "templates", "pages"))[0])).getroot()
            self.assertEqual(page.get("width"), "215.900mm")
            with self.assertRaises(ValueError):
                export.export(self.design, tmp, paper="A3")

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
            root = ET.parse(os.path.join(self.tmp.name, "templates", export.file_stem(w) + ".svg")).getroot()
            self.assertTrue(root.get("width").endswith("mm"))
            line = next(e for e in root.iter() if e.tag.endswith("polyline") and "wire-path" in (e.get("class") or ""))
            pts = [tuple(map(float, p.split(","))) for p in line.get("points").split()]
            np.testing.assert_allclose(edge_lengths(pts), edge_lengths(self.rest_mm(w["name"])), atol=0.01)

    def test_machine_svg_is_one_path_from_the_origin(self):
        for w in self.design["wires"]:
            root = ET.parse(os.path.join(self.tmp.name, "svg", export.file_stem(w) + ".svg")).getroot()
            self.assertTrue(root.get("width").endswith("mm") and root.get("height").endswith("mm"))
            drawn = [e for e in root.iter() if e.tag.split("}")[-1] in
                     ("path", "polyline", "line", "circle", "text", "rect", "polygon", "ellipse")]
            self.assertEqual([e.tag.split("}")[-1] for e in drawn], ["path"], w["name"])
            words = drawn[0].get("d").split()
            self.assertEqual(words[0], "M")
            pts = np.array([[float(words[i + 1]), float(words[i + 2])] for i in range(0, len(words), 3)])
            self.assertTrue(all(words[i] in ("M", "L") for i in range(0, len(words), 3)))
            np.testing.assert_allclose(pts[0], [0.0, 0.0], atol=1e-9)
            rest = self.rest_mm(w["name"])
            np.testing.assert_allclose(edge_lengths(pts), edge_lengths(rest), atol=0.01)
            # the same shape, not its mirror image: y is flipped for the page (SVG y points down)
            np.testing.assert_allclose(pts, (rest - rest[0]) * [1.0, -1.0], atol=0.01)
            vb = [float(x) for x in root.get("viewBox").split()]
            self.assertLessEqual(vb[0], pts[:, 0].min())
            self.assertGreaterEqual(vb[0] + vb[2], pts[:, 0].max())
            self.assertAlmostEqual(float(root.get("width")[:-2]), vb[2], places=3)  # 1 user unit = 1 mm

    def read_dxf(self, path):
        import ezdxf

        doc = ezdxf.readfile(path)
        auditor = doc.audit()
        self.assertFalse(auditor.has_errors, [str(e) for e in auditor.errors])
        self.assertGreaterEqual(doc.dxfversion, "AC1015")  # R2000 or later
        self.assertEqual(doc.header.get("$INSUNITS"), 4)  # millimetres
        return doc

    def test_each_wire_dxf_is_one_lwpolyline_in_mm(self):
        for w in self.design["wires"]:
            doc = self.read_dxf(os.path.join(self.tmp.name, "dxf", export.file_stem(w) + ".dxf"))
            entities = list(doc.modelspace())
            self.assertEqual([e.dxftype() for e in entities], ["LWPOLYLINE"], w["name"])
            pts = np.array([(x, y) for x, y, *_ in entities[0].get_points()])
            np.testing.assert_allclose(pts[0], [0.0, 0.0], atol=1e-6)  # origin at the start
            rest = self.rest_mm(w["name"])
            np.testing.assert_allclose(pts, rest - rest[0], atol=1e-3)
            self.assertIn(entities[0].dxf.layer, [layer.dxf.name for layer in doc.layers])

    def test_combined_dxf_lays_the_wires_side_by_side(self):
        doc = self.read_dxf(os.path.join(self.tmp.name, "dxf", "sculpture.dxf"))
        polylines = list(doc.modelspace().query("LWPOLYLINE"))
        self.assertEqual(len(polylines), len(self.design["wires"]))
        self.assertEqual(len({p.dxf.layer for p in polylines}), len(polylines))  # one layer per wire
        boxes = []
        for p in polylines:
            pts = np.array([(x, y) for x, y, *_ in p.get_points()])
            boxes.append((pts[:, 0].min(), pts[:, 0].max(), pts[:, 1].min(), pts[:, 1].max()))
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                a, b = boxes[i], boxes[j]
                overlap = a[0] < b[1] and b[0] < a[1] and a[2] < b[3] and b[2] < a[3]
                self.assertFalse(overlap, f"the boxes of wires {i} and {j} overlap: {a} {b}")
        lengths = sorted(float(np.sum(edge_lengths([(x, y) for x, y, *_ in p.get_points()]))) for p in polylines)
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
