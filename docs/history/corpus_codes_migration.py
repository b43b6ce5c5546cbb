"""One-off migration, run once on docs/corpus.json (the run of 2026-12-01, commit 3c1cdfb): the
verdict's codes each stored run carries since the pipeline writes them (scripts/corpus.py
run_codes: `verdict_cause`, `relayering_end`, `forbidden_hooks`), derived from what the stored
run kept, its reason's words, because that run predates the codes. Kept here, outside addon/ and
scripts/ (which must not read a message's words, blender_tests/pure/test_no_text_matching.py), as
the record of how the stored codes were made; a fresh `scripts/corpus.py bench` writes the codes
from the designs themselves and makes this obsolete.

    /usr/bin/python3.11 docs/history/corpus_codes_migration.py rerun [--cache DIR]   (build/corpus-check/rerun.json)
    /usr/bin/python3.11 docs/history/corpus_codes_migration.py [--check-only]

(rerun: RERUN, one scene per kind and a stable one, by scripts/corpus.py run_scene on the scenes of
`scripts/corpus.py prepare`, DIR defaulting to build/corpus.)

How each code is derived (the words are those the solver of that commit wrote, unchanged since):
- stable: verdict_cause "none", relayering_end "stable", forbidden_hooks as recorded: unknown
  (None; the run kept only the number of learnt pairs, not the too-close ones forbidden up front);
- the reason ends with "finds no stable assembly (stages.relayering)": the pipeline's note when the
  last layering found no stable assembly and the design is the last round the target shape reached:
  relayering_end "no_assembly"; that round's verdict is the target shape's ("the target shape
  cannot realise ...; without ... no longer stable"), verdict_cause "unrealised";
- otherwise the reason's first words name the verdict: the layering's own ("no hook configuration
  can make the finished sculpture stable" mechanism, "wire '...' crosses no other wire" alone,
  "search incomplete", "no pair of wires is stable" no_stable_pair, "no stable assembly order
  exists" no_assembly_order, "... are not connected to wire" disconnected), the target shape's
  ("the target shape cannot realise" unrealised) or the machine's ("the design cannot be made on
  the machine" not_buildable); a layering verdict's forbidden_hooks is the count its note gives
  ("(with N hook(s) forbidden"), 0 without the note (the native appends it exactly when N > 0);
  a later stage's verdict leaves the layering's count unknown (None);
- relayering_end, when not "no_assembly": "search_incomplete" for that verdict, "max_rounds" when
  the reason says the re-layering stopped after relayer_rounds, "nothing_new" otherwise (an
  unstable end with nothing left to forbid).

Checked two ways (both printed; the migration writes nothing unless both hold):
1. every stored run's kind in the report (scripts/corpus.py cause_kind over the derived codes)
   is the kind the report gave before from the reason's words (the former reason_kind, below),
   with the one fallback kind that had no name ("the design cannot be made on ...", the first
   six words) now named "the design cannot be made on the machine": the table's outcomes stay;
2. scenes re-run with the codes written by the pipeline (build/corpus-check/rerun.json, made by
   scripts/corpus.py run_scene on one scene per kind, `rerun`) carry the codes derived here for the same
   scene, whenever the fresh run's reason is the stored one word for word, figures aside (every
   number masked: the model size the scale advice names has been the mesh's since, not the
   contours'), i.e. the same verdict.
"""
import json
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import corpus  # noqa: E402

# The report's former grouping by the reason's words (scripts/corpus.py before the codes).
REASON_KINDS = (
    ("search incomplete", "the layering search hit max_nodes"),
    ("finds no stable assembly (stages.relayering)",
     "no stable assembly once the hooks the target shape cannot realise are forbidden"),
    ("hooks forbidden", "no stable assembly once the hooks the target shape cannot realise are forbidden"),
    ("no hook configuration can make the finished sculpture stable",
     "a mechanism: not stable with both hooks at every crossing"),
    ("no pair of wires is stable", "no pair of wires holds under forces only"),
    ("no stable assembly order exists", "no stable assembly order"),
    ("the target shape cannot realise", "crossings the target shape cannot realise (re-layering stopped)"),
    ("crosses no other wire", "a wire crosses no other"),
)
RENAMED = {"the design cannot be made on ...": "the design cannot be made on the machine"}


def reason_kind(reason):
    kind = next((kind for words, kind in REASON_KINDS if words in reason), corpus.first_words(reason, 6))
    return RENAMED.get(kind, kind)


