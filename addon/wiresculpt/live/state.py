"""Live's state, bpy-free: what the engine (live/engine.py) runs on, kept apart from what it records
for the tests and the bench (LiveRecord), and the one reader of both (observed)."""
import types


class LiveState:
    """The engine's run state; `record` holds what only the tests and the bench read."""

    def __init__(self):
        self.record = LiveRecord()
        self.reset()
        self.message = ""  # why Live was refused or stopped; kept across resets
        self.message_model = ""  # the name of the model `message` speaks of

    def reset(self):
        self.running = False  # the timer is registered
        self.seen = None  # the snapshot of the previous tick
        self.seen_since = 0.0  # time.monotonic() when `seen` was first seen
        self.solved = None  # the snapshot of the shown verdict
        self.job = None  # the LiveJob of the current snapshot, while it runs
        # core/live_verdict.verdict: "stable", "not stable — …", "cannot solve — …", … (the panel adds "Live: ")
        self.verdict = ""
        self.reason = ""  # the whole text behind `verdict` (its reason, problem or error), "" for a word alone
        self.kind = ""  # the kind of `verdict` (core/live_verdict: STABLE, NOT_STABLE, ...), "" before the first
        self.limits = ()  # the codes of the limits a stable verdict breaks (core/limits.limit_records)
        self.standing = ""  # the shown verdict's 3D check in one line (core/standing.summary), "" when it did not run
        self.preview = []  # [(RGBA, (2k, 3) float32 segment end points)], one per wire of the shown verdict
        # the wire id of each preview entry and the verdict's assembly_steps: the slider's filter
        # (core/assembly_view.shown_lines, ui/overlay)
        self.preview_ids, self.preview_steps = [], []
        self.mesh_key = None  # the model's name, matrix and geometry count the cached triangles belong to
        self.geometry = 0  # changes of the model's geometry seen by the depsgraph handler (edits, modifiers)
        self.failed = ""  # the last unexpected error's text, printed once
        self.mesh = None  # (V, F) world coordinates
        self.record.reset()


class LiveRecord:
    """What a run of Live did, for the tests and the bench (read through observed)."""

    def __init__(self):
        self.reset()

    def reset(self):
        self.durations = []  # seconds of each tick (the engine's stop keeps them)
        self.results = []  # the verdicts shown, in order
        self.shown_at = None  # time.monotonic() when the latest verdict was set
        self.drawn_at = None  # time.monotonic() of the overlay's latest draw of the preview
        self.job_seconds = None  # the shown verdict's LiveJob wall time
        self.drawn = 0  # overlay draws of the preview


STATE = LiveState()

# what observed() shows of the run state, besides the whole record
_SHOWN = ("running", "verdict", "reason", "kind", "limits", "standing", "preview", "preview_steps", "job", "solved", "geometry")


def observed(state=STATE):
    """A read-only view of Live now, for the tests and the bench: the run state's running, verdict,
    reason, kind, limits, standing, preview, preview_steps, job, solved and geometry, and the record's
    durations, results, shown_at, drawn_at, job_seconds and drawn (a copy: writing to it changes
    nothing)."""
    record = state.record
    return types.SimpleNamespace(
        **{name: getattr(state, name) for name in _SHOWN},
        durations=list(record.durations), results=list(record.results), shown_at=record.shown_at,
        drawn_at=record.drawn_at, job_seconds=record.job_seconds, drawn=record.drawn)
