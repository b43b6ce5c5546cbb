"""The design's vocabulary (core/design.py KEYS) against docs/formats.md and a real design.

bpy-free (blender_tests/run.py pure). The check against a real design slices and solves a small
case (three great circles of a UV sphere) through the pipeline when the native module is built,
and is skipped otherwise.
"""
import math
import os
import re
import unittest

import numpy as np

from wiresculpt import native, pipeline
from wiresculpt.core import design as vocabulary
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.settings import defaults

from helpers import PLANES, ROOT, sphere

FORMATS = os.path.join(ROOT, "docs", "formats.md")
# Each bullet of the doc's design-file section and the writers (KEYS owners) it describes.
BULLETS = {"Top": {"design", "pipeline", "every stage"}, "Slicing": {"slicing"}, "Layering": {"layering"},
           "Target shape": {"target_shape"}, "Forces and rest shape": {"forces"}, "Fabrication": {"fabrication"},
           "Plane search": {"plane_search"}, "Standing in 3D": {"stands_3d"}}
PREFIX = {"top": "", "wire": "wires[].", "crossing": "crossings[].", "stages": "stages.",
          "plane_search": "plane_search."}


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


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class RealDesign(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        V, F = sphere()
        cls.design = pipeline.run(V, F, PLANES, dict(PRESETS["steel"]), defaults())

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
        ran = {"design", "pipeline", "slicing", "layering", "target_shape", "forces", "stands_3d"}
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

    def test_crossing_axis_is_numpys_cross_normalised_to_the_bit(self):
        """Written out without numpy, the target shape's bisectors are the same floats as
        np.cross / np.linalg.norm gave (every solve depends on them to the last bit)."""
        rng = np.random.default_rng(7)
        for _ in range(500):
            a, b = rng.normal(size=3), rng.normal(size=3) * rng.choice([1e-3, 1.0, 1e3])
            design = {"wires": [{"plane": {"normal": list(a)}}, {"plane": {"normal": list(b)}}]}
            d = np.cross(a, b)
            self.assertEqual(vocabulary.crossing_axis(design, {"wires": [0, 1]}), tuple(d / np.linalg.norm(d)))
        parallel = {"wires": [{"plane": {"normal": [0, 0, 1]}}, {"plane": {"normal": [0, 0, 2]}}]}
        self.assertTrue(all(math.isnan(x) for x in vocabulary.crossing_axis(parallel, {"wires": [0, 1]})))

    def test_model_size(self):
        self.assertAlmostEqual(vocabulary.model_size(self.design), 0.25, places=3)


if __name__ == "__main__":
    unittest.main()
