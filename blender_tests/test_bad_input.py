"""The bad-input corpus (bad_input.json): each case through the headless run, with the exact
message it must produce; no case may crash, hang or leave a partial file behind."""
import json
import os
import subprocess
import tempfile
import time
import unittest

from helpers import BATCH, BLENDER, ROOT, run_blender, wiresculpt_lines

HERE = os.path.dirname(os.path.abspath(__file__))
GLOBE = os.path.join(ROOT, "scripts", "examples", "globe", "globe.obj")


def bowl_obj():
    """The globe's upper half: an open surface."""
    with open(GLOBE) as f:
        lines = f.read().splitlines()
    vertices = [tuple(map(float, l.split()[1:])) for l in lines if l.startswith("v ")]
    kept = [l for l in lines if l.startswith("v ")]
    for l in lines:
        if l.startswith("f ") and all(vertices[int(i) - 1][2] >= -1e-9 for i in l.split()[1:]):
            kept.append(l)
    return "\n".join(kept) + "\n"


def mesh_text(spec):
    if spec.startswith("@globe"):
        with open(GLOBE) as f:
            return f.read() + spec[len("@globe+"):]
    if spec == "@bowl":
        return bowl_obj()
    return spec


def lookup(design, dotted):
    value = design
    for part in dotted.split("."):
        value = value[int(part)] if isinstance(value, list) else value[part]
    return value


def corpus(section):
    with open(os.path.join(HERE, "bad_input.json")) as f:
        return json.load(f)[section]


class BadInput(unittest.TestCase):
    def test_profile_files(self):
        """Malformed machine-profile files: one ValueError each, naming the file and the key."""
        from wiresculpt import native
        from wiresculpt.core import calibration

        if not native.available():
            self.skipTest(native.LOAD_ERROR)
        for case in corpus("profiles"):
            with self.subTest(case["name"]), tempfile.TemporaryDirectory() as tmp:
                path = os.path.join(tmp, "profile.json")
                with open(path, "w", encoding=case.get("encoding", "utf-8")) as f:
                    f.write(case["text"] if "text" in case else json.dumps(case["profile"]))
                with self.assertRaises(ValueError) as ctx:
                    calibration.load_profile(path)
                self.assertEqual(str(ctx.exception), case["message"])
                self.assertEqual(os.listdir(tmp), ["profile.json"])

    def test_corpus(self):
        cases = corpus("cases")
        for case in cases:
            with self.subTest(case["name"]), tempfile.TemporaryDirectory() as tmp:
                for name, spec in case.get("meshes", {}).items():
                    with open(os.path.join(tmp, name), "w") as f:
                        f.write(mesh_text(spec))
                scene = os.path.join(tmp, "scene.json")
                with open(scene, "w", encoding=case.get("encoding", "utf-8")) as f:
                    f.write(case["text"] if "text" in case else json.dumps(case["scene"]))
                out = os.path.join(tmp, "out")
                r = run_blender(BATCH, scene, "--out", out, timeout=120)
                self.assertEqual(r.returncode, case["exit"], r.stdout + r.stderr)
                self.assertNotIn("RuntimeWarning", r.stderr)  # numpy's warnings are not messages
                messages = wiresculpt_lines(r.stderr)
                if "stderr" in case:
                    self.assertEqual(messages, [case["stderr"].replace("{dir}", tmp)])
                if case["exit"] == 1:
                    self.assertFalse(os.path.exists(out), "a refused input must leave nothing behind")
                    continue
                self.assertEqual(sorted(n for n in os.listdir(out) if n.endswith(".tmp")), [])
                with open(os.path.join(out, "design.json")) as f:
                    design = json.load(f)
                self.assertEqual(design["stable"], case["exit"] == 0)
                for key, expected in case.get("design", {}).items():
                    self.assertEqual(lookup(design, key), expected, key)


