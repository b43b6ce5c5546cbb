"""The plane assistant on the real-mesh corpus (scripts/corpus.py prepare), in-process
(system Python with the built module; no Blender): for every `zzxxy5` scene at the given size, the
planes as given ("off"), then `plane_search: "nearby"`; and for every mesh `plane_search: "auto"`
with N planes. Every stable design is re-checked (blender_tests/pure/recheck.py). Prints a
Markdown table and writes JSON; with --section FILE (docs/performance.md) also writes the table
between FILE's `<!-- planes:begin -->` and `<!-- planes:end -->`, keeping the section's hand-written
notes (from `<!-- planes:notes -->` on); with --counts "" (nearby only) the section's auto columns
are kept as they were, and its header says from which run. --out also records the load average at the start and
end and the commit; --from-json FILE redoes the table and section from such a file, without a run.

    python3.11 scripts/plane_search_corpus.py [--cache build/corpus] [--size 0.5] [--counts 5] [--out FILE]
                                              [--section FILE] [--from-json FILE] [NAME...]
"""
import argparse
import datetime
import json
import os
import re
import subprocess
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
        out.update(changes=r["changes"], candidates=r["candidates"], full_solves=r["full_solves"], score=r["score"],
                   budget=r["budget_seconds"], final_solve=r.get("final_solve"), solves_stopped=r["solves_stopped"])
        if "not_found" in r:
            out["not_found"] = r["not_found"]
    return out


BEGIN, END, NOTES = "<!-- planes:begin -->", "<!-- planes:end -->", "<!-- planes:notes -->"


def nearby_cell(nearby):
    """An unstable nearby row's cell, from the search's record of how it ended (`not_found`,
    docs/formats.md): whether the budget ended the search (after N of M candidates) or every
    candidate was screened, and its advice (the reason's "To change: ..."), cut at 160 characters;
    a row without that record (the search did not run: an error) by its reason's first 100
    characters."""
    ending, reason = nearby.get("not_found"), nearby.get("reason") or ""
    if not ending:
        return f"*{reason[:100]}{'…' if len(reason) > 100 else ''}*"
    todo = "; or ".join(ending["advice"])
    head = (f"budget ended after {ending['screened']} of {ending['total']} candidates" if ending["budget_ended"] else
            f"all {ending['total']} candidates screened" if ending["screened"] == ending["total"] else "")
    return f"{head}; *{todo[:160]}{'…' if len(todo) > 160 else ''}*"


def table(rows, counts, kept=None):
    """The Markdown table: a row per mesh, the auto columns of `counts` from the rows or, when
    `kept` = (headers, {mesh: cells}) is given (a nearby-only run), those cells as they were."""
    def verdict(r):
        if r["stable"]:
            return "stable" + ("" if not r.get("recheck") else " (re-check FAILS)")
        return "not stable"
    autos = kept[0] if kept else [f"auto N={n} (s, screened / solved)" for n in counts]
    lines = ["| " + " | ".join(["mesh", "given planes", "nearby", "nearby s (screened / solved)"] + autos) + " |",
             "|" + "---|" * (4 + len(autos))]
    for row in rows:
        nb = row["nearby"]
        change = ("; ".join(nb.get("changes") or []) or "kept as given" if nb["stable"] else nearby_cell(nb))
        cells = (kept[1].get(row["mesh"], ["-"] * len(autos)) if kept else
                 [f"{verdict(row[f'auto{n}'])} ({row[f'auto{n}']['seconds']:.1f}, "
                  f"{row[f'auto{n}'].get('candidates', '-')} / {row[f'auto{n}'].get('full_solves', '-')})"
                  for n in counts])
        lines.append("| " + " | ".join([row["mesh"], verdict(row["off"]), f"{verdict(nb)}: {change}",
                                        f"{nb['seconds']:.1f} ({nb.get('candidates', '-')} / "
                                        f"{nb.get('full_solves', '-')})"] + cells) + " |")
    return lines


def kept_auto(old):
    """From an earlier planes section `old`: (the auto columns' headers, {mesh: their cells}) and
    a sentence saying when that run was (date, commit, load, budget), and its auto result.
    SystemExit when it has none, naming what is missing."""
    rows = [[c.strip() for c in line.strip().strip("|").split(" | ")] for line in old.splitlines()
            if line.startswith("| ")]
    if not rows or not any(c.startswith("auto N=") for c in rows[0]):
        raise SystemExit("plane_search_corpus: --counts \"\" (nearby only) keeps the auto columns of the "
                         "section, but its table has none: run with --counts")
    first = [k for k, c in enumerate(rows[0]) if c.startswith("auto N=")][0]
    result = re.search(r"Auto(?: \(the run before\))?: stable on [^.]*\.", old)
    before = re.search(r"The auto columns are kept from the run before \(.*?\)\.", old, re.S)
    if before and result:  # a nearby-only section already: its auto part as it says
        return ((rows[0][first:], {r[0]: r[first:] for r in rows[1:]}), before.group(0),
                result.group(0).replace("Auto (the run before):", "Auto:"))
    run = re.search(r"\((\d{4}-\d\d-\d\d), commit (\w+);", old)
    load = re.search(r"shared: ([\d.]+) at the start, ([\d.]+) at the end", old)
    budget = re.search(r'`"auto"` \(((?:budget|at most) .*?)\)', old, re.S)  # the older header said "budget"
    if not (run and load and budget and result):
        raise SystemExit("plane_search_corpus: the section's header does not say when its auto columns ran "
                         "(date, commit, load, budget, result): run with --counts")
    about = (f"The auto columns are kept from the run before ({run.group(1)}, commit {run.group(2)}, load "
             f"{load.group(1)} at the start and {load.group(2)} at the end; {budget.group(1)}).")
    return (rows[0][first:], {r[0]: r[first:] for r in rows[1:]}), about, result.group(0)


