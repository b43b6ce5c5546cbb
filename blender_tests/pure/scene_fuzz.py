"""A fuzz target over whole scene files: JSON mutations of the seed scenes in
blender_tests/fuzz_scenes/ (the bundled globe's, corpus-style placements, plane search, settings,
cuts) through the batch's scene reader, core.scene.load_scene.

Each input must be read into a Scene whose planes are bounded (names of at most 63 bytes, printable,
no separator; normals finite, non-zero, cleaned) or refused with one ValueError whose sentence is
one line; any other exception, a warning, or a message on several lines is a finding.

    python3.11 blender_tests/pure/scene_fuzz.py [SECONDS] [OUT]   mutate for SECONDS (default 30),
                                                                 findings into OUT (out/fuzz/scenes)

test_scene_fuzz.py replays the seeds and a fixed set of mutations of each (scripts/test runs it with
the pure suites); `scripts/fuzz scenes SECONDS` runs this.
"""
import json
import math
import os
import random
import sys
import tempfile
import time
import warnings

HERE = os.path.dirname(os.path.abspath(__file__))
SEEDS = os.path.join(os.path.dirname(HERE), "fuzz_scenes")
ADDON = os.path.join(os.path.dirname(os.path.dirname(HERE)), "addon")
if ADDON not in sys.path:
    sys.path.insert(0, ADDON)

from wiresculpt.core import scene as scene_reader  # noqa: E402

MESH = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"
MAX_MESSAGE = 2000

ODD_VALUES = [None, True, False, 0, -1, 1, 2 ** 31, 2 ** 63, -2 ** 63, 10 ** 400, 0.5, -0.0, 1e-300, 5e-324,
              1e300, 1e308, -1e308, float("nan"), float("inf"), -float("inf"), "", " ", "\n", "\x00", "a/b", "\\",
              "largest", "all", "auto", "nearby", "off", "steel", "brass", "\u200b", "\u2028", "é" * 40, "x" * 300,
              [], [0], [0, 0], [0, 0, 0], [1e-300, 1, 0], [1e-99, 1, 0], [0, 0, 1], [1, 2, 3, 4], ["a", "b", "c"],
              {}, {"x": 1}, [[0, 0, 0]]]
KEYS = ["mesh", "size", "material", "planes", "settings", "machine_profile", "name", "origin", "normal",
        "contours", "cuts", "plane_search", "plane_count", "max_solve_seconds", "min_segment", "density",
        "wire_diameter", "A/0", "", "\n", "x" * 100]


def seeds():
    """[(name, text)] of the seed scenes, sorted by name."""
    out = []
    for name in sorted(os.listdir(SEEDS)):
        if name.endswith(".json"):
            with open(os.path.join(SEEDS, name), encoding="utf-8") as f:
                out.append((name, f.read()))
    return out