def full_disk_at(limit):
    """For the child: files cannot grow past `limit` bytes and a write past it fails with EFBIG
    (SIGXFSZ ignored, as across exec), as a write to a full disk fails with ENOSPC."""
    def apply():
        import resource
        import signal

        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return apply


class CommandLine(unittest.TestCase):
    """The batch as a shell runs it, with what the shell can hand it: bytes that are not UTF-8, a
    disk that fills up."""

    SCENE = os.path.join(ROOT, "scripts", "examples", "globe", "scene.json")

    def test_an_out_folder_name_that_is_not_utf8(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.fsencode(tmp) + b"/out\xff"
            r = run_blender(BATCH, self.SCENE, "--out", out, timeout=120)
            self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
            self.assertEqual(wiresculpt_lines(r.stderr),
                             [f"wiresculpt: error: --out {tmp}/out\\xff: the folder name is not UTF-8; choose a name in UTF-8"])
            self.assertEqual(os.listdir(tmp), [])

    def refused(self, out, message, cwd=None):
        """The globe with --out `out`: exit 1, the one line `message`, before any solve."""
        r = run_blender(BATCH, self.SCENE, "--out", out, timeout=120)
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        self.assertEqual(wiresculpt_lines(r.stderr), [message])
        self.assertNotIn("wiresculpt: mesh:", r.stdout)  # nothing was solved

    def test_out_folders_no_run_can_write_are_refused_before_the_solve(self):
        self.refused("", "wiresculpt: error: --out is empty; give the folder the outputs go to (e.g. --out out/globe)")
        self.refused("/proc/wiresculpt-out", "wiresculpt: error: --out /proc/wiresculpt-out: /proc is on the kernel's "
                     "proc file system, not a place for files; choose a folder on a disk")
        self.refused("/sys/kernel/wiresculpt-out", "wiresculpt: error: --out /sys/kernel/wiresculpt-out: /sys/kernel is on "
                     "the kernel's sysfs file system, not a place for files; choose a folder on a disk")
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "a" * 300, "out")
            self.refused(out, f"wiresculpt: error: --out {out[:60]}...: the folder name {'a' * 20}... is 300 bytes "
                              "long; a name in a path may have at most 255 bytes")
            self.assertEqual(os.listdir(tmp), [])

    def test_a_folder_where_design_json_belongs_is_refused_not_deleted(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "out")
            os.makedirs(os.path.join(out, "design.json"))
            with open(os.path.join(out, "design.json", "mine.txt"), "w") as f:
                f.write("the user's")
            self.refused(out, f"wiresculpt: error: --out {out}: {out}/design.json is a folder, where the run writes "
                              "the file design.json; move it away or choose another --out")
            self.assertEqual(sorted(os.listdir(out)), ["design.json"])
            self.assertEqual(os.listdir(os.path.join(out, "design.json")), ["mine.txt"])

    def test_a_second_run_on_the_same_folder_is_refused_while_the_first_writes(self):
        """Two real batch processes on one --out: the second is refused at once, naming the folder
        and the first's process; the first ends with its whole set, no staging folder is lost."""
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "out")
            cmd = [BLENDER, "--background", "--factory-startup", "--python-exit-code", "1", "--python", BATCH,
                   "--", self.SCENE, "--out", out]
            first = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                     env=dict(os.environ, WIRESCULPT_STAGING_FAULT="slow:0.2"))
            try:
                lock = os.path.join(out, ".wiresculpt-lock")
                deadline = time.monotonic() + 60
                while not (os.path.exists(lock) and open(lock).read().strip()) and time.monotonic() < deadline:
                    time.sleep(0.05)
                self.assertIsNone(first.poll(), "the first run ended before it took the folder")
                second = run_blender(BATCH, self.SCENE, "--out", out, timeout=120)
                self.assertEqual(second.returncode, 1, second.stdout + second.stderr)
                self.assertEqual(wiresculpt_lines(second.stderr), [
                    f"wiresculpt: error: --out {out}: another wiresculpt run (process {first.pid}) is writing to this "
                    "folder; wait for it to end or choose another --out"])
                stdout, stderr = first.communicate(timeout=300)
            finally:
                if first.poll() is None:
                    first.kill()
                    first.wait()
            self.assertEqual(first.returncode, 0, stdout + stderr)
            self.assertEqual(sorted(e for e in os.listdir(out) if e.startswith(".")), [])
            with open(os.path.join(out, "design.json")) as f:
                self.assertTrue(json.load(f)["stable"])
            # and the folder is free again: a third run writes
            third = run_blender(BATCH, self.SCENE, "--out", out, timeout=300)
            self.assertEqual(third.returncode, 0, third.stdout + third.stderr)

    def test_normal_components_zero_but_for_representation_solve_as_zeros(self):
        """[1e-300, 1, 0] stopped GLPK, [1e-99, 1, 0] was refused by the force LP: both are the
        plane [0, 1, 0], and the design is the same as its."""
        with open(self.SCENE) as f:
            scene = json.load(f)
        scene["mesh"] = os.path.join(os.path.dirname(self.SCENE), scene["mesh"])
        designs = {}
        with tempfile.TemporaryDirectory() as tmp:
            for tiny in (0.0, 1e-300, 1e-99):
                scene["planes"][2]["normal"] = [tiny, 1.0, 0.0]
                path = os.path.join(tmp, f"scene-{tiny}.json")
                with open(path, "w") as f:
                    json.dump(scene, f)
                out = os.path.join(tmp, f"out-{tiny}")
                r = run_blender(BATCH, path, "--out", out, timeout=300)
                self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
                with open(os.path.join(out, "design.json")) as f:
                    design = json.load(f)
                for timed in ("stages", "fabrication"):
                    design.pop(timed, None)
                designs[tiny] = design
        self.assertEqual(designs[0.0]["wires"][2]["plane"]["normal"], [0.0, 1.0, 0.0])
        self.assertEqual(designs[1e-300], designs[0.0])
        self.assertEqual(designs[1e-99], designs[0.0])

    def test_a_disk_that_fills_during_the_blend_save_keeps_the_earlier_set(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "out")
            first = run_blender(BATCH, self.SCENE, "--out", out, timeout=300)
            self.assertEqual(first.returncode, 0, first.stdout + first.stderr)
            before = {}
            for folder, _dirs, files in os.walk(out):
                for name in files:
                    with open(os.path.join(folder, name), "rb") as f:
                        before[os.path.relpath(os.path.join(folder, name), out)] = f.read()
            blend = len(before["sculpture.blend"])
            # every other output fits (design.json, render.png and the rest are far smaller), the
            # .blend does not
            limit = blend // 2
            self.assertLess(max(len(v) for k, v in before.items() if k != "sculpture.blend"), limit)
            r = run_blender(BATCH, self.SCENE, "--out", out, timeout=300, preexec_fn=full_disk_at(limit))
            self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
            lines = wiresculpt_lines(r.stderr)
            self.assertEqual(len(lines), 1, lines)
            self.assertTrue(lines[0].startswith("wiresculpt: error: Blender could not save sculpture.blend ("), lines)
            self.assertTrue(lines[0].endswith("; is the disk full?); the earlier outputs are kept"), lines)
            self.assertNotIn("wiresculpt: written:", r.stdout)
            after = {}
            for folder, _dirs, files in os.walk(out):
                for name in files:
                    with open(os.path.join(folder, name), "rb") as f:
                        after[os.path.relpath(os.path.join(folder, name), out)] = f.read()
            self.assertEqual(sorted(after), sorted(before))
            self.assertTrue(all(after[k] == before[k] for k in before), "the earlier set changed")
            self.assertEqual(os.listdir(tmp), ["out"])  # no staging folder left behind


if __name__ == "__main__":
    unittest.main()
