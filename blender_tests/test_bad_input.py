"""The bad-input corpus (bad_input.json): each case through the headless run, with the exact
message it must produce; no case may crash, hang or leave a partial file behind."""
import json
import os
import tempfile
import unittest

from helpers import BATCH, ROOT, run_blender, wiresculpt_lines

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
