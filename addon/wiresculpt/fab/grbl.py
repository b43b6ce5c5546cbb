"""Talking to a GRBL bender outside a stream (the Machine panel; protocol: docs/machine-protocol.md,
"The Machine panel"): its status report read, jog lines made in the profile's units, a console
line checked, the test-bend program of the spring-back calibration, and a Machine session that
keeps one serial link open and answers every line in GRBL's send-response way.

Free of bpy: the add-on's operators poll a Machine from a timer, the tests from a loop. Causes are
codes (the constants below); core/machine_words makes their sentences.
"""
import math
import time

import numpy as np

from .. import native
from ..core import calibration as cal

# --- the status report (`?`) ---------------------------------------------------------------------

AXES = "XYZABC"  # GRBL's order of the position fields


def parse_status(text):
    """{"state", "substate", "mpos" (tuple of axis units), "wpos"} of one status report line,
    GRBL 1.1 (`<Idle|MPos:0.000,0.000,0.000|FS:0,0>`, WPos with WCO when $10 asks for it) or
    0.9 (`<Idle,MPos:…,WPos:…>`); None when the line is not one. Work position = machine position
    - WCO: the one missing is made from the other when GRBL sent WCO."""
    text = text.strip()
    if len(text) < 3 or text[0] != "<" or text[-1] != ">":
        return None
    body = text[1:-1]
    if "|" in body:
        fields = body.split("|")
    else:  # 0.9: commas between fields and inside them; a field starts with a letter and a colon
        fields, part = [], []
        for piece in body.split(","):
            if part and ":" in piece and piece[:1].isalpha():
                fields.append(",".join(part))
                part = []
            part.append(piece)
        fields.append(",".join(part))
    state, _, sub = fields[0].partition(":")
    out = {"state": state, "substate": int(sub) if sub.isdigit() else None, "mpos": None, "wpos": None}
    wco = None
    for field in fields[1:]:
        key, _, value = field.partition(":")
        try:
            numbers = tuple(float(v) for v in value.split(","))
        except ValueError:
            continue
        if key == "MPos":
            out["mpos"] = numbers
        elif key == "WPos":
            out["wpos"] = numbers
        elif key == "WCO":
            wco = numbers
    if wco is not None:
        if out["mpos"] is None and out["wpos"] is not None:
            out["mpos"] = tuple(w + o for w, o in zip(out["wpos"], wco))
        elif out["wpos"] is None and out["mpos"] is not None:
            out["wpos"] = tuple(m - o for m, o in zip(out["mpos"], wco))
    return out


def axis_value(position, letter):
    """The coordinate of axis `letter` (X, Y, Z…) in a report's position, None when absent."""
    k = AXES.find(letter.upper()) if letter else -1
    if position is None or k < 0 or k >= len(position):
        return None
    return position[k]


def machine_position(status, profile):
    """(feed mm, bend deg) of a parsed report's machine position in the profile's units (the bend
    signed as the program's: left bends positive); None for an axis the report does not give."""
    feed = axis_value(status.get("mpos"), profile["feed_axis"])
    bend = axis_value(status.get("mpos"), profile["bend_axis"])
    sign = 1.0 if profile.get("left_is_positive", True) else -1.0
    return (None if feed is None else feed / profile["feed_units_per_mm"],
            None if bend is None else sign * bend / profile["bend_units_per_deg"])


# --- jogs and console lines ----------------------------------------------------------------------

FEED, BEND = "feed", "bend"  # the axes a jog moves


def jog_line(axis, amount, profile):
    """GRBL's jog line (`$J=G91 G21 X10.0000 F1200.0`) for `amount` mm of feed or degrees of head
    (left positive, as the programs), at the profile's feed or bend speed, in axis units."""
    if axis == FEED:
        letter, units, speed = profile["feed_axis"], profile["feed_units_per_mm"], profile["feed_speed_mm_s"]
        value = amount * units
    elif axis == BEND:
        letter, units, speed = profile["bend_axis"], profile["bend_units_per_deg"], profile["bend_speed_deg_s"]
        value = amount * units * (1.0 if profile.get("left_is_positive", True) else -1.0)
    else:
        raise ValueError(f"a jog moves the feed or the bend axis, not {axis!r}")
    if not math.isfinite(amount) or amount == 0.0:
        raise ValueError("a jog needs a distance other than 0")
    return f"$J=G91 G21 {letter}{value:.4f} F{speed * 60.0 * units:.1f}"


REALTIME = {"?": b"?", "!": b"!", "~": b"~"}  # a console line of one of these is sent as GRBL's realtime byte

