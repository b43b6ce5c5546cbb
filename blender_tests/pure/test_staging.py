"""Outputs replaced as one set (core/staging.py): the batch run's design.json, .blend, render,
guide and fabrication folders either all belong to the new run or all to the old one.

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- staging
"""
import os
import tempfile
import unittest
from unittest import mock

from wiresculpt.core import staging

NAMES = ("svg", "design.json", "render.png")


def tree(folder):
    """{relative path: bytes} of every file under folder."""
    out = {}
    for root, _dirs, files in os.walk(folder):
        for name in files:
            path = os.path.join(root, name)
            with open(path, "rb") as f:
                out[os.path.relpath(path, folder)] = f.read()
    return out


def write(path, data):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        f.write(data)


class Staged(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.out = os.path.join(self.tmp.name, "out")
        write(os.path.join(self.out, "design.json"), "old design")
        write(os.path.join(self.out, "render.png"), "old render")
        write(os.path.join(self.out, "svg", "01-A.svg"), "old svg")
        write(os.path.join(self.out, "svg", "sheet.svg"), "old sheet")
        write(os.path.join(self.out, "notes.txt"), "the user's own file")
        self.before = tree(self.out)

    def tearDown(self):
        self.tmp.cleanup()

    def test_success_replaces_the_whole_set(self):
        with staging.staged(self.out, NAMES) as folder:
            write(os.path.join(folder, "design.json"), "new design")
            write(os.path.join(folder, "svg", "02-B.svg"), "new svg")
        # render.png was not written this time: the old one must not sit beside the new design
        self.assertEqual(tree(self.out), {"design.json": b"new design", os.path.join("svg", "02-B.svg"): b"new svg",
                                          "notes.txt": b"the user's own file"})
        self.assertEqual(sorted(os.listdir(self.out)), ["design.json", "notes.txt", "svg"])

    def test_failure_half_way_leaves_the_old_set(self):
        with self.assertRaises(RuntimeError):
            with staging.staged(self.out, NAMES) as folder:
                write(os.path.join(folder, "design.json"), "new design")
                write(os.path.join(folder, "svg", "02-B.svg"), "new svg")
                raise RuntimeError("the render failed")
        self.assertEqual(tree(self.out), self.before)
        self.assertEqual(sorted(os.listdir(self.out)), ["design.json", "notes.txt", "render.png", "svg"])

    def test_a_move_that_fails_is_rolled_back(self):
        real = os.replace
        calls = []

        def flaky(src, dst):
            calls.append((src, dst))
            if len(calls) == 5:  # three old entries moved aside, svg/ moved in, then a failure
                raise OSError("disk full")
            return real(src, dst)

        with self.assertRaises(OSError), mock.patch.object(staging.os, "replace", flaky):
            with staging.staged(self.out, NAMES) as folder:
                write(os.path.join(folder, "design.json"), "new design")
                write(os.path.join(folder, "render.png"), "new render")
                write(os.path.join(folder, "svg", "02-B.svg"), "new svg")
        # 3 aside, 1 in, the failure, then the rollback: 1 back to staging, 3 back in place
        self.assertEqual(len(calls), 9)
        self.assertEqual(tree(self.out), self.before)
        self.assertEqual(sorted(os.listdir(self.out)), ["design.json", "notes.txt", "render.png", "svg"])

    def test_a_new_folder_is_created(self):
        out = os.path.join(self.tmp.name, "fresh", "out")
        with staging.staged(out, NAMES) as folder:
            write(os.path.join(folder, "design.json"), "new design")
        self.assertEqual(os.listdir(out), ["design.json"])


if __name__ == "__main__":
    unittest.main()
