"""The words of Live's verdict line (live/engine.py; the Wire panel adds "Live: "): its kinds,
each said with one prefix, and the part of a long reason the line shows.

- "stable", "solving…": a word alone;
- "stable, over its limits — <limits>": stable and buildable but breaking a limit a maker asked
  for (core/limits.py: the load factor, wires bending out of their planes, the stock, the size);
- "not stable — <reason>": a solve that ended with the design not stable (design["reason"]);
- "cannot solve — <problem>": the scene as it is set up cannot be solved at all (no model, no
  contour ticked, a panel value the solver refuses, a ticked contour the plane no longer cuts,
  fewer than two wires: the pipeline's setup reasons, core/design.setup_problem): no verdict on
  the design, something to set up;
- "error — <text>": an unexpected exception (a bug of ours), said as such.

A reason is shown whole up to REASON_WORDS words. The solver's reasons repeat a prefix per
crossing or wire ("crossing 0 on wire Front/0: …; crossing 1 on wire Front/0: …"), so a longer one
shows its first clause (up to the first ";" or full stop outside brackets) whole, where its
deciding figure (the angle, the length, the scale) comes last, up to CLAUSE_WORDS words. The reason
itself is never reworded (design.json keeps it; docs/formats.md). bpy-free.
"""
from .design import setup_problem
from .limits import OVER_LIMITS, STOCK_LENGTH, broken_limits

STABLE = "stable"
SOLVING = "solving…"
NOT_STABLE = "not stable"
CANNOT_SOLVE = "cannot solve"
ERROR = "error"
DASH = " — "  # between a kind and its text
# Reasons up to this many words are shown whole: the hinge reason of one wire with its advice (54
# words) is.
REASON_WORDS = 60
# The first clause of a longer reason is shown whole up to this many words: Live's solves of the
# globe and the bench scenes with planes moved or a bend limit lowered gave first clauses of 30-43
# words (a 30-word cut ended before "the machine bends at most 30°"); the corpus's too-close clause,
# which lists the crossings and ends with the scale to reach, up to 75 (docs/corpus.json).
CLAUSE_WORDS = 80
MORE = "…"  # ends a shortened reason


def clause_end(text):
    """The index just past the first clause of `text`: its first ";", or full stop followed by a
    space, outside brackets; len(text) when there is none. (A decimal point is followed by a digit,
    "stages.relayering" by a letter.)"""
    depth = 0
    for i, ch in enumerate(text):
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth = max(0, depth - 1)
        elif depth == 0 and (ch == ";" or ch == "." and (i + 1 == len(text) or text[i + 1].isspace())):
            return i + 1
    return len(text)


def shown_reason(text, words=REASON_WORDS, clause_words=CLAUSE_WORDS):
    """What the verdict line shows of `text` (whitespace collapsed): all of it up to `words` words,
    else its first clause (clause_end) up to `clause_words` words, else its first `clause_words`
    words. A shortened text ends with MORE (its clause's own ";" or "." dropped)."""
    if len(text.split()) <= words:
        return " ".join(text.split())
    end = clause_end(text)
    clause = text[:end].split()
    if len(clause) > clause_words:
        return " ".join(clause[:clause_words]) + MORE
    shown = " ".join(clause)
    if not text[end:].strip():  # one clause: all of it fits
        return shown
    return (shown[:-1] if shown.endswith((";", ".")) else shown).rstrip() + MORE


def verdict(kind, text=""):
    """The line's verdict (without "Live: ") of `kind` (one of the kinds above) and its reason,
    problem or error `text` (shown_reason of it); the kind alone when `text` is empty."""
    return kind + DASH + shown_reason(text) if text.strip() else kind


def of_design(design, stock_length=STOCK_LENGTH):
    """(kind, text) of a solved `design`: STABLE alone, or OVER_LIMITS with the limits it breaks
    (core/limits.broken_limits, with the machine's `stock_length`, m); CANNOT_SOLVE with its reason when that is a setup problem
    (core/design.setup_problem: fewer than two wires, nothing was solved); else NOT_STABLE with its
    reason."""
    if design["stable"]:
        limits = broken_limits(design, stock_length)
        return (OVER_LIMITS, "; ".join(limits)) if limits else (STABLE, "")
    return (CANNOT_SOLVE if setup_problem(design) else NOT_STABLE), design.get("reason") or ""


def shortened(text):
    """Whether the line shows only part of `text` (shown_reason)."""
    return shown_reason(text) != " ".join(text.split())