# Why a console line is not sent (codes; core/machine_words says them)
LINE_EMPTY = "line_empty"
LINE_TOO_LONG = "line_too_long"          # more than LINE_MAX characters
LINE_NOT_PRINTABLE = "line_not_printable"
LINE_REALTIME = "line_realtime"          # a realtime character inside a longer line
LINE_MAX = 79


def line_fault(line):
    """Why `line` cannot go to GRBL as a line (a code), None when it can (a realtime character on
    its own goes as a realtime byte)."""
    if not line:
        return LINE_EMPTY
    if line in REALTIME:
        return None
    if len(line) > LINE_MAX:
        return LINE_TOO_LONG
    if any(not (0x20 <= ord(c) < 0x7f) for c in line):
        return LINE_NOT_PRINTABLE
    if any(c in line for c in "!~?"):
        return LINE_REALTIME
    return None


# --- the test-bend program (spring-back calibration) --------------------------------------------

TEST_NAME = "Test bends"  # the test piece's name where a wire's would be (stream, load step)
TEST_ANGLES = (15.0, 30.0, 45.0, 60.0, 90.0, 120.0)  # commanded degrees, left bends
TEST_FEED = 0.04  # m of straight wire before each bend and after the last


def test_bend_program(profile=None, angles=TEST_ANGLES, feed=TEST_FEED):
    """(stream lines, native profile, commanded degrees, wire length m) of the test piece: `feed`
    of straight wire, then one left bend per angle, each commanded exactly as given (the profile's
    spring-back line set to measured = commanded, so no compensation), each followed by `feed`.
    Bent, the measured angles of its bends against these commanded ones are the spring-back
    capture. ValueError for an angle the profile's head cannot make."""
    machine = cal.default_profile() if profile is None else dict(profile)
    machine = native.validate_machine_profile(cal.machine_dict(machine))
    machine.update(springback_a=1.0, springback_b_deg=0.0)
    machine["max_bend_deg"] = max(machine["max_bend_deg"], max(angles))
    heading, point, points = 0.0, np.zeros(2), [np.zeros(2)]
    for angle in list(angles) + [None]:
        point = point + feed * np.array([math.cos(heading), math.sin(heading)])
        points.append(point)
        if angle is not None:
            heading += math.radians(angle)
    program = native.make_bend_program(np.array(points), machine)
    text = native.write_gcode(None, np.array(points), machine, TEST_NAME, "")
    return native.stream_lines(text), machine, list(program["commanded_deg"]), float(program["wire_length"])


# --- the Machine session -------------------------------------------------------------------------

# What a line's answer was (codes)
OK = "ok"
ERROR = "error"          # error:N, the line rejected
ALARM = "alarm"          # ALARM:N while it was outstanding
RESET = "reset"          # the controller restarted (its banner) before answering
LOST = "lost"            # the link dropped
NO_ANSWER = "no_answer"  # no answer within the wait

STATUS_EVERY = 0.5  # s between status queries while the panel polls


class Command:
    """One line sent to GRBL and its answer: `answer` one of the codes above (None while it
    waits), `code` the N of error:N / ALARM:N, `info` the other lines GRBL sent meanwhile."""

    def __init__(self, line):
        self.line, self.answer, self.code, self.info = line, None, 0, []

    @property
    def done(self):
        return self.answer is not None


