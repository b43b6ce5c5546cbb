"""The words of the machine: a stream's stop as a box of short lines, the "load the wire" step,
the status line, a console line's answer, why a line was not sent (bpy-free, made only here).

Everything arrives as codes and figures: a stop is a dict (fab/streaming.stop_facts) with
"status" (the native stream status: completed, error, alarm, disconnected, timeout, aborted,
protocol_error), "code" (N of error:N / ALARM:N), the 1-based "line" and "step" numbers; an
answer is a code of fab/grbl (ok, error, alarm, reset, lost, no_answer). Steps and lines are
numbered one way everywhere: step k is the k-th bend step of the program (its lines end with the
step's G4 P0), lines are the streamed lines counted from 1, and "line L" of a stop is always the
line a resume starts at.
"""

# GRBL 1.1's error codes a bender meets (the rest are said by number)
GRBL_ERRORS = {
    1: "a word without its letter", 2: "a number it cannot read", 3: "a $ command it does not know",
    8: "a $ command while not idle", 9: "G-code locked out (alarm or jog)", 10: "soft limits need homing",
    15: "a jog beyond the machine's travel", 16: "a jog line it cannot read", 20: "an unsupported G-code",
    22: "a move without a feed rate", 33: "a move it cannot plan",
}
GRBL_ALARMS = {
    1: "a hard limit switch was hit", 2: "a move beyond the soft limits", 3: "reset while moving (position lost)",
    4: "the probe was not clear", 6: "homing was reset", 7: "the safety door opened while homing",
    8: "homing could not pull off the switch", 9: "homing found no switch",
}
STATES = {"Idle": "idle", "Run": "running", "Hold": "feed hold", "Jog": "jogging", "Alarm": "alarm, locked",
          "Door": "safety door open", "Check": "check mode", "Home": "homing", "Sleep": "asleep"}


def grbl_error(code):
    what = GRBL_ERRORS.get(code)
    return f"error:{code}" + (f" ({what})" if what else "")


def grbl_alarm(code):
    what = GRBL_ALARMS.get(code)
    return f"ALARM:{code}" + (f" ({what})" if what else "")


# --- a stream's stop ---------------------------------------------------------------------------

def _lines(a, b):
    return f"line {a}" if a == b else f"lines {a}-{b}"


def _moves(facts):
    parts = []
    if facts.get("feed_mm"):
        parts.append(f"feed {facts['feed_mm']:.1f} mm")
    if facts.get("bend_deg"):
        parts.append(f"bend {facts['bend_deg']:+.1f}°")
    return ", ".join(parts)


def stop_cause(facts):
    """The first line of a stop's box: what happened, on which port."""
    status, line, port = facts["status"], facts["failed_line"], facts["port"]
    if status == "disconnected":
        return f"The link to {port} dropped (or GRBL restarted)."
    if status == "timeout":
        return f"GRBL on {port} did not answer line {line} in time."
    if status == "error":
        return f"GRBL refused line {line} with {grbl_error(facts['code'])}."
    if status == "alarm":
        return f"GRBL raised {grbl_alarm(facts['code'])}."
    if status == "aborted":
        return "Cancelled: feed hold and soft reset sent."
    if status == "unopened":
        return f"The stream did not start: {facts['why']}"
    if status == "protocol_error":
        return f"GRBL on {port} sent more answers than lines."
    return f"The stream stopped ({status})."


def _what(facts):
    return "The test piece" if facts.get("test") else f"Wire {facts['wire']}"


def stop_lines(facts):
    """A stopped stream as short lines, first the cause, last what the Resume button does. Every
    number is a step (of the program's bend steps) or a line (1-based) as the box says it."""
    out = [f"{_what(facts)} stopped.", stop_cause(facts)]
    done = facts["done_steps"]
    steps = facts["steps"]
    out.append(f"Done: steps 1-{done} of {steps}." if done else f"Done: no step of {steps}.")
    step, resume_line = facts["resume_step"], facts["resume_line"]
    if facts["in_doubt"]:
        a, b = facts["step_lines"]
        moves = _moves(facts)
        out.append(f"Step {step} ({_lines(a, b)}{': ' + moves if moves else ''}) may be half made:")
        out.append("check the wire before resuming.")
    elif facts["status"] == "error":
        out.append(f"Line {resume_line} was not run: fix it, then resume.")
    if facts["status"] == "alarm" or facts.get("code") == 9:
        out.append("Unlock ($X) or home ($H) in the Machine panel first.")
    if step > steps:
        out.append(f"Resume sends the program's last lines from line {resume_line}.")
    else:
        out.append(f"Resume restarts step {step} at line {resume_line}." if facts["in_doubt"]
                   else f"Resume continues step {step} at line {resume_line}.")
    return out