def head_commit():
    try:
        return subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True).stdout.strip() or "?"
    except OSError:
        return "?"


def section(path, rows, counts, args, load, commit):
    """Writes the table and the run's header between the planes markers of `path`, keeping the
    notes after `<!-- planes:notes -->` of the section as it was. With no counts (a nearby-only
    run), the auto columns and what the header said of them are kept from the section (kept_auto)."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    old = re.search(re.escape(BEGIN) + r".*?" + re.escape(END), text, re.S)
    notes = ""
    if old and NOTES in old.group(0):
        notes = old.group(0).split(NOTES, 1)[1].rsplit(END, 1)[0].strip("\n")
    kept, about, auto_result = None, "", ""
    if not counts:
        if not old:
            raise SystemExit(f"plane_search_corpus: {path} has no planes section whose auto columns a nearby-only "
                             "run could keep: run with --counts")
        kept, about, auto_result = kept_auto(old.group(0).split(NOTES, 1)[0])
        auto_result = auto_result.replace("Auto: stable", "Auto (the run before): stable") + " "
    stable = {n: sum(1 for r in rows if r[f"auto{n}"]["stable"]) for n in counts}
    fixed = sum(1 for r in rows if not r["off"]["stable"] and r["nearby"]["stable"])
    unstable = sum(1 for r in rows if not r["off"]["stable"])
    rechecked = sum(1 for r in rows for k in ["nearby"] + [f"auto{n}" for n in counts] if r[k]["stable"])
    failed = sum(1 for r in rows for k in ["nearby"] + [f"auto{n}" for n in counts] if r[k].get("recheck"))
    auto_run = ("" if kept else
                f', and every mesh with `"auto"` (at most {plane_search.AUTO_SCREENS_PER_PLANE} proposals screened and '
                f"{plane_search.AUTO_SOLVES_PER_PLANE} solved per plane, then at most {plane_search.FINAL_HOOK_PATTERNS} "
                "patterns for the comparison of hook patterns on the returned design)")
    counts_arg = args.counts or '""'
    head = [BEGIN, "## Plane assistant on the real-mesh corpus", "",
            f"`scripts/bench planes --size {args.size} --counts {counts_arg} --section docs/performance.md` "
            f"({datetime.date.today().isoformat()}, commit {commit}; `scripts/plane_search_corpus.py`, in-process with "
            "the system Python 3.11 and the built module, no Blender): every `zzxxy5` scene of the corpus at "
            f"{args.size} m, solved with the planes as given, then with `plane_search: \"nearby\"` (at most "
            f"{plane_search.NEARBY_SCREENS} candidates screened and {plane_search.NEARBY_SOLVES} solved){auto_run}. Load average (1 min) of the 2-core "
            f"machine, shared: {load[0]:.1f} at the start, {load[1]:.1f} at the end. Every stable design of the run is "
            f"re-checked by `blender_tests/pure/recheck.py`: {rechecked} stable, {failed} refused by it."
            + (f" {about}" if about else ""), "",
            (f"Auto: stable on {', '.join(f'{stable[n]}' for n in counts)} of {len(rows)} meshes for "
             f"N = {', '.join(str(n) for n in counts)}. " if counts else auto_result)
            + f"Nearby: {fixed} of the {unstable} unstable scenes made stable.", ""]
    body = "\n".join(head + table(rows, counts, kept) + ["", NOTES] + ([notes] if notes else []) + [END])
    text = text.replace(old.group(0), body) if old else text.rstrip("\n") + "\n\n" + body + "\n"
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def main(argv):
    parser = argparse.ArgumentParser()
    parser.add_argument("--cache", default=os.path.join(ROOT, "build", "corpus"))
    parser.add_argument("--size", default="0.5")
    parser.add_argument("--counts", default="5")
    parser.add_argument("--out", default=None)
    parser.add_argument("--section", default=None, help="write the table into this file's planes section")
    parser.add_argument("--from-json", default=None, help="no run: the rows of an earlier --out (its load average "
                                                          "is recorded in it)")
    parser.add_argument("names", nargs="*")
    args = parser.parse_args(argv)
    folder = os.path.join(args.cache, "scenes")
    counts = [int(c) for c in args.counts.split(",") if c.strip()]  # --counts "": nearby only
    rows, load = [], [os.getloadavg()[0]]
    if args.from_json:
        with open(args.from_json) as f:
            saved = json.load(f)
        rows, load, commit = saved["rows"], saved["load"], saved["commit"]
    else:
        commit = head_commit()  # the code that ran
    for name in ([] if args.from_json else sorted(os.listdir(folder))):
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
    if not args.from_json:
        load.append(os.getloadavg()[0])
    if args.out:
        with open(args.out, "w") as f:
            json.dump({"rows": rows, "load": load, "commit": commit}, f, indent=1)
    print("\n" + "\n".join(table(rows, counts)))
    if args.section:
        section(args.section, rows, counts, args, load, commit)


if __name__ == "__main__":
    main(sys.argv[1:])
