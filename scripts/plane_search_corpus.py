"""The plane assistant (issue 15) on the real-mesh corpus (scripts/corpus.py prepare), in-process
(system Python with the built module; no Blender): for every `zzxxy5` scene at the given size, the
planes as given ("off"), then `plane_search: "nearby"`; and for every mesh `plane_search: "auto"`
with N planes. Every stable design is re-checked (blender_tests/pure/recheck.py). Prints a
Markdown table and writes JSON.

    python3.11 scripts/plane_search_corpus.py [--cache build/corpus] [--size 0.5] [--counts 5] [--out FILE] [NAME...]
"""
import argparse
import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(ROOT, "addon"), os.path.join(ROOT, "blender_tests", "pure"), os.path.join(ROOT, "scripts")]

from corpus import read_obj  # noqa: E402
from recheck import recheck  # noqa: E402
from wiresculpt import plane_search  # noqa: E402
from wiresculpt.core.scene import PlaneSpec, load_scene  # noqa: E402


def mesh_of(scene):
    with open(scene.mesh) as f:
        V, F = read_obj(f.read())
    V, F = np.asarray(V, dtype=float), np.asarray(F, dtype=np.int64)
    factor = scene.size / float(np.max(V.max(axis=0) - V.min(axis=0))) if scene.size else 1.0
    return V * factor, F, factor


def one(V, F, planes, scene, **settings):
    s = dict(scene.settings, **settings)
    start = time.perf_counter()
    try:
        design, _used = plane_search.run(V, F, planes, scene.material, s)
    except (ValueError, RuntimeError) as exc:
        return {"stable": False, "reason": f"error: {exc}", "seconds": time.perf_counter() - start}
    out = {"stable": design["stable"], "reason": design["reason"], "seconds": time.perf_counter() - start}
    if design["stable"]:
        out["recheck"] = recheck(json.loads(json.dumps(design)))
    if "plane_search" in design:
        r = design["plane_search"]
        out.update(changes=r["changes"], candidates=r["candidates"], full_solves=r["full_solves"], score=r["score"])
    return out


def main(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("--cache", default=os.path.join(ROOT, "build", "corpus"))
    parser.add_argument("--size", default="0.5")
    parser.add_argument("--counts", default="5")
    parser.add_argument("--out", default=None)
    parser.add_argument("names", nargs="*")
    args = parser.parse_args(argv)
    folder = os.path.join(args.cache, "scenes")
    counts = [int(c) for c in args.counts.split(",") if c.strip()]  # --counts "": nearby only
    rows = []
    for name in sorted(os.listdir(folder)):
        mesh, config, size = name[:-5].rsplit("-", 2)
        if config != "zzxxy5" or size != args.size or (args.names and mesh not in args.names):
            continue
        scene = load_scene(os.path.join(folder, name))
        V, F, factor = mesh_of(scene)
        planes = [PlaneSpec(p.name, tuple(factor * c for c in p.origin), p.normal, p.contours) for p in scene.planes]
        row = {"mesh": mesh, "off": one(V, F, planes, scene), "nearby": one(V, F, planes, scene, plane_search="nearby")}
        for n in counts:
            row[f"auto{n}"] = one(V, F, [], scene, plane_search="auto", plane_count=n)
        rows.append(row)
        print(json.dumps(row)[:600], flush=True)
    if args.out:
        with open(args.out, "w") as f:
            json.dump(rows, f, indent=1)
    print("\n| mesh | given planes | nearby | nearby s (screened / solved) | " +
          " | ".join(f"auto N={n}" for n in counts) + " |")
    print("|---|---|---|---|" + "---|" * len(counts))

    def verdict(r):
        if r["stable"]:
            return "stable" + ("" if not r.get("recheck") else " (re-check FAILS)")
        return "not stable"
    for row in rows:
        nb = row["nearby"]
        change = "; ".join(nb.get("changes") or []) if nb["stable"] else nb["reason"][-90:]
        autos = " | ".join(f"{verdict(row[f'auto{n}'])} ({row[f'auto{n}']['seconds']:.1f} s)"
                           for n in counts)
        print(f"| {row['mesh']} | {verdict(row['off'])} | {verdict(nb)}: {change} | {nb['seconds']:.1f} "
              f"({nb.get('candidates', '-')} / {nb.get('full_solves', '-')}) | {autos} |")


if __name__ == "__main__":
    main(sys.argv[1:])