def resume_button(facts):
    """The Resume button's text: the step it starts from (the box above names the line)."""
    if facts["resume_step"] > facts["steps"]:
        return f"Resume at Line {facts['resume_line']}"
    return f"Resume from Step {facts['resume_step']}"


def finished_lines(facts):
    """A stream that ran to its end, or a dry run."""
    if facts["status"] == "dry_run":
        return [f"{_what(facts)}: the program checks out ({facts['total_lines']} lines, "
                f"{facts['steps']} steps); nothing was sent."]
    start = f", resumed at line {facts['first_line']}" if facts.get("resumed") else ""
    return [f"{_what(facts)} done: all {facts['steps']} steps ({facts['total_lines']} lines) "
            f"acknowledged by {facts['port']}{start}."]


def not_started_lines(facts):
    """A stream that failed before GRBL answered anything of it (the port, the program)."""
    what = "the test piece" if facts.get("test") else f"wire {facts['wire']}"
    return [f"Cannot send {what} to {facts['port']}:", facts["why"]]


# --- loading a wire ------------------------------------------------------------------------------

def load_lines(facts):
    """The "load the wire" step: which wire, how much of which stock."""
    out = [f"Load wire {facts['wire']}" + (f" ({facts['index']} of {facts['count']})" if facts.get("count", 1) > 1
                                           else "") + ":",
           f"{facts['length_mm']:.0f} mm of {facts['diameter_mm']:g} mm {facts['material']},",
           f"from stock of {facts['stock_mm']:.0f} mm ({facts['stock_name']})."]
    if facts["length_mm"] > facts["stock_mm"]:
        out.append(f"The wire is {facts['length_mm'] - facts['stock_mm']:.0f} mm longer than the stock: join two pieces.")
    out.append("Feed its end to the bend head, then Continue.")
    return out


def test_piece_lines(facts):
    """The load step of the test-bend program."""
    angles = ", ".join(f"{a:g}" for a in facts["angles"])
    return ["Load a straight test piece:", f"{facts['length_mm']:.0f} mm of {facts['diameter_mm']:g} mm "
            f"{facts['material']}.", f"It gets {len(facts['angles'])} bends commanded {angles}°.",
            "Then measure each bend and type it in the Calibration rows."]


# --- the status line and the console -------------------------------------------------------------

def status_line(status, feed_mm, bend_deg):
    """`Idle · feed 12.500 mm · bend +30.00°` of a parsed report (None: no report yet)."""
    if status is None:
        return "No status yet"
    state = STATES.get(status["state"], status["state"])
    parts = [state[:1].upper() + state[1:]]
    if feed_mm is not None:
        parts.append(f"feed {feed_mm:.3f} mm")
    if bend_deg is not None:
        parts.append(f"bend {bend_deg:+.2f}°")
    return " · ".join(parts)


ANSWERS = {"ok": "ok", "reset": "GRBL restarted before answering", "lost": "the link dropped",
           "no_answer": "no answer yet"}


def answer_line(answer, code=0, info=()):
    """A console line's answer as GRBL gave it: ok, error:N (what it means), …, its [MSG] lines."""
    if answer is None:
        said = "waiting…"
    elif answer == "error":
        said = grbl_error(code)
    else:
        said = ANSWERS.get(answer, answer)
    return "; ".join(list(info) + [said])


LINE_FAULTS = {"line_empty": "type a line first", "line_too_long": "GRBL takes at most 79 characters a line",
               "line_not_printable": "only printable characters", "line_realtime":
               "!, ~ and ? are GRBL's realtime commands: send them on their own"}


def line_fault(code):
    return LINE_FAULTS.get(code, code)


NOT_CONNECTED = "not_connected"
STREAMING = "streaming"
BUSY = "busy"  # a console line, jog or home still waits for GRBL's answer on the link a stream would use
REFUSALS = {NOT_CONNECTED: "Connect to the machine first (Machine panel)",
            STREAMING: "A wire is being sent: Hold, Resume and Cancel only",
            BUSY: "The Machine panel still waits for GRBL's answer (a jog, Home or a console line): send when "
                  "it has answered"}


def refusal(code):
    return REFUSALS[code]
