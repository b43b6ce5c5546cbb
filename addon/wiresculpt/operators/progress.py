"""What a modal operator watching a worker thread shows (Optimize, Send to Machine): a timer that
wakes the modal, Blender's progress indicator, a line in the status bar, and the 3D views (the
sidebar's panels) redrawn."""
TIMER_SECONDS = 0.1
JOIN_SECONDS = 0.2  # the longest a cancel waits for the worker in Blender's UI thread
_RUNNING = {}  # kind of job ("optimize") -> running(): whether one runs now


def note_running(kind, running):
    """Makes `running()` (whether a job of `kind` runs now) known to the other operators."""
    _RUNNING[kind] = running


def busy(kind):
    """Whether a job of `kind` runs now (False for a kind no operator noted)."""
    return kind in _RUNNING and bool(_RUNNING[kind]())


class WorkerModal:
    """Mixin for a bpy.types.Operator whose modal() polls a worker thread on TIMER events."""

    _timer = None

    def begin_watch(self, context, steps):
        """Starts the timer and the progress indicator (0 to `steps`) and makes the operator modal."""
        wm = context.window_manager
        self._timer = wm.event_timer_add(TIMER_SECONDS, window=context.window)
        wm.progress_begin(0, steps)
        wm.modal_handler_add(self)

    def show_progress(self, context, done=None, text=None):
        """Progress `done` (of `steps`), `text` in the status bar (None clears it), panels redrawn."""
        if done is not None:
            context.window_manager.progress_update(done)
        if context.workspace is not None:
            context.workspace.status_text_set(text)
        for area in (context.screen.areas if context.screen else []):
            if area.type == 'VIEW_3D':
                area.tag_redraw()

    def watch_event(self, context, event, thread, cancel):
        """The common part of modal(): Esc calls `cancel()`, timer ticks refresh the progress (the
        operator's `_show`) while `thread` runs. The modal's answer, or None once the worker has
        ended (the caller finishes)."""
        if event.type == 'ESC' and event.value == 'PRESS':
            cancel()
            self._show(context)
            return {'RUNNING_MODAL'}
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}
        if thread.is_alive():
            self._show(context)
            return {'PASS_THROUGH'}
        return None

    def end_watch(self, context):
        wm = context.window_manager
        if self._timer is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
        wm.progress_end()
        self.show_progress(context)
