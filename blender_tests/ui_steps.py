"""Shared by the ui_*.py scripts the modal tests run in a Blender with a window: timer steps that
print what they saw as one line `MODAL {json}` and quit, and never hang the test."""
import json

import bpy


def report(seen, **extra):
    """Prints `MODAL {json}` of `seen` (and `extra`) and quits Blender."""
    print("MODAL " + json.dumps({**extra, **seen} if extra else seen), flush=True)
    bpy.ops.wm.quit_blender()


def guarded(seen, step):
    """A timer callback that reports an exception and quits instead of hanging the test."""
    def run():
        try:
            return step()
        except Exception as exc:
            report(seen, error=f"{type(exc).__name__}: {exc}")
            return None
    return run


def start_watchdog(seen, seconds=60.0):
    """Reports "timed out" (with what was seen) and quits after `seconds`."""
    def watchdog():
        report(seen, error="timed out")
    bpy.app.timers.register(watchdog, first_interval=seconds)