def _nodes(value, path=()):
    """Every (path, value) of a decoded JSON value, the value itself first."""
    yield path, value
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _nodes(v, path + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from _nodes(v, path + (i,))


def _set(root, path, value):
    if not path:
        return value
    node = root
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value
    return root


def _odd(rng):
    value = rng.choice(ODD_VALUES)
    return json.loads(json.dumps(value)) if not isinstance(value, float) or math.isfinite(value) else value


def mutate(rng, text):
    """One mutant of the scene `text`: 1-4 structural edits of its JSON (a value replaced by an
    odd one, a key dropped or added, a list grown, shrunk or nested), or a byte-level edit of the
    text (a flip, a cut, an insertion, deep nesting)."""
    try:
        data = json.loads(text)
    except (ValueError, RecursionError):  # a finding's text: only byte-level edits apply
        data = None
    if data is None or rng.random() < 0.15:
        raw = bytearray(text.encode("utf-8"))
        kind = rng.randrange(4)
        if kind == 0 and raw:
            raw[rng.randrange(len(raw))] = rng.randrange(256)
        elif kind == 1:
            raw = raw[:rng.randrange(len(raw) + 1)]
        elif kind == 2:
            at = rng.randrange(len(raw) + 1)
            raw[at:at] = rng.choice([b"\xff", b"\xc3", b"\x00", b",", b"]", b"{", b"NaN", b"1e999", b'"\\ud800"'])
        else:
            depth = rng.choice([100, 1000, 100_000])
            return "[" * depth + "]" * depth if rng.random() < 0.5 else '{"planes": ' + "[" * depth + "]" * depth + "}"
        return raw.decode("utf-8", "surrogateescape")
    for _ in range(rng.randint(1, 4)):
        nodes = list(_nodes(data))
        path, value = rng.choice(nodes)
        kind = rng.randrange(6)
        if kind == 0:
            data = _set(data, path, _odd(rng))
        elif kind == 1 and isinstance(value, dict) and value:
            del value[rng.choice(list(value))]
        elif kind == 2 and isinstance(value, dict):
            value[rng.choice(KEYS)] = _odd(rng)
        elif kind == 3 and isinstance(value, list) and value:
            value.append(json.loads(json.dumps(rng.choice(value))))
            if rng.random() < 0.3:
                value.extend(json.loads(json.dumps(value[-1])) for _ in range(rng.choice([10, 70])))
        elif kind == 4 and isinstance(value, list) and value:
            value.pop(rng.randrange(len(value)))
        elif kind == 5:
            data = _set(data, path, [value] if rng.random() < 0.5 else {"x": value})
    return json.dumps(data, allow_nan=True)


def check(text, folder):
    """Reads `text` as the scene file folder/scene.json (folder holds m.obj): "read" or "refused";
    AssertionError describing the finding otherwise."""
    path = os.path.join(folder, "scene.json")
    with open(path, "w", encoding="utf-8", errors="surrogateescape") as f:
        f.write(text)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            scene = scene_reader.load_scene(path)
        except ValueError as exc:
            message = str(exc)
            assert message and "\n" not in message and "\r" not in message, f"a message on several lines: {message!r}"
            assert len(message) <= MAX_MESSAGE, f"a message of {len(message)} characters: {message[:200]!r}"
            return "refused"
        except Exception as exc:  # noqa: BLE001 - every other exception is the finding
            raise AssertionError(f"{type(exc).__name__}: {str(exc)[:300]}") from None
    for p in scene.planes:
        assert isinstance(p.name, str) and len(p.name.encode("utf-8", "surrogatepass")) <= scene_reader.MAX_NAME_BYTES
        assert not any(scene_reader._hidden(ch) or ch in "/\\" for ch in p.name), p.name
        largest = max(abs(c) for c in p.normal)
        assert all(math.isfinite(c) for c in p.normal + p.origin) and largest > 0, p
        assert all(c == 0 or abs(c) >= scene_reader.NORMAL_ZERO * largest for c in p.normal), p
    return "read"


def prepare(folder):
    with open(os.path.join(folder, "m.obj"), "w") as f:
        f.write(MESH)


def main(argv):
    seconds = float(argv[0]) if argv else 30.0
    out = argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(os.path.dirname(HERE)), "out", "fuzz", "scenes")
    os.makedirs(out, exist_ok=True)
    corpus = seeds()
    runs, findings, counts = 0, 0, {"read": 0, "refused": 0}
    rng = random.Random()
    end = time.monotonic() + seconds
    with tempfile.TemporaryDirectory() as folder:
        prepare(folder)
        while time.monotonic() < end:
            name, text = rng.choice(corpus)
            mutant = mutate(rng, text)
            runs += 1
            try:
                counts[check(mutant, folder)] += 1
            except AssertionError as exc:
                findings += 1
                crash = os.path.join(out, f"crash-{findings:03d}.json")
                with open(crash, "w", encoding="utf-8", errors="surrogateescape") as f:
                    f.write(mutant)
                print(f"finding ({name}): {exc} -> {crash}", flush=True)
    print(f"scene fuzz: {runs} inputs in {seconds:g} s ({counts['read']} read, {counts['refused']} refused), "
          f"{findings} findings", flush=True)
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
