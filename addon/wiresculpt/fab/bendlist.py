"""The bend list a DIWire-class machine runs through FabMo's Bend List app:

    UNIT MM
    FEED 50.000
    BEND 92.222
    FEED 50.000
    BEND -92.222
    FEED 50.000

Source: github.com/FabMo/fabmo-bendlist-app (README.md, js/bend.js): one command a line, `UNIT
INCH|MM`, `FEED length`, `BEND degrees` (the bend head's angle: a positive and a negative bend
are on the two sides of the wire), `REPEAT n:` ... `END`. Its compiler ducks the bend pin under
the wire (G0 Z180), moves the head to the other side's clearance and unducks it (G0 Z0) at every
change of bend side, so the list carries no pin command: the sign of BEND is the side. It applies
no spring-back compensation: the BEND angles written here are the profile's commanded angles
(what the head must turn to leave the target bend after spring-back). Its parser matches words
anywhere in a line and reads any line containing "end" as END, and comments do not work (its
README says so): the list holds nothing but commands, numbers without exponent or "+".

bpy-free; the bend program comes from the native module (make_bend_program).
"""
import os


def _number(value, places):
    text = f"{value:.{places}f}"
    return "0" if float(text) == 0 else text  # never "-0.000"


def bend_list(program, left_is_positive=True):
    """The bend list text of a bend program (native make_bend_program's result): per step FEED
    its length in mm, then BEND its commanded angle (degrees, the sign of the head's move: left
    bends positive when `left_is_positive`) unless the step does not bend."""
    side = 1.0 if left_is_positive else -1.0
    lines = ["UNIT MM"]
    for step in program["steps"]:
        lines.append(f"FEED {_number(step['feed_mm'], 3)}")
        if step.get("vertex", -1) >= 0 and step["bend_deg"] != 0:
            lines.append(f"BEND {_number(side * step['commanded_deg'], 3)}")
    return "\n".join(lines) + "\n"


def write_bend_list(path, program, left_is_positive=True):
    """Writes bend_list(...) to `path` atomically; returns the text."""
    text = bend_list(program, left_is_positive)
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="ascii", newline="\n") as f:
        f.write(text)
    os.replace(tmp, path)
    return text
