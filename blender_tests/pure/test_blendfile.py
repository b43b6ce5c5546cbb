"""core/blendfile.py refuses what it cannot read, with a sentence (the batch then keeps the file as
Blender saved it). Reading and patching real files is tested in test_batch_outputs.py, against
what a Blender with a window makes of the patched file."""
import gzip
import unittest

from wiresculpt.core import blendfile


class BlendFileHeader(unittest.TestCase):
    def test_refusals(self):
        cases = {b"PK\x03\x04 a zip": "no BLENDER header",
                 b"\x28\xb5\x2f\xfd zstd frame": "zstd-compressed",
                 b"BLENDER17-01v0500" + bytes(64): "header this reader does not know",
                 gzip.compress(b"BLENDER17-01v0500" + bytes(64)): "header this reader does not know"}
        for data, words in cases.items():
            with self.assertRaisesRegex(ValueError, words):
                blendfile.BlendFile(data)


if __name__ == "__main__":
    unittest.main()
