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

WORKERS = 2  # at most; each full solve also runs its target shape on two threads


def workers(most=None):
    """How many pieces of work to run at once: `most` (default WORKERS), but one when the machine
    has no core to spare (the 1-minute load average leaves less than one of its cores idle). The
    answers do not depend on it (InOrder takes them in order); only the time does. Measured on the
    hinged globe (docs/performance.md, plane assistant): at load 10 on 2 cores, two solves at once
    took 1.6x the time of one (their threads only queue behind the others', and the solves one
    thread would not have run are extra work)."""
    most = WORKERS if most is None else most
    try:
        idle = (os.cpu_count() or 1) - os.getloadavg()[0]
    except (AttributeError, OSError):  # no load average on this system
        return most
    return most if idle >= 1.0 else 1


class InOrder:
    """`submit(tag, fn, *args)` runs fn(*args) on a worker; `take(tag, result)` (given to the
    constructor) is called on the submitting thread with each result in submission order. At most
    `workers` pieces of work are in flight: submit waits for (and takes) the oldest beyond that.
    An exception raised by a piece of work is raised from submit/drain when its turn comes; the
    work still in flight is then waited for (it should watch the same cancel as the caller).
    Use as a context manager: leaving it drains what is left unless an exception is on its way."""

    def __init__(self, take, workers=WORKERS, name="wiresculpt-search"):
        self.take = take
        self.workers = max(1, int(workers))
        self.pending = collections.deque()
        self.pool = ThreadPoolExecutor(max_workers=self.workers, thread_name_prefix=name)

    def submit(self, tag, fn, *args):
        self.pending.append((tag, self.pool.submit(fn, *args)))
        while len(self.pending) >= self.workers + 1 or (self.workers == 1 and self.pending):
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
            self.pool.shutdown(wait=True)
        return False
