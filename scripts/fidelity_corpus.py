"""How much of each corpus mesh's outline the plane assistant's auto designs trace (core/fidelity.py),
before and after auto maximised it: in-process (system Python with the built module, no Blender).

    python3.11 scripts/fidelity_corpus.py run --out FILE [--root CHECKOUT] [--cache build/corpus]
                                              [--size 0.5] [--count 5] [NAME...]
        runs `plane_search: "auto"` with `plane_count` COUNT on every closed corpus mesh (its
        zzxxy5 scene at SIZE: material and settings) with the add-on of CHECKOUT (default: this
        one; another checkout's add-on, e.g. `git archive` of an earlier commit with this build's
        module copied in, gives "before") and writes the designs' wires to FILE (JSON).
    python3.11 scripts/fidelity_corpus.py report --before FILE --after FILE [--docs docs]
        measures both files' designs with this checkout's core/fidelity.py, writes
        DOCS/images/fidelity/NAME.png (three views, front, side, top from left to right; the top
        row before, the bottom row after) and the table between `<!-- fidelity:begin -->` and
        `<!-- fidelity:end -->` of DOCS/fidelity.md.

In the renders the mesh's silhouette is light grey, its outline green where a wire lies within the
tolerance and red where none does, and the wires (target shapes, projected) dark blue.
"""
import argparse
import json
import os
import struct
import sys
import time
import zlib

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BEGIN, END = "<!-- fidelity:begin -->", "<!-- fidelity:end -->"
RENDER_PIXELS = 240  # pixels across the model size in the renders (the measure uses fidelity.PIXELS)


def mesh_of(scene, read_obj):
    with open(scene.mesh) as f:
        V, F = read_obj(f.read())
    V, F = np.asarray(V, dtype=float), np.asarray(F, dtype=np.int64)
    factor = scene.size / float(np.max(V.max(axis=0) - V.min(axis=0))) if scene.size else 1.0
    return V * factor, F


def names_of(cache, only):
    with open(os.path.join(cache, "manifest.json")) as f:
        meshes = json.load(f)["meshes"]
    kept = [m["name"] for m in meshes if os.path.exists(os.path.join(cache, "meshes", m["name"] + ".obj"))]
    return [n for n in kept if not only or any(o in n for o in only)]


def run(args):
    sys.path[:0] = [os.path.join(args.root, "addon"), os.path.join(ROOT, "scripts")]
    from corpus import read_obj
    from wiresculpt import plane_search
    from wiresculpt.core.scene import load_scene

    rows = {}
    for name in names_of(args.cache, args.names):
        scene = load_scene(os.path.join(args.cache, "scenes", f"{name}-zzxxy5-{args.size:g}.json"))
        V, F = mesh_of(scene, read_obj)
        settings = dict(scene.settings, plane_search="auto", plane_count=args.count)
        start = time.perf_counter()
        try:
            design, _used = plane_search.run(V, F, [], scene.material, settings)
        except (ValueError, RuntimeError) as exc:
            rows[name] = {"stable": False, "reason": f"error: {exc}", "wires": []}
            continue
        wires = [{"name": w["name"], "closed": w["closed"],
                  "points": w.get("target") or w["contour"]} for w in design["wires"]]
        rows[name] = {"stable": design["stable"], "reason": design["reason"], "wires": wires,
                      "seconds": time.perf_counter() - start,
                      "changes": design.get("plane_search", {}).get("changes", []),
                      "coverage": design.get("plane_search", {}).get("coverage")}
        print(f"{name}: {'stable' if design['stable'] else 'not stable'}, {len(wires)} wires, "
              f"{rows[name]['seconds']:.0f} s", file=sys.stderr)
    with open(args.out, "w") as f:
        json.dump({"root": os.path.abspath(args.root), "size": args.size, "count": args.count,
                   "load": os.getloadavg(), "rows": rows}, f)


def png(path, rgb):
    """Writes the (H, W, 3) uint8 image `rgb` as a PNG (8-bit RGB, no filter)."""
    H, W, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[i].tobytes() for i in range(H))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


GREY, GREEN, RED, BLUE, WHITE = (215, 215, 215), (0, 160, 60), (220, 30, 30), (20, 40, 140), (255, 255, 255)


def render_view(view, shapes, tolerance):
    """(H, W, 3) image of `view` (a fidelity.View), y up: silhouette, outline traced or not, wires."""
    from wiresculpt.core import fidelity

    mask = view.mask
    img = np.full(mask.shape + (3,), 255, dtype=np.uint8)
    img[mask] = GREY
    P = np.pad(mask, 2)
    inner = P[1:-1, 1:-1] & P[:-2, 1:-1] & P[2:, 1:-1] & P[1:-1, :-2] & P[1:-1, 2:]  # (H + 2, W + 2)
    deep = inner[1:-1, 1:-1] & inner[:-2, 1:-1] & inner[2:, 1:-1] & inner[1:-1, :-2] & inner[1:-1, 2:]
    edge = mask & ~deep  # the outline drawn two pixels wide, inside the silhouette
    rows, cols = np.nonzero(edge)
    centres = np.stack([cols + 0.5, rows + 0.5], axis=1)
    projected = [(view.project(p), closed) for p, closed in shapes]
    hit = fidelity.near(centres, projected, tolerance / view.pixel)
    img[rows[hit], cols[hit]] = GREEN
    img[rows[~hit], cols[~hit]] = RED
    A, B = fidelity.segments(projected)
    for a, b in zip(A, B):
        n = max(int(np.ceil(np.linalg.norm(b - a) * 2)), 1)
        t = np.linspace(0.0, 1.0, n + 1)[:, None]
        q = np.floor(a + t * (b - a)).astype(int)
        ok = (q[:, 0] >= 0) & (q[:, 0] < mask.shape[1]) & (q[:, 1] >= 0) & (q[:, 1] < mask.shape[0])
        img[q[ok, 1], q[ok, 0]] = BLUE
    return img[::-1]


