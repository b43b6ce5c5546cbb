"""Driven by test_live.py in a Blender with a window (under Xvfb): the globe with Live on; the
window switches to a new scene (Live off there: the timer stops) and back (Live on there: the timer
starts again, although a scene shown again fires no depsgraph update: a msgbus subscription to the
window's scene; without it the timer stayed off there, checked when it was added). Prints one line `MODAL {json}` with what it saw, then quits."""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [os.path.join(os.path.dirname(HERE), "addon"), HERE]

import bpy  # noqa: E402

import wiresculpt  # noqa: E402

wiresculpt.register()
from wiresculpt.live import engine as live  # noqa: E402
from ui_steps import globe_scene as setup, guarded, report, start_watchdog  # noqa: E402

seen = {}
WAIT = 2.0  # seconds for the window's event loop to show a switched scene


def window():
    return bpy.context.window_manager.windows[0]


def turn_on():
    bpy.context.scene.wiresculpt.live = True
    seen["on"] = bpy.app.timers.is_registered(live.tick)
    bpy.app.timers.register(guarded(seen, to_other), first_interval=WAIT)


def to_other():
    seen["first"] = window().scene.name
    window().scene = bpy.data.scenes.new("Other")
    bpy.app.timers.register(guarded(seen, back), first_interval=WAIT)


def back():
    seen["other_timer"] = bpy.app.timers.is_registered(live.tick)
    seen["other_line"] = live.line()
    window().scene = bpy.data.scenes[seen["first"]]
    bpy.app.timers.register(guarded(seen, look), first_interval=WAIT)


def look():
    seen["back_timer"] = bpy.app.timers.is_registered(live.tick)
    seen["back_line"] = live.line()
    report(seen)


setup()
bpy.app.timers.register(guarded(seen, turn_on), first_interval=1.0)
start_watchdog(seen, 120.0)
