"""Sending one wire's bend program to a GRBL bender (Sec. 5.1; protocol: docs/machine-protocol.md).

The G-code comes from the design's rest shape and the machine profile (export.machine_profile),
is streamed by the native stream_program in a worker thread (it releases the GIL), and its state is
kept per wire in PENDING, so a Resume after an error, a dropped link or a cancel continues where the
native state says: the first unacknowledged line, or, when the stop may have lost moves GRBL had
acknowledged (queued) but not run, the first line of that step (the stop's message names it and
asks to check the wire). No line is skipped.

Free of bpy: the add-on's operators, and the tests, call it.
"""
import numpy as np

from .. import native
from ..core import session
from ..core.jobs import WorkerJob
from . import export

PENDING = {}  # wire name -> Stopped: the program a Resume continues
JOB = None  # the StreamJob while a wire is being sent, else None
LAST = {}  # wire name -> (report type, sentence) of its last run, for the panel
# PENDING and LAST are the open file's: another file's wires may have the same names.
# forget() empties them when a file is loaded (blend/ownership's load handlers), and a stream that
# ends after a load records nothing (its generation is the closed file's).


def forget():
    """No stop to resume and no last run (a file is being loaded); a running stream goes on."""
    PENDING.clear()
    LAST.clear()


def rest_wires(design):
    """The design's wires that have a rest shape (the ones that can be bent)."""
    return [w for w in (design or {}).get("wires", []) if "rest" in w]


def wire_program(design, wire_name, profile=None):
    """(stream lines, native profile dict, notes) of the named wire: its G-code as Export writes
    it, without comments. ValueError naming the wire when it is absent, has no rest shape or
    cannot be bent with the profile."""
    wire = next((w for w in design["wires"] if w["name"] == wire_name), None)
    if wire is None:
        raise ValueError(f"the design has no wire '{wire_name}'")
    if "rest" not in wire:
        raise ValueError(f"wire {wire_name} has no rest shape: {export.no_rest_reason(design)}")
    machine, notes = export.machine_profile(design, profile)
    material = design["material"].get("name", "")
    try:
        text = native.write_gcode(None, np.asarray(wire["rest"], dtype=np.float64), machine, wire_name, material)
    except ValueError as exc:
        raise ValueError(f"wire {wire_name}: {exc}") from None
    return native.stream_lines(text), machine, notes


class Stopped:
    """A wire whose stream stopped before its end: the program, the profile and the state
    ({"next_line", "confirmed"}) the native stream_program updates in place."""

    def __init__(self, lines, profile, state, port, result):
        self.lines, self.profile, self.state, self.port, self.result = lines, profile, state, port, result

    @property
    def next_line(self):
        return int(self.state.get("next_line", 0))


def quoted(lines, index):
    """'line N (`text`)' with N 1-based, or 'no line' for index < 0."""
    if index < 0:
        return "no line yet"
    return f"line {index + 1} (`{lines[index]}`)"


class StreamJob(WorkerJob):
    """One run of stream_program: started fresh (Send) or from a Stopped state (Resume)."""

    name = "wiresculpt stream"
    expected = (ValueError, RuntimeError, OSError)

    def __init__(self, wire, port, lines, profile, state, dry_run=False, settle=2.0, response_timeout=30.0,
                 resumed=False):
        super().__init__()
        self.wire, self.port, self.lines, self.profile, self.state = wire, port, lines, profile, state
        self.dry_run, self.settle, self.response_timeout, self.resumed = dry_run, settle, response_timeout, resumed
        self.first = int(state.get("next_line", 0))
        self.fraction = self.first / len(lines) if lines else 1.0
        self.control = native.stream_control()  # abort is one-shot: a fresh one per run
        self.result = None
        self.generation = session.generation()  # the file the stream was started from

    def _progress(self, _stage, fraction):
        self.fraction = fraction
        return True

    def work(self):
        self.result = native.stream_program(
            self.port, self.lines, self.profile, self.state, progress=self._progress, control=self.control,
            dry_run=self.dry_run, response_timeout=self.response_timeout, settle=self.settle)

    def cancel(self):
        self.control.abort()

    def line(self):
        """Lines acknowledged so far (of len(lines))."""
        return int(round(self.fraction * len(self.lines)))

    def status(self):
        if self.control.aborted:
            return f"wiresculpt: cancelling the stream of {self.wire}…"
        verb = "checking" if self.dry_run else "sending"
        return (f"wiresculpt: {verb} {self.wire} to {self.port}: line {self.line()} of {len(self.lines)} "
                f"({100 * self.fraction:.0f} %) (Esc to cancel)")


