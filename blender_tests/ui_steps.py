"""Shared by the ui_*.py scripts the modal tests run in a Blender with a window: timer steps that
print what they saw as one line `MODAL {json}` and quit, and never hang the test."""
import json
import time

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


class Held:
    """`module.name` made to wait, polling its `cancel` keyword (or its `context` keyword's, a
    SolveContext), up to `seconds` before it runs, so that a test's cancel or next move surely lands
    while the work is under way however fast the work has become. restore() puts the original back."""

    def __init__(self, module, name, seconds):
        self.module, self.name, self.original = module, name, getattr(module, name)

        def held(*args, **kwargs):
            cancel = kwargs.get("cancel")
            if cancel is None and kwargs.get("context") is not None:
                cancel = kwargs["context"].cancelled
            until = time.monotonic() + seconds
            while cancel is not None and not cancel() and time.monotonic() < until:
                time.sleep(0.01)
            return self.original(*args, **kwargs)
        setattr(module, name, held)

    def restore(self):
        setattr(self.module, self.name, self.original)


def start_watchdog(seen, seconds=60.0):
    """Reports "timed out" (with what was seen) and quits after `seconds`."""
    def watchdog():
        report(seen, error="timed out")
    bpy.app.timers.register(watchdog, first_interval=seconds)


def globe_scene():
    """The bundled globe scaled by 1/8, cut by three slicing planes
    through its centre (XY, YZ, XZ) and sliced: the scene the modal scripts start from."""
    import math
    import os

    from wiresculpt.blend.mesh import import_mesh

    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    _V, _F, objs = import_mesh(os.path.join(root, "scripts", "examples", "globe", "globe.obj"))
    objs[0].scale = (0.125,) * 3
    bpy.context.view_layer.update()
    bpy.context.scene.wiresculpt.model = objs[0]
    for rotation in ((0, 0, 0), (0, math.pi / 2, 0), (math.pi / 2, 0, 0)):
        bpy.ops.wiresculpt.add_plane()
        bpy.context.view_layer.objects.active.rotation_euler = rotation
    bpy.context.view_layer.update()
    bpy.ops.wiresculpt.slice()
