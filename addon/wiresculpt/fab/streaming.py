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
from ..core import machine_words as words
from ..core import session, sizes
from ..core.jobs import WorkerJob
from . import export

PENDING = {}  # wire name -> Stopped: the program a Resume continues
JOB = None  # the StreamJob while a wire is being sent, else None
LAST = {}  # wire name -> (report type, sentence) of its last run, for the panel
LOAD = None  # the Load waiting for the user to load its wire and press Continue, else None
# PENDING and LAST are the open file's: another file's wires may have the same names.
# forget() empties them when a file is loaded (blend/ownership's load handlers), and a stream that
# ends after a load records nothing (its generation is the closed file's).


def forget():
    """No stop to resume, no last run, no wire waiting to be loaded (a file is being loaded); a
    running stream goes on."""
    global LOAD
    PENDING.clear()
    LAST.clear()
    LOAD = None


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


def wire_steps(design, wire_name, machine):
    """The bend program's steps ({"feed_mm", "bend_deg", …}) and wire length (m) of a wire of
    wire_program: what its G-code's steps feed and bend, in order."""
    wire = next(w for w in design["wires"] if w["name"] == wire_name)
    program = native.make_bend_program(np.asarray(wire["rest"], dtype=np.float64), machine)
    return program["steps"], float(program["wire_length"])


def is_dwell(line):
    """A program line with a G4 word: the end of a bend step (the G-code writer closes each with one)."""
    return "G4" in line.upper().split()


def step_bounds(lines):
    """[(first, last)] 0-based lines of each bend step: step k (1-based) is bounds[k-1], ending with
    its G4; the lines after the last G4 (the pin back, M2) are the program's end, step len+1."""
    bounds, first = [], 0
    for i, line in enumerate(lines):
        if is_dwell(line):
            bounds.append((first, i))
            first = i + 1
    return bounds


def step_of(bounds, index):
    """The step (1-based) line `index` (0-based) belongs to; len(bounds) + 1 past the last step."""
    return 1 + sum(1 for _first, last in bounds if last < index)


class Stopped:
    """A wire whose stream stopped before its end: the program, the profile and the state
    ({"next_line", "confirmed"}) the native stream_program updates in place; `facts` the stop as
    codes and figures (stop_facts), which the panel's box says."""

    def __init__(self, lines, profile, state, port, result, facts=None):
        self.lines, self.profile, self.state, self.port, self.result = lines, profile, state, port, result
        self.facts = facts

    @property
    def next_line(self):
        return int(self.state.get("next_line", 0))


class StreamJob(WorkerJob):
    """One run of stream_program: started fresh (Send) or from a Stopped state (Resume)."""

    name = "wiresculpt stream"
    expected = (ValueError, RuntimeError, OSError)

    def __init__(self, wire, port, lines, profile, state, dry_run=False, settle=2.0, response_timeout=30.0,
                 resumed=False, steps=(), link=None):
        super().__init__()
        self.wire, self.port, self.lines, self.profile, self.state = wire, port, lines, profile, state
        self.steps = list(steps)  # the bend program's steps, for the stop's words
        self.link = link  # the Machine panel's open SerialLink on `port`, streamed on instead of reopening
        self.queue = []  # the wires Send All sends after this one (each after its own "load the wire")
        self.queue_count = 1  # how many wires that Send All sends in all
        self.after = None  # what to do when it completes (the test bends fill the calibration rows)
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
            self.link if self.link is not None else self.port, self.lines, self.profile, self.state, progress=self._progress, control=self.control,
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


TIMING = (2.0, 30.0)  # s: the settle after opening the port, and the longest wait for an answer


