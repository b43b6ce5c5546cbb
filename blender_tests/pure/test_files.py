"""core/files.write_atomic: the file is written whole, readable by others where the system has
mode bits, and a Python without os.fchmod (Windows before 3.13) writes it too, leaving no
temporary file behind. bpy-free."""
import os
import stat
import tempfile
import unittest
from unittest import mock

from wiresculpt.core import files


class WriteAtomic(unittest.TestCase):
    def test_written_whole_and_readable_by_others(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "sub", "a.svg")
            files.write_atomic(path, "<svg/>\n")
            with open(path, encoding="utf-8") as f:
                self.assertEqual(f.read(), "<svg/>\n")
            self.assertEqual(stat.S_IMODE(os.stat(path).st_mode), 0o644)
            self.assertEqual(os.listdir(os.path.dirname(path)), ["a.svg"])

    def test_a_python_without_fchmod_writes_it_too(self):
        with tempfile.TemporaryDirectory() as tmp, mock.patch.object(files.os, "fchmod", create=True) as fchmod:
            del files.os.fchmod  # as on Windows before Python 3.13
            try:
                path = os.path.join(tmp, "b.bin")
                files.write_atomic(path, b"\x00\x01")
                with open(path, "rb") as f:
                    self.assertEqual(f.read(), b"\x00\x01")
                self.assertEqual(os.listdir(tmp), ["b.bin"])
            finally:
                files.os.fchmod = fchmod  # mock.patch restores the real one after

    def test_a_failed_write_leaves_nothing(self):
        with tempfile.TemporaryDirectory() as tmp:
            with self.assertRaises(TypeError):
                files.write_atomic(os.path.join(tmp, "c.txt"), 12)  # neither text nor bytes
            self.assertEqual(os.listdir(tmp), [])


if __name__ == "__main__":
    unittest.main()
