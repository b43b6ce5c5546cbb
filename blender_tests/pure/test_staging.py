"""Outputs replaced as one set (core/staging.py): the batch run's design.json, .blend, render,
guide and fabrication folders either all belong to the new run or all to the old one.

    blender --background --factory-startup --python-exit-code 1 --python blender_tests/run.py -- staging
"""
import os
import stat
import subprocess
import sys
import tempfile
import unittest
from unittest import mock

from wiresculpt.core import staging

NAMES = ("svg", "design.json", "render.png")
NEW_DESIGN = '{"format": "wiresculpt-design", "run": "new"}'


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
            write(os.path.join(folder, "design.json"), NEW_DESIGN)
            write(os.path.join(folder, "svg", "02-B.svg"), "new svg")
        # render.png was not written this time: the old one must not sit beside the new design
        self.assertEqual(tree(self.out), {"design.json": NEW_DESIGN.encode(), os.path.join("svg", "02-B.svg"): b"new svg",
                                          "notes.txt": b"the user's own file"})
        self.assertEqual(sorted(os.listdir(self.out)), ["design.json", "notes.txt", "svg"])

    def test_failure_half_way_leaves_the_old_set(self):
        with self.assertRaises(RuntimeError):
            with staging.staged(self.out, NAMES) as folder:
                write(os.path.join(folder, "design.json"), NEW_DESIGN)
                write(os.path.join(folder, "svg", "02-B.svg"), "new svg")
                raise RuntimeError("the render failed")
        self.assertEqual(tree(self.out), self.before)
        self.assertEqual(sorted(os.listdir(self.out)), ["design.json", "notes.txt", "render.png", "svg"])

    def test_a_move_that_fails_is_rolled_back(self):
        real = os.replace
        calls = []

        def flaky(src, dst):
            calls.append((src, dst))
            if len(calls) == 6:  # the journal, three old entries moved aside, svg/ moved in, then a failure
                raise OSError("disk full")
            return real(src, dst)

        with self.assertRaises(OSError), mock.patch.object(staging.os, "replace", flaky):
            with staging.staged(self.out, NAMES) as folder:
                write(os.path.join(folder, "design.json"), NEW_DESIGN)
                write(os.path.join(folder, "render.png"), "new render")
                write(os.path.join(folder, "svg", "02-B.svg"), "new svg")
        # the journal, 3 aside, 1 in, the failure, then the rollback: 1 back to staging, 3 back in place
        self.assertEqual(len(calls), 10)
        self.assertEqual(tree(self.out), self.before)
        self.assertEqual(sorted(os.listdir(self.out)), ["design.json", "notes.txt", "render.png", "svg"])

    def test_a_new_folder_is_created(self):
        out = os.path.join(self.tmp.name, "fresh", "out")
        with staging.staged(out, NAMES) as folder:
            write(os.path.join(folder, "design.json"), NEW_DESIGN)
        self.assertEqual(os.listdir(out), ["design.json"])


    def test_outputs_that_do_not_verify_leave_the_old_set(self):
        cases = [
            ("design.json", "", "output design.json was written empty; the earlier outputs are kept"),
            ("design.json", '{"format": "other"}',
             "output design.json does not read back as a design; the earlier outputs are kept"),
            ("design.json", '{"format": "wiresculpt-design", ', 
             "output design.json does not read back as a design; the earlier outputs are kept"),
            # a .blend cut short by a full disk: the header but no ENDB block at its end
            ("sculpture.blend", "BLENDER-v304REND" + "x" * 200,
             "output sculpture.blend is not a complete .blend file (truncated or damaged); the earlier outputs are "
             "kept"),
        ]
        for name, data, message in cases:
            with self.subTest(message):
                with self.assertRaises(ValueError) as ctx:
                    with staging.staged(self.out, NAMES + ("sculpture.blend",)) as folder:
                        write(os.path.join(folder, "svg", "02-B.svg"), "new svg")
                        if name != "design.json":
                            write(os.path.join(folder, "design.json"), NEW_DESIGN)
                        write(os.path.join(folder, name), data)
                self.assertEqual(str(ctx.exception), message)
                self.assertEqual(tree(self.out), self.before)
                self.assertEqual(sorted(os.listdir(self.out)), ["design.json", "notes.txt", "render.png", "svg"])

    def test_a_complete_blend_verifies_and_files_are_0644(self):
        with staging.staged(self.out, NAMES + ("sculpture.blend",)) as folder:
            write(os.path.join(folder, "design.json"), NEW_DESIGN)
            write(os.path.join(folder, "sculpture.blend"), "BLENDER-v304" + "x" * 100 + "ENDB" + "\0" * 20)
            write(os.path.join(folder, "svg", "02-B.svg"), "new svg")
            os.chmod(os.path.join(folder, "design.json"), 0o600)
        for path in ("design.json", "sculpture.blend", os.path.join("svg", "02-B.svg")):
            self.assertEqual(stat.S_IMODE(os.stat(os.path.join(self.out, path)).st_mode), 0o644, path)
        self.assertEqual(stat.S_IMODE(os.stat(os.path.join(self.out, "svg")).st_mode), 0o755)

    def test_stale_folders_of_a_killed_run_are_removed_by_the_next(self):
        os.makedirs(os.path.join(self.out, staging.STAGING_PREFIX + "abc", "svg"))
        os.makedirs(os.path.join(self.out, staging.ASIDE_PREFIX + "def"))
        write(os.path.join(self.out, "." + staging.JOURNAL + ".x1.tmp"), "{")
        self.assertEqual(staging.recover(self.out), "")
        self.assertEqual(tree(self.out), self.before)
        self.assertEqual(sorted(os.listdir(self.out)), ["design.json", "notes.txt", "render.png", "svg"])