def prepare(design, wire, port, profile=None, resume=False, dry_run=False, settle=2.0, response_timeout=30.0):
    """A StreamJob (not started) for `wire` to `port`. Send (resume=False) starts the program at
    its first line and forgets an earlier stop of that wire; Resume continues the stopped one and
    refuses when there is none or when the program would now be different (another design or
    profile). ValueError with one sentence otherwise."""
    if not port:
        raise ValueError("no serial port chosen: pick one or type its path (e.g. /dev/ttyUSB0)")
    lines, machine, _notes = wire_program(design, wire, profile)
    if not resume:
        return StreamJob(wire, port, lines, machine, {}, dry_run, settle, response_timeout)
    stopped = PENDING.get(wire)
    if stopped is None:
        raise ValueError(f"nothing to resume for wire {wire}: it has no stopped stream (use Send)")
    if stopped.lines != lines or stopped.profile != machine:
        raise ValueError(f"wire {wire}'s program changed since its stream stopped at line {stopped.next_line + 1} "
                         "(another design or machine profile): Send it again from the start")
    return StreamJob(wire, port, stopped.lines, stopped.profile, stopped.state, dry_run, settle, response_timeout,
                     resumed=True)


def finish(job):
    """(report type, one sentence) for a finished job; keeps or drops its wire's stop in PENDING."""
    outcome = _outcome(job)
    if job.generation != session.generation():  # started from a file closed since: not this file's
        PENDING.pop(job.wire, None)
        return outcome
    LAST[job.wire] = outcome
    return outcome


def _outcome(job):
    r, state, n = job.result, job.state, len(job.lines)
    done = int(state.get("next_line", job.first))
    start = f" (resumed at line {job.first + 1})" if job.resumed and job.first else ""
    if job.error is not None and r is None:
        if job.dry_run:
            return {'ERROR'}, f"Wire {job.wire}: the dry run failed: {job.error}"
        keep = done > 0 or job.resumed
        if keep:
            PENDING[job.wire] = Stopped(job.lines, job.profile, state, job.port, None)
        else:
            PENDING.pop(job.wire, None)
        tail = f"; Resume continues from line {done + 1}" if keep else ""
        return {'ERROR'}, f"Cannot send wire {job.wire} to {job.port}: {job.error}{tail}"
    if r["status"] == "dry_run":
        return {'INFO'}, f"Wire {job.wire}: {r['message']}"
    if r["status"] == "completed":
        PENDING.pop(job.wire, None)
        return {'INFO'}, (f"Wire {job.wire}: all {n} lines acknowledged by {job.port}{start}; "
                          f"{r['acknowledged']} sent in this run")
    PENDING[job.wire] = Stopped(job.lines, job.profile, state, job.port, r)
    last = quoted(job.lines, r["last_acknowledged"])
    what = "cancelled" if r["status"] == "aborted" else f"stopped ({r['status']})"
    if done <= r["last_acknowledged"]:  # acknowledged (queued) moves may be lost: the step again
        resume = f"Resume restarts the step in doubt from line {done + 1} of {n} (check the wire first)"
    else:
        resume = f"Resume continues from line {done + 1} of {n}"
    return {'WARNING'} if r["status"] == "aborted" else {'ERROR'}, (
        f"Wire {job.wire} {what} on {job.port}{start}: the last acknowledged line is {last}; "
        f"{resume}. {r['message']}")


def running():
    return JOB is not None


def cancel():
    """Asks the running stream to stop (feed hold and soft reset); False when none runs.
    Thread-safe: the control's switch is atomic."""
    job = JOB
    if job is None:
        return False
    job.cancel()
    return True
