"""Print templates tiled onto paper pages (fab/tiles.py), checked by rendering
each page with rsvg-convert at 254 dpi (10 pixels per millimetre) and measuring the pixels: the
page is the paper's size, the scale bar is 100 mm long, and every point of the wire lands on the
page where the 1:1 drawing puts it."""
import math
import os
import shutil
import subprocess
import tempfile
import unittest
import xml.etree.ElementTree as ET

import numpy as np

from wiresculpt import native
from wiresculpt.fab import tiles

PX_PER_MM = 10  # 254 dpi
SVG = "{http://www.w3.org/2000/svg}"


def rectangle_with_teeth(width=0.40, height=0.30, teeth=7):
    """A wire 400 x 300 mm (two A4 pages wide at least) with bends of both signs (m)."""
    top = [[width * i / (2 * teeth), (0.02 if i % 2 else 0.0) + height] for i in range(2 * teeth + 1)]
    return np.array([[0.0, 0.0], [width, 0.0]] + top[::-1][:-1] + [[0.0, height], [0.0, 0.0]])


def render(path):
    png = path[:-4] + ".png"
    r = subprocess.run(["rsvg-convert", "--dpi-x", str(25.4 * PX_PER_MM), "--dpi-y", str(25.4 * PX_PER_MM),
                        "--background-color", "white", path, "-o", png], capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        raise AssertionError(r.stderr)
    from PIL import Image

    return np.asarray(Image.open(png).convert("RGB")).astype(int)


def longest_runs(mask):
    """Per row, the length of the longest run of True."""
    out = []
    for row in mask:
        best = run = 0
        for v in row:
            run = run + 1 if v else 0
            best = max(best, run)
        out.append(best)
    return np.array(out)


class TilesLayout(unittest.TestCase):
    def test_tiles_cover_the_template_with_the_overlap(self):
        for paper in ("A4", "Letter"):
            for width, height in ((50, 40), (190, 259), (191, 260), (589, 580), (1200, 90)):
                t = tiles.layout(width, height, paper, overlap_mm=10)
                _x, _y, ww, wh = t["window"]
                pw, ph = tiles.PAPERS[paper.upper()]
                self.assertLessEqual(ww, pw - 2 * tiles.MARGIN_MM)
                self.assertLessEqual(wh, ph - 2 * tiles.MARGIN_MM)
                xs = sorted({tile["x"] for tile in t["tiles"]})
                ys = sorted({tile["y"] for tile in t["tiles"]})
                self.assertEqual(len(t["tiles"]), len(xs) * len(ys))
                self.assertEqual(xs[0], 0)
                self.assertEqual(ys[0], 0)
                self.assertGreaterEqual(xs[-1] + ww, width)  # covered
                self.assertGreaterEqual(ys[-1] + wh, height)
                for a, b in zip(xs, xs[1:]):
                    self.assertAlmostEqual(a + ww - b, 10.0)  # neighbours share 10 mm
                for a, b in zip(ys, ys[1:]):
                    self.assertAlmostEqual(a + wh - b, 10.0)
                if len(xs) > 1:  # no page too many
                    self.assertLess(xs[-2] + ww, width)
                if len(ys) > 1:
                    self.assertLess(ys[-2] + wh, height)
        self.assertEqual(len(tiles.layout(100, 100)["tiles"]), 1)
        with self.assertRaises(ValueError):
            tiles.layout(100, 100, "A3")
        with self.assertRaises(ValueError):
            tiles.layout(100, 100, overlap_mm=-1)

    def test_page_names(self):
        t = tiles.layout(589, 580)
        self.assertEqual([tile["name"] for tile in t["tiles"]][:4], ["A1", "A2", "A3", "A4"])
        self.assertEqual(tiles._row_name(26), "AA")


@unittest.skipUnless(shutil.which("rsvg-convert"), "rsvg-convert (librsvg2-bin) is required")
class TilesRendered(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        w = native.require()
        cls.tmp = tempfile.TemporaryDirectory()
        cls.points = rectangle_with_teeth()
        prog = w.make_bend_program(cls.points, {})
        cls.template = w.write_svg(None, [{"name": "Big/0", "points": cls.points,
                                           "bend_points": prog["bend_vertices"], "crossing_points": [3]}], False)
        cls.paths = tiles.write_pages(cls.template, cls.tmp.name, "00-Big-0", "Big/0")
        root = ET.fromstring(cls.template)
        cls.size = (float(root.get("width")[:-2]), float(root.get("height")[:-2]))
        line = root.find(f".//{SVG}polyline[@class='wire-path']")
        cls.wire_mm = np.array([[float(v) for v in p.split(",")] for p in line.get("points").split()])
        cls.layout = tiles.layout(*cls.size)
        cls.images = {os.path.basename(p): render(p) for p in cls.paths}

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_pages_are_the_paper_size(self):
        self.assertGreater(len(self.paths), 1)
        self.assertEqual(len(self.paths), len(self.layout["tiles"]))
        for name, image in self.images.items():
            self.assertEqual(image.shape[:2], (2970, 2100), name)  # 297 x 210 mm at 10 px/mm

    def test_scale_bar_measures_100_mm(self):
        for name, image in self.images.items():
            r, g, b = image[..., 0], image[..., 1], image[..., 2]
            green = (g > 60) & (r < g - 40) & (b < g - 40)  # the bar's colour, #008000, antialiased edges too
            self.assertTrue(green.any(), name)
            runs = longest_runs(green)
            bar_rows = runs > 50 * PX_PER_MM
            self.assertGreaterEqual(bar_rows.sum(), 3, name)  # 0.6 mm thick
            # the bar's bottom rows: the ticks stand on top of it, so below them the run is the bar alone
            length_mm = runs[np.nonzero(bar_rows)[0][-2]] / PX_PER_MM
            self.assertAlmostEqual(length_mm, 100.0, delta=0.25, msg=name)

    def test_every_wire_point_is_drawn_at_one_to_one(self):
        wx, wy, ww, wh = self.layout["window"]
        seen = np.zeros(len(self.wire_mm), dtype=bool)
        for tile in self.layout["tiles"]:
            image = self.images[f"00-Big-0-{tile['name']}.svg"]
            dark = image.sum(axis=2) < 3 * 100
            for k, (x, y) in enumerate(self.wire_mm):
                u, v = x - tile["x"], y - tile["y"]  # in the window, mm
                if not (1 < u < ww - 1 and 1 < v < wh - 1):
                    continue
                px, py = (wx + u) * PX_PER_MM, (wy + v) * PX_PER_MM
                patch = dark[int(py) - 2:int(py) + 3, int(px) - 2:int(px) + 3]
                self.assertTrue(patch.any(), f"wire point {k} is not drawn at ({x:.1f}, {y:.1f}) mm on {tile['name']}")
                seen[k] = True
            # and nothing of the wire is drawn outside the window
            outside = dark.copy()
            outside[int(wy * PX_PER_MM) - 3:int((wy + wh) * PX_PER_MM) + 3,
                    int(wx * PX_PER_MM) - 3:int((wx + ww) * PX_PER_MM) + 3] = False
            outside[int((wy + wh) * PX_PER_MM) + 3:, :] = False  # the footer: scale label and caption
            self.assertFalse(outside.any(), tile["name"])
        self.assertTrue(seen.all(), f"points on no page: {np.nonzero(~seen)[0]}")

    def test_overlap_marks_name_the_neighbours(self):
        t = self.layout
        for path in self.paths:
            root = ET.parse(path).getroot()
            name = os.path.basename(path)[len("00-Big-0-"):-4]
            tile = next(x for x in t["tiles"] if x["name"] == name)
            neighbours = (tile["col"] > 0) + (tile["col"] + 1 < t["cols"]) + (tile["row"] > 0) + (tile["row"] + 1 < t["rows"])
            self.assertEqual(len(root.findall(f"{SVG}line[@class='overlap']")), neighbours, name)
            caption = root.find(f"{SVG}text[@class='caption']").text
            self.assertIn("Big/0", caption)
            self.assertIn(f"page {name}", caption)
            self.assertIn("100 %", caption)


if __name__ == "__main__":
    unittest.main()