class Machine:
    """One open link to a GRBL: lines go one at a time (the next when the previous is answered),
    realtime bytes at once, a status query every STATUS_EVERY s while polled; `status` is the last
    report parsed, `log` every command in order, `alarm` the code of the last ALARM (0: none),
    `lost` True once the link dropped.

    The link is the native SerialLink (native.open_link); `settle` s after opening (GRBL restarts
    when its port opens) nothing is sent unless its banner came first."""

    def __init__(self, port, profile=None, settle=2.0, link=None):
        self.profile = native.validate_machine_profile(cal.machine_dict(profile or cal.default_profile()))
        self.port = port
        self.link = link if link is not None else native.open_link(port, self.profile)
        self.ready_at = time.monotonic() + settle
        self.status, self.status_at, self.alarm, self.lost = None, None, 0, False
        self.banner = ""
        self.log, self._queue, self._waiting = [], [], None
        self._buffer, self._asked_at = b"", None

    def close(self):
        if self.link is not None and self.link.is_open:
            self.link.close()

    @property
    def ready(self):
        return time.monotonic() >= self.ready_at

    # --- sending ---

    def realtime(self, byte):
        """Sends one realtime byte (b"!" feed hold, b"~" resume, b"?" status, b"\\x18" reset) at once;
        False when the link is lost."""
        if self.lost or not self.link.write(byte, 1.0):
            self.lost = True
            return False
        if byte == b"?":
            self._asked_at = time.monotonic()
        return True

    def send(self, line):
        """Queues a line (a Command, answered by later polls); ValueError with the fault's code as
        its only argument when it is not a line GRBL takes."""
        fault = line_fault(line)
        if fault is not None:
            raise ValueError(fault)
        command = Command(line)
        self.log.append(command)
        if line in REALTIME:
            command.answer = OK if self.realtime(REALTIME[line]) else LOST
            return command
        self._queue.append(command)
        self._next()
        return command

    def _next(self):
        if self._waiting is not None or not self._queue or not self.ready or self.lost:
            return
        command = self._queue.pop(0)
        if not self.link.write(command.line + "\n", 2.0):
            self._end(command, LOST)
            self.lost = True
            return
        self._waiting = command

    def _end(self, command, answer, code=0):
        command.answer, command.code = answer, code

    # --- reading ---

    def poll(self, wait=0.0):
        """Reads what arrived (waiting at most `wait` s for the first bytes), answers the waiting
        line, keeps the last status report, sends the next line and, every STATUS_EVERY s, a
        status query. Returns the lines read."""
        if self.lost:
            return []
        now = time.monotonic()
        if self.ready and (self._asked_at is None or now - self._asked_at >= STATUS_EVERY):
            self.realtime(b"?")
        data = self.link.read(wait)
        if data is None:
            self._lose()
            return []
        self._buffer += data
        lines = []
        while b"\n" in self._buffer:
            raw, self._buffer = self._buffer.split(b"\n", 1)
            text = raw.decode("ascii", errors="replace").strip()
            if text:
                lines.append(text)
                self._take(text)
        self._next()
        return lines

    def _lose(self):
        self.lost = True
        self.close()  # its lock file goes with it: a stream or a new Connect may open the port again
        for command in ([self._waiting] if self._waiting else []) + self._queue:
            self._end(command, LOST)
        self._waiting, self._queue = None, []

    def _take(self, text):
        status = parse_status(text)
        if status is not None:
            self.status, self.status_at = status, time.monotonic()
            return
        waiting = self._waiting
        if text == "ok" and waiting is not None:
            self._end(waiting, OK)
            self._waiting = None
        elif text.startswith("error:") and waiting is not None:
            self._end(waiting, ERROR, _code(text))
            self._waiting = None
        elif text.startswith("ALARM"):
            self.alarm = _code(text)
            if waiting is not None:
                waiting.info.append(text)
        elif text.startswith("Grbl "):
            self.banner, self.ready_at = text, time.monotonic()
            if waiting is not None:
                self._end(waiting, RESET)
                self._waiting = None
        elif waiting is not None:
            waiting.info.append(text)
        elif self.log:
            self.log[-1].info.append(text)

    def wait(self, command, timeout):
        """Polls until `command` is answered or `timeout` s pass (then NO_ANSWER is its answer and
        it is no longer waited for); the command."""
        end = time.monotonic() + timeout
        while not command.done and not self.lost:
            left = end - time.monotonic()
            if left <= 0:
                if self._waiting is command:
                    self._waiting = None
                elif command in self._queue:
                    self._queue.remove(command)
                self._end(command, NO_ANSWER)
                break
            self.poll(min(left, 0.05))
        return command

    def query(self, timeout=1.0):
        """Asks for a status report now and waits for it: the parsed report, None when none came."""
        before = self.status_at
        self.realtime(b"?")
        end = time.monotonic() + timeout
        while time.monotonic() < end and not self.lost:
            self.poll(0.05)
            if self.status_at != before:
                return self.status
        return None

    def busy(self):
        """A line waits for its answer or for its turn."""
        return self._waiting is not None or bool(self._queue)


def _code(text):
    try:
        return int(text.partition(":")[2])
    except ValueError:
        return 0


# --- the open session (the Machine panel's) ------------------------------------------------------

SESSION = None  # the Machine the panel connected, else None; a machine, not a file's: kept across files


def connect(port, profile=None, settle=2.0):
    """Opens the panel's session on `port` (closing an earlier one); the Machine. ValueError
    naming the port when it cannot be opened."""
    global SESSION
    disconnect()
    SESSION = Machine(port, profile, settle)
    return SESSION


def disconnect():
    global SESSION
    if SESSION is not None:
        SESSION.close()
    SESSION = None


BUSY = "busy"  # the session's link has a line waiting for its answer: no stream may start on it


def link_for(port):
    """The session's open link when it is connected to `port` (a stream runs on it), else None;
    ValueError(BUSY) while a line of the session waits for its answer (GRBL's answer would reach
    the stream as an answer to none of its lines)."""
    s = SESSION
    if s is not None and not s.lost and s.port == port and s.link.is_open:
        if s.busy():
            raise ValueError(BUSY)
        return s.link
    return None