LEADS = (  # the reason's first words -> verdict_cause
    ("search incomplete", "search_incomplete"),
    ("no hook configuration can make the finished sculpture stable", "mechanism"),
    ("no pair of wires is stable", "no_stable_pair"),
    ("no two wires cross", "no_crossings"),
    ("no stable assembly order exists", "no_assembly_order"),
    ("the target shape cannot realise", "unrealised"),
    ("the design cannot be made on the machine", "not_buildable"),
)
LAYERING = ("search_incomplete", "mechanism", "no_stable_pair", "no_crossings", "no_assembly_order")


def derive(run):
    """{verdict_cause, relayering_end, forbidden_hooks} of a stored run (the module's rules)."""
    reason = run["reason"]
    if run["stable"]:
        return {"verdict_cause": "none", "relayering_end": "stable", "forbidden_hooks": None}
    if reason.endswith("finds no stable assembly (stages.relayering)"):
        assert reason.startswith("the target shape cannot realise"), run["name"]
        return {"verdict_cause": "unrealised", "relayering_end": "no_assembly", "forbidden_hooks": None}
    cause = next((code for words, code in LEADS if reason.startswith(words)), None)
    if cause is None and re.match(r"wire '[^']*' crosses no other wire, so nothing can hold it$", reason):
        cause = "alone"
    if cause is None and re.match(r"wire '[^']*' and the wires it crosses are not connected to wire", reason):
        cause = "disconnected"
    assert cause is not None, (run["name"], reason)
    note = re.search(r"\(with (\d+) hooks? forbidden because the target shape cannot realise them", reason)
    hooks = (int(note.group(1)) if note else 0) if cause in LAYERING else 0 if cause in ("alone", "disconnected") \
        else None
    end = ("search_incomplete" if cause == "search_incomplete"
           else "max_rounds" if "(re-layering stopped after relayer_rounds = " in reason else "nothing_new")
    return {"verdict_cause": cause, "relayering_end": end, "forbidden_hooks": hooks}


def same_words(a, b):
    """Whether two reasons are the same words, every number masked."""
    def masked(text):
        return re.sub(r"\d+(\.\d+)?", "#", text)
    return masked(a) == masked(b)


RERUN = ("dino-zzxxy5-0.3", "armadillo-zzxxy5-0.3", "man-xyz3-0.3", "homer-zzxxy5-0.5", "bear-zzxxy5-0.5",
         "hand-xyz3-0.3")
FRESH = os.path.join(ROOT, "build", "corpus-check", "rerun.json")


def rerun(cache):
    with open(os.path.join(cache, "manifest.json")) as f:
        scenes = [e for e in json.load(f)["scenes"] if e["name"] in RERUN]
    rows = {e["name"]: corpus.run_scene(e, os.path.join(os.path.dirname(FRESH), "out")) for e in scenes}
    os.makedirs(os.path.dirname(FRESH), exist_ok=True)
    with open(FRESH, "w") as f:
        json.dump(rows, f, indent=1)
    return 0


def main(argv):
    if argv[:1] == ["rerun"]:
        return rerun(argv[argv.index("--cache") + 1] if "--cache" in argv else os.path.join(ROOT, "build", "corpus"))
    path = os.path.join(ROOT, "docs", "corpus.json")
    with open(path) as f:
        results = json.load(f)
    runs = [r for r in results["runs"] if r["stable"] is not None]
    derived = {r["name"]: derive(r) for r in runs}
    kinds_differ = [(r["name"], reason_kind(r["reason"]), corpus.cause_kind(derived[r["name"]]))
                    for r in runs if not r["stable"]
                    and reason_kind(r["reason"]) != corpus.cause_kind(derived[r["name"]])]
    print(f"check 1: {len(runs)} runs, {len(kinds_differ)} whose kind differs {kinds_differ}")
    with open(FRESH) as f:
        fresh = json.load(f)
    keys = ("verdict_cause", "relayering_end", "forbidden_hooks")
    compared, differ = [], []
    for name, row in sorted(fresh.items()):
        stored = next(r for r in runs if r["name"] == name)
        if not same_words(row["reason"], stored["reason"]) or row["stable"] != stored["stable"]:
            print(f"check 2: {name}: the fresh run's verdict is not the stored one; not compared")
            continue
        want = derived[name]
        got = {k: row[k] for k in keys if want[k] is not None}
        compared.append(name)
        if got != {k: v for k, v in want.items() if v is not None}:
            differ.append((name, want, got))
    print(f"check 2: {len(compared)} re-run scenes compared ({', '.join(compared)}), {len(differ)} differ {differ}")
    if kinds_differ or differ or not compared or "--check-only" in argv:
        return 1 if kinds_differ or differ or not compared else 0
    for r in results["runs"]:
        if r["name"] in derived:
            r.update(derived[r["name"]])
    with open(path + ".tmp", "w") as f:
        json.dump(results, f, indent=1)
    os.replace(path + ".tmp", path)
    print(f"wrote the codes of {len(derived)} runs into {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