def prepare(design, wire, port, profile=None, resume=False, dry_run=False, timing=TIMING, link=None):
    """A StreamJob (not started) for `wire` to `port` (on `link`, the Machine panel's open link to
    it, when given); `timing` is (settle, response_timeout) in seconds. Send (resume=False) starts the program at its first line and forgets an
    earlier stop of that wire; Resume continues the stopped one and refuses when there is none or
    when the program would now be different (another design or profile). ValueError with one
    sentence otherwise."""
    if not port:
        raise ValueError("no serial port chosen: pick one or type its path (e.g. /dev/ttyUSB0)")
    lines, machine, _notes = wire_program(design, wire, profile)
    steps, _length = wire_steps(design, wire, machine)
    settle, response_timeout = timing
    if not resume:
        return StreamJob(wire, port, lines, machine, {}, dry_run, settle, response_timeout, steps=steps, link=link)
    stopped = PENDING.get(wire)
    if stopped is None:
        raise ValueError(f"nothing to resume for wire {wire}: it has no stopped stream (use Send)")
    if stopped.lines != lines or stopped.profile != machine:
        raise ValueError(f"wire {wire}'s program changed since its stream stopped at line {stopped.next_line + 1} "
                         "(another design or machine profile): Send it again from the start")
    return StreamJob(wire, port, stopped.lines, stopped.profile, stopped.state, dry_run, settle, response_timeout,
                     resumed=True, steps=steps, link=link)


def prepare_program(name, lines, machine, port, steps=(), timing=TIMING, link=None, resume=False):
    """A StreamJob for a program that is no wire of the design (the test bends); Resume continues
    its stop as prepare's does; `timing` as prepare's."""
    if not port:
        raise ValueError("no serial port chosen: pick one or type its path (e.g. /dev/ttyUSB0)")
    settle, response_timeout = timing
    if not resume:
        return StreamJob(name, port, lines, machine, {}, False, settle, response_timeout, steps=steps, link=link)
    stopped = PENDING.get(name)
    if stopped is None or stopped.lines != lines or stopped.profile != machine:
        raise ValueError(f"nothing to resume for {name}: send it again from the start")
    return StreamJob(name, port, lines, machine, stopped.state, False, settle, response_timeout, resumed=True,
                     steps=steps, link=link)


# --- loading the wire ---------------------------------------------------------------------------

class Load:
    """A wire to load before its stream starts: `facts` for the panel's words (load_lines), the
    wire, and the wires Send All sends after it."""

    def __init__(self, wire, facts, queue=(), kind="wire"):
        self.wire, self.facts, self.queue, self.kind = wire, facts, list(queue), kind


def load_facts(design, wire, profile=None, index=1, count=1):
    """What the "load the wire" step says: the wire, its length as the machine feeds it (the bend
    program's, as the G-code's header), the material, and the profile's stock."""
    lines, machine, _notes = wire_program(design, wire, profile)
    _steps, length = wire_steps(design, wire, machine)
    stock, stock_name = sizes.stock(profile)
    material = design.get("material", {})
    return {"wire": wire, "length_mm": 1000.0 * length, "stock_mm": 1000.0 * stock, "stock_name": stock_name,
            "material": material.get("name") or "wire", "diameter_mm": 1000.0 * float(material.get("wire_diameter", 0.0)),
            "index": index, "count": count, "lines": len(lines)}


def ask_load(design, wires, profile=None):
    """Sets LOAD to the first of `wires` (the others follow it); its Load."""
    global LOAD
    if not wires:
        raise ValueError("no wire to send (optimize until the wires have rest shapes)")
    LOAD = Load(wires[0], load_facts(design, wires[0], profile, 1, len(wires)), wires[1:])
    return LOAD


def next_load(design, job, profile=None):
    """After a stream that completed: LOAD for the next wire of its Send All queue (None: none)."""
    global LOAD
    if not job.queue:
        return None
    count = job.queue_count
    index = count - len(job.queue) + 1
    LOAD = Load(job.queue[0], load_facts(design, job.queue[0], profile, index, count), job.queue[1:])
    return LOAD


def clear_load():
    global LOAD
    LOAD = None


