"""The design's vocabulary (core/design.py KEYS) against docs/formats.md and a real design.

bpy-free: runs under the system Python 3.11 (python3.11 -m unittest discover blender_tests/pure)
as well as inside Blender. The check against a real design solves a small case (three great
circles) through the pipeline when the native module is built, and is skipped otherwise.
"""
import math
import os
import re
import sys
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
if os.path.join(ROOT, "addon") not in sys.path:
    sys.path.insert(0, os.path.join(ROOT, "addon"))

from wiresculpt import native, pipeline  # noqa: E402
from wiresculpt.core import design as vocabulary  # noqa: E402
from wiresculpt.core.materials import PRESETS  # noqa: E402
from wiresculpt.core.settings import defaults  # noqa: E402

FORMATS = os.path.join(ROOT, "docs", "formats.md")
# Each bullet of the doc's design-file section and the writers (KEYS owners) it describes.
BULLETS = {"Top": {"design", "pipeline", "every stage"}, "Slicing": {"slicing"}, "Layering": {"layering"},
           "Target shape": {"target_shape"}, "Forces and rest shape": {"forces"}, "Fabrication": {"fabrication"}}
PREFIX = {"top": "", "wire": "wires[].", "crossing": "crossings[].", "stages": "stages."}


def documented():
    """{bullet name: set of backticked names} of the doc's design-file section."""
    with open(FORMATS, encoding="utf-8") as f:
        text = f.read()
    section = text[text.index("## Design file"):]
    bullets, name = {}, None
    for line in section.splitlines():
        if line.startswith("- "):
            name = re.split(r"[(:]", line[2:], maxsplit=1)[0].strip()
            bullets[name] = set()
        elif not line.startswith("  "):
            name = None
        if name is not None:
            bullets[name].update(re.findall(r"`([^`]+)`", line))
    return bullets


def names(tokens, part):
    """The keys of `part` that `tokens` name, prefixed (wires[].cut) or bare (cut)."""
    out = set()
    for t in tokens:
        if part == "top" and t.endswith("[]"):
            t = t[:-2]
        if t.startswith(PREFIX[part]):
            out.add(t[len(PREFIX[part]):])
        elif part != "stages":
            out.add(t)
    return out


class DocumentedVocabulary(unittest.TestCase):
    def test_every_key_is_documented_by_its_writer(self):
        bullets = documented()
        self.assertEqual(set(bullets), set(BULLETS))
        everything = set().union(*bullets.values())
        for part, table in vocabulary.KEYS.items():
            for key, owner in table.items():
                with self.subTest(part=part, key=key):
                    self.assertIn(key, names(everything, part), f"{PREFIX[part]}{key} is not in docs/formats.md")
                    homes = [b for b, owners in BULLETS.items() if owner in owners]
                    if homes:  # "user" keys are documented where they are used
                        self.assertIn(key, names(bullets[homes[0]], part),
                                      f"{PREFIX[part]}{key} ({owner}) is not in the doc's {homes[0]} bullet")

    def test_every_documented_wire_crossing_and_stage_key_is_in_the_table(self):
        everything = set().union(*documented().values())
        for part in ("wire", "crossing", "stages"):
            prefixed = {t[len(PREFIX[part]):] for t in everything if t.startswith(PREFIX[part])}
            prefixed = {re.split(r"[\[.]", t)[0] for t in prefixed if t}
            with self.subTest(part=part):
                self.assertLessEqual(prefixed, set(vocabulary.KEYS[part]))

    def test_optional_keys_are_keys(self):
        for part, keys in vocabulary.OPTIONAL.items():
            self.assertLessEqual(keys, set(vocabulary.KEYS[part]))


def circle(normal, radius=0.1, n=32):
    """A great circle about the origin in the plane with this normal, counter-clockwise about it."""
    n0 = [float(x) for x in normal]
    _n, u, v = native.plane_frame(n0)
    return [[radius * (math.cos(t) * u[k] + math.sin(t) * v[k]) for k in range(3)]
            for t in (2 * math.pi * i / n for i in range(n))]


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class RealDesign(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        material, settings = dict(PRESETS["steel"]), defaults()
        design = vocabulary.new_design(material, settings)
        for i, (name, normal) in enumerate((("X", (1, 0, 0)), ("Y", (0, 1, 0)), ("Z", (0, 0, 1)))):
            design["wires"].append(vocabulary.wire_entry(i, f"{name}/0", (0, 0, 0), normal, True, circle(normal)))
        cls.design = pipeline.solve(design, material, settings)

    def test_the_case_solves(self):
        self.assertEqual(self.design["pending_stages"], [])
        self.assertTrue(self.design["stable"], self.design["reason"])

    def test_every_key_is_in_the_table(self):
        d = self.design
        parts = {"top": [d], "wire": d["wires"], "crossing": d["crossings"], "stages": [d["stages"]]}
        for part, items in parts.items():
            for item in items:
                with self.subTest(part=part):
                    self.assertLessEqual(set(item), set(vocabulary.KEYS[part]))

    def test_every_stage_wrote_its_keys(self):
        d = self.design
        parts = {"top": [d], "wire": d["wires"], "crossing": d["crossings"], "stages": [d["stages"]]}
        ran = {"design", "pipeline", "slicing", "layering", "target_shape", "forces"}
        ran.discard("slicing")  # the case's wires are made by hand (wire_entry), not sliced
        for part, items in parts.items():
            wanted = {k for k, owner in vocabulary.KEYS[part].items()
                      if owner in ran and k not in vocabulary.OPTIONAL[part]}
            for item in items:
                with self.subTest(part=part):
                    self.assertLessEqual(wanted, set(item))

    def test_crossing_direction_is_the_planes_common_line(self):
        for c in self.design["crossings"]:
            d = vocabulary.crossing_direction(self.design, c)
            self.assertAlmostEqual(float(d @ d), 1.0, places=12)
            for w in c["wires"]:
                self.assertAlmostEqual(float(d @ self.design["wires"][w]["plane"]["normal"]), 0.0, places=12)

    def test_model_size(self):
        self.assertAlmostEqual(vocabulary.model_size(self.design), 0.2, places=6)


if __name__ == "__main__":
    unittest.main()
