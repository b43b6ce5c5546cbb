"""The assembly guide of a design whose wires are made in pieces (fab/pieces.py): each wire's
pieces and, per joint, which piece ends meet, where, and the sleeve or overlap."""
import html
import unittest

from wiresculpt import native, pipeline
from wiresculpt.blend import guide as assembly_guide
from wiresculpt.core import sizes
from wiresculpt.core.materials import PRESETS
from wiresculpt.core.settings import defaults

from helpers import PLANES, sphere


@unittest.skipUnless(native.available(), native.LOAD_ERROR)
class GuidePieces(unittest.TestCase):
    def test_the_guide_joins_the_pieces(self):
        V, F = sphere()  # three great circles of 815 mm on a 500 mm stock: two pieces each
        design = pipeline.run(V, F, PLANES, dict(PRESETS["steel"]), defaults(), stock=(0.5, "short stock"))
        text = assembly_guide.page_html(design, [])
        for w in design["wires"]:
            self.assertEqual(len(w["pieces"]), 2)
            lengths = ", ".join(f"piece {k + 1} {p['length'] * 1000:.0f} mm" for k, p in enumerate(w["pieces"]))
            self.assertIn(f"made in 2 pieces ({lengths})", text)
            (joint,) = w["joints"]
            said = html.escape(sizes.joint_sentence(w, joint, design["material"]["wire_diameter"]))
            self.assertIn(said[0].upper() + said[1:], text)
            self.assertIn(f"Join {html.escape(w['name'])} piece 1 of 2 and piece 2 of 2 {joint['at'] * 1000:.0f} mm from the cut",
                          text)
        one = dict(design, wires=[{k: v for k, v in w.items() if k not in ("pieces", "joints")} for w in design["wires"]])
        self.assertNotIn("pieces (", assembly_guide.page_html(one, []))  # a wire of one piece: nothing said


if __name__ == "__main__":
    unittest.main()