# The kill test: a child process switches the set and is killed (SIGKILL, fault injection) just
# before step N of the switch, for every N; the next run's recover() must leave exactly the old
# set or exactly the new one, and nothing of the run behind.
CHILD = r"""
import os, sys
sys.path.insert(0, sys.argv[2])
from wiresculpt.core import staging
def write(path, data):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        f.write(data)
with staging.staged(sys.argv[1], ("svg", "design.json", "render.png", "bends")) as folder:
    write(os.path.join(folder, "design.json"), '{"format": "wiresculpt-design", "run": "new"}')
    write(os.path.join(folder, "svg", "02-B.svg"), "new svg")
    write(os.path.join(folder, "bends", "02-B.csv"), "new bends")
"""


class KilledSwitch(unittest.TestCase):
    def test_a_kill_at_every_step_leaves_the_old_set_or_the_new_one(self):
        addon = os.path.dirname(os.path.dirname(os.path.abspath(staging.__file__)))
        addon_parent = os.path.dirname(addon)
        outcomes = set()
        with tempfile.TemporaryDirectory() as tmp:
            new = None
            for n in range(40):
                out = os.path.join(tmp, f"out{n}")
                write(os.path.join(out, "design.json"), "old design")
                write(os.path.join(out, "render.png"), "old render")
                write(os.path.join(out, "svg", "01-A.svg"), "old svg")
                write(os.path.join(out, "notes.txt"), "the user's own file")
                old = tree(out)
                env = dict(os.environ, WIRESCULPT_STAGING_FAULT=f"kill:{n}")
                child = subprocess.run([sys.executable, "-c", CHILD, out, addon_parent], env=env,
                                       capture_output=True, text=True)
                killed = child.returncode == -9
                if not killed:
                    self.assertEqual(child.returncode, 0, child.stderr)
                    new = tree(out)
                staging.recover(out)
                after = tree(out)
                self.assertEqual(sorted(e for e in os.listdir(out) if e.startswith(".")), [], n)
                if after == old:
                    outcomes.add("old")
                else:
                    self.assertEqual(after, {"design.json": NEW_DESIGN.encode(), os.path.join("svg", "02-B.svg"):
                                             b"new svg", os.path.join("bends", "02-B.csv"): b"new bends",
                                             "notes.txt": b"the user's own file"}, n)
                    outcomes.add("new")
                if not killed:
                    break
            self.assertIsNotNone(new, "the switch never ran to its end within 40 steps")
            self.assertEqual(outcomes, {"old", "new"})  # kills before and after the commit point


if __name__ == "__main__":
    unittest.main()
