"""The words of Live's verdict line (operators/live.py; the Wire panel adds "Live: "): its kinds,
each said with one prefix, and the part of a long reason the line shows.

- "stable", "solving…": a word alone;
- "not stable — <reason>": a solve that ended with the design not stable (design["reason"]);
- "cannot solve — <problem>": the scene as it is set up cannot be solved at all (no target, no
  contour ticked, a panel value the solver refuses, a ticked contour the plane no longer cuts):
  no verdict on the design, something to set up;
- "error — <text>": an unexpected exception (a bug of ours), said as such.

The line shows the first REASON_WORDS words of a reason. The reason itself is never reworded
(design.json keeps it; FORMATS.md). bpy-free.
"""
STABLE = "stable"
SOLVING = "solving…"
NOT_STABLE = "not stable"
CANNOT_SOLVE = "cannot solve"
ERROR = "error"
DASH = " — "  # between a kind and its text
REASON_WORDS = 30  # words of the reason the line shows (wrapped): enough for its numbers and units
MORE = "…"  # ends a shortened reason


def shown_reason(text, words=REASON_WORDS):
    """The first `words` words of `text`, ending with MORE when there are more."""
    split = text.split()
    return " ".join(split[:words]) + (MORE if len(split) > words else "")


def verdict(kind, text=""):
    """The line's verdict (without "Live: ") of `kind` (one of the kinds above) and its reason,
    problem or error `text` (shown_reason of it); the kind alone when `text` is empty."""
    return kind + DASH + shown_reason(text) if text.strip() else kind


def kind_of(line):
    """The kind of a verdict made by `verdict` (the panel picks its icon by it); "" when none."""
    for kind in (NOT_STABLE, CANNOT_SOLVE, ERROR):
        if line == kind or line.startswith(kind + DASH):
            return kind
    return line if line in (STABLE, SOLVING) else ""

