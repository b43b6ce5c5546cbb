"""Work on a small pool of threads whose results are taken in the order it was handed in, so that
a search that decides on each result in turn (plane_search.py) decides exactly as it would on one
thread, while the next piece of work already runs.

Sound for the solver's calls because the native module releases the GIL in its slicing,
layering, target-shape and forces calls and GLPK (the LPs of layering and forces) keeps its
environment per thread (Debian 12's libglpk 5.0 is built with _Thread_local:
native/tests/test_lp.cpp "two threads ..."; docs/robustness.md, "GLPK on two threads").
"""
import collections
import os
from concurrent.futures import ThreadPoolExecutor

# One: measured on the hinged globe (docs/performance.md, "Two solves at once"), two full solves
# at once found the same candidates but cost 1.5-1.9x the CPU time (the solves one thread would
# not have started are the expensive ones, and each solve already runs its target shape on two
# threads), so the search took longer at every load this shared machine had (3-10). Set 2 to run
# them two at once (tests do).
WORKERS = 1


def workers(most=None):
    """How many pieces of work to run at once: `most` (default WORKERS), but one when the machine
    has no core to spare (the 1-minute load average leaves less than one of its cores idle). The
    answers do not depend on it (InOrder takes them in order); only the time does."""
    most = WORKERS if most is None else most
    try:
        idle = (os.cpu_count() or 1) - os.getloadavg()[0]
    except (AttributeError, OSError):  # no load average on this system
        return most
    return most if idle >= 1.0 else 1


class InOrder:
    """`submit(tag, fn, *args)` runs fn(*args) on a worker (with one worker: at once, on the caller's
    thread); `take(tag, result)` (given to the constructor) is called on the submitting thread with
    each result in submission order. At most `workers` pieces of work are pending when submit
    returns: it waits for (and takes) the oldest beyond that.
    An exception raised by a piece of work is raised from submit/drain when its turn comes; the
    work still in flight is then waited for (it should watch the same cancel as the caller).
    Use as a context manager: leaving it drains what is left unless an exception is on its way."""

    def __init__(self, take, workers=WORKERS, name="wiresculpt-search"):
        self.take = take
        self.workers = max(1, int(workers))
        self.pending = collections.deque()
        # one worker: the work runs here, on the caller's thread, as a plain loop would run it
        self.pool = ThreadPoolExecutor(max_workers=self.workers, thread_name_prefix=name) if self.workers > 1 else None

    def submit(self, tag, fn, *args):
        if self.pool is None:
            self.take(tag, fn(*args))
            return
        self.pending.append((tag, self.pool.submit(fn, *args)))
        while len(self.pending) >= self.workers + 1:
            self._take_oldest()

    def _take_oldest(self):
        tag, future = self.pending.popleft()
        self.take(tag, future.result())

    def drain(self):
        while self.pending:
            self._take_oldest()

    def __enter__(self):
        return self

    def __exit__(self, kind, _value, _tb):
        try:
            if kind is None:
                self.drain()
        finally:
            for _tag, future in self.pending:
                future.cancel()  # not started yet: never started
            self.pending.clear()
            if self.pool is not None:
                self.pool.shutdown(wait=True)
        return False