def render(V, F, rows_of_shapes):
    """One image: a row per entry of `rows_of_shapes` ([(points, closed)] or None: no design), the
    three views side by side."""
    from wiresculpt.core import fidelity

    outlines = fidelity.Silhouettes(V, F)
    drawn = fidelity.Silhouettes.__new__(fidelity.Silhouettes)  # the same views at the render's pixel
    drawn.size, drawn.pixel, drawn.tolerance = outlines.size, outlines.size / RENDER_PIXELS, outlines.tolerance
    drawn.views = [fidelity.View(name, axes, V, F, drawn.pixel) for name, axes in fidelity.VIEWS]
    height = max(v.mask.shape[0] for v in drawn.views)
    lines = []
    for shapes in rows_of_shapes:
        parts = []
        for v in drawn.views:
            img = render_view(v, shapes or [], drawn.tolerance)
            pad = np.full((height - img.shape[0], img.shape[1], 3), 255, dtype=np.uint8)
            parts += [np.concatenate([pad, img]), np.full((height, 8, 3), 255, dtype=np.uint8)]
        lines += [np.concatenate(parts[:-1], axis=1), np.full((8, sum(p.shape[1] for p in parts[:-1]), 3), 180,
                                                              dtype=np.uint8)]
    return np.concatenate(lines[:-1])


def report(args):
    sys.path[:0] = [os.path.join(ROOT, "addon"), os.path.join(ROOT, "scripts")]
    from corpus import read_obj
    from wiresculpt.core import fidelity
    from wiresculpt.core.scene import load_scene

    with open(args.before) as f:
        before = json.load(f)
    with open(args.after) as f:
        after = json.load(f)
    size, count = after["size"], after["count"]
    images = os.path.join(args.docs, "images", "fidelity")
    os.makedirs(images, exist_ok=True)
    lines = [f"Auto at N = {count}, {size:g} m, the corpus' zzxxy5 scene settings; tolerance "
             f"{fidelity.TOLERANCE * size * 1000:.0f} mm ({fidelity.TOLERANCE:.0%} of the model size). "
             f"Load average during the runs: before {before['load'][0]:.1f}, after {after['load'][0]:.1f} "
             "(the search has a time budget: a busier machine screens fewer proposals).", "",
             "| mesh | before: fidelity (front / side / top) | after: fidelity (front / side / top) | after: coverage | renders |",
             "|---|---|---|---|---|"]
    for name in sorted(after["rows"]):
        scene = load_scene(os.path.join(args.cache, "scenes", f"{name}-zzxxy5-{size:g}.json"))
        V, F = mesh_of(scene, read_obj)
        outlines = fidelity.Silhouettes(V, F)
        cells, shown = [], []
        for run_ in (before, after):
            row = run_["rows"].get(name)
            if row is None or not row["wires"]:
                cells.append("not run" if row is None else f"*{row['reason'][:60]}*")
                shown.append(None)
                continue
            shapes = [(np.asarray(w["points"], dtype=float), w["closed"]) for w in row["wires"]]
            r = outlines.fidelity(shapes)
            v = r["views"]
            cell = f"**{r['share']:.2f}** ({v['front']:.2f} / {v['side']:.2f} / {v['top']:.2f})"
            cells.append(cell if row["stable"] else f"{cell}, not stable")
            shown.append(shapes)
        cover = after["rows"][name].get("coverage")
        png(os.path.join(images, f"{name}.png"), render(V, F, shown))
        lines.append(f"| {name} | {cells[0]} | {cells[1]} | {'' if cover is None else f'{cover:.2f}'} | "
                     f"[{name}.png](images/fidelity/{name}.png) |")
        print(lines[-1], file=sys.stderr)
    md = os.path.join(args.docs, "fidelity.md")
    with open(md) as f:
        text = f.read()
    head, rest = text.split(BEGIN, 1)
    _old, tail = rest.split(END, 1)
    with open(md, "w") as f:
        f.write(head + BEGIN + "\n" + "\n".join(lines) + "\n" + END + tail)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("command", choices=("run", "report"))
    parser.add_argument("names", nargs="*")
    parser.add_argument("--root", default=ROOT)
    parser.add_argument("--cache", default=os.path.join(ROOT, "build", "corpus"))
    parser.add_argument("--size", type=float, default=0.5)
    parser.add_argument("--count", type=int, default=5)
    parser.add_argument("--out")
    parser.add_argument("--before")
    parser.add_argument("--after")
    parser.add_argument("--docs", default=os.path.join(ROOT, "docs"))
    args = parser.parse_args(argv)
    (run if args.command == "run" else report)(args)


if __name__ == "__main__":
    main()