# --- the words of a run's end -------------------------------------------------------------------

def stop_facts(job, port=None):
    """A stopped stream as codes and figures (core/machine_words.stop_lines says them)."""
    r, state, lines = job.result or {}, job.state, job.lines
    bounds = step_bounds(lines)
    nxt = int(state.get("next_line", job.first))
    confirmed = int(state.get("confirmed", nxt))
    step = step_of(bounds, nxt)
    in_doubt = r.get("last_acknowledged", -1) >= nxt
    last = bounds[step - 1][1] if step <= len(bounds) else len(lines) - 1
    program_step = job.steps[step - 1] if 0 < step <= len(job.steps) else {}
    failed = r.get("failed_line", -1)
    return {"wire": job.wire, "port": port or job.port, "status": r.get("status", "unopened"), "code": r.get("code", 0),
            "failed_line": failed + 1 if failed is not None and failed >= 0 else None,
            "resume_line": nxt + 1, "resume_step": step, "steps": len(bounds),
            "done_steps": sum(1 for _f, b in bounds if b < confirmed), "in_doubt": in_doubt,
            "step_lines": (nxt + 1, last + 1), "feed_mm": program_step.get("feed_mm"),
            "bend_deg": program_step.get("bend_deg"), "total_lines": len(lines), "why": job.error or "",
            "test": job.after is not None}


def stop_text(facts):
    """The stop's box as one report (the lines joined)."""
    return " ".join(words.stop_lines(facts))


def finish(job):
    """(report type, one sentence) for a finished job; keeps or drops its wire's stop in PENDING."""
    outcome = _outcome(job)
    if job.generation != session.generation():  # started from a file closed since: not this file's
        PENDING.pop(job.wire, None)
        return outcome
    LAST[job.wire] = outcome
    return outcome


def _outcome(job):
    r, state = job.result, job.state
    done = int(state.get("next_line", job.first))
    finished = {"wire": job.wire, "port": job.port, "steps": len(step_bounds(job.lines)),
                "total_lines": len(job.lines), "resumed": job.resumed and job.first > 0, "first_line": job.first + 1,
                "test": job.after is not None}
    if job.error is not None and r is None:
        if job.dry_run:
            return {'ERROR'}, f"Wire {job.wire}: the dry run failed: {job.error}"
        keep = done > 0 or job.resumed
        if keep:
            facts = stop_facts(job)
            PENDING[job.wire] = Stopped(job.lines, job.profile, state, job.port, None, facts)
            return {'ERROR'}, " ".join(words.not_started_lines(dict(finished, why=job.error)) +
                                       [words.resume_button(facts) + " when it is back."])
        PENDING.pop(job.wire, None)
        return {'ERROR'}, " ".join(words.not_started_lines(dict(finished, why=job.error)))
    if r["status"] == "dry_run":
        return {'INFO'}, " ".join(words.finished_lines(dict(finished, status="dry_run")))
    if r["status"] == "completed":
        PENDING.pop(job.wire, None)
        return {'INFO'}, " ".join(words.finished_lines(dict(finished, status="completed")))
    facts = stop_facts(job)
    PENDING[job.wire] = Stopped(job.lines, job.profile, state, job.port, r, facts)
    return {'WARNING'} if r["status"] == "aborted" else {'ERROR'}, stop_text(facts)


def hold(job):
    """Feed hold of a running stream: no line is sent after the current one's answer (the streamer
    then sends `!` itself), and on the panel's open link `!` goes at once, so the machine stops
    inside a step too (GRBL acts on a realtime byte wherever it arrives)."""
    job.control.pause()
    if job.link is not None:
        job.link.write(b"!", 1.0)


def go_on(job):
    """Resume of a held stream: `~` (at once on the panel's link; the streamer also sends it if it
    had entered its own hold) and the lines go on."""
    job.control.resume()
    if job.link is not None:
        job.link.write(b"~", 1.0)


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
