"""Work on a worker thread (Optimize, Send to Machine): the thread, and the error it ended with as
one sentence, never an exception raised into Blender's UI thread."""
import threading


class WorkerJob:
    """Subclasses give `work()` (run on the thread), `name` (the thread's) and `expected` (the
    exceptions whose message is the user's sentence; anything else is reported as our bug)."""

    name = "wiresculpt worker"
    expected = (ValueError, RuntimeError)

    def __init__(self):
        self.error = None
        self.unexpected = False  # `error` is our bug's, not the user's sentence
        self.thread = threading.Thread(target=self.run, name=self.name, daemon=True)

    def work(self):
        raise NotImplementedError

    def run(self):
        """Does the work here and now (the thread runs this; background mode calls it directly)."""
        try:
            self.work()
        except self.expected as exc:
            self.error = str(exc)
        except Exception as exc:  # a bug of ours: reported, never raised into Blender's UI thread
            self.unexpected = True
            self.error = f"internal error ({type(exc).__name__}: {exc}); please report it"
