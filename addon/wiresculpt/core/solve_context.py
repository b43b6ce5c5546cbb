"""The context of one solve: how it reports, when it stops, and what its stages share.

pipeline.solve builds one SolveContext and hands it to the stages' callers (pipeline.relayer,
shape_and_rest, hooks_by_forces); the plane search holds one for the whole run (its progress,
cancel and the run's one deadline, settings.max_solve_seconds), and each of its full solves gets a
for_solve view of it.
Instead of closures passed by position, a stage's caller reads

    context.say(stage, message)        a progress line (and the stage under way, for OutOfTime)
    context.native_progress            the callback the native stages take: (stage, fraction) -> bool,
                                       False when cancelled or past the deadline
    context.checkpoint()               raises Cancelled or OutOfTime at a safe point
    context.quiet()                    the same context, saying nothing (hook patterns after the first)
    context.for_solve(cancel)          a fresh context for one solve inside a longer run (the plane
                                       search's): its own memos, the run's clock and deadline

and the solve's shared memos: `same_solves` (target-shape solves by exact input, for every
re-layering round: target_shape.Memo's `same`) and `contour_cache` (core.polylines.ContourArrays).
bpy-free."""
import copy
import math
import time

from .polylines import ContourArrays


class Cancelled(Exception):
    """The user cancelled; the caller keeps its previous state."""


class OutOfTime(RuntimeError):
    """The solve ran past settings.max_solve_seconds; the caller keeps its previous state."""

    def __init__(self, budget, stage):
        super().__init__(f"the solve stopped at its time budget, settings.max_solve_seconds = {budget:g} s, during "
                         f"the {stage.replace('_', ' ')}: raise the budget, or give fewer planes or a smaller "
                         f"max_nodes")
        self.budget, self.stage = budget, stage


def quiet(stage, message):
    """A progress callback that says nothing."""


# The native solver's parts of the layering are reported as the layering.
_LAYERING_PARTS = ("network", "check_assembly")


class SolveContext:
    """Progress, cancel and deadline of one solve, and its shared memos.

    `progress(stage, message)`: called by say (None: nothing is said); `cancel()`: True stops the
    solve at its next safe point (None: never); `budget`: seconds of wall clock from now after
    which the solve is out of time (math.inf: never); `clock()`: the seconds it reads the time
    in (None: time.monotonic; a test's may run fast), for the deadline and for every wall-clock
    bound of whoever holds the context (the plane search's guard)."""

    def __init__(self, progress=None, cancel=None, budget=math.inf, clock=None):
        self.progress = progress or quiet
        self.cancelled = cancel or (lambda: False)
        self.budget = budget
        self.clock = clock or time.monotonic
        self.deadline = self.clock() + budget
        self._at = {"stage": "layering"}  # the stage under way, shared with quiet() views
        self._speaks = True
        self.same_solves = {}
        self.contour_cache = ContourArrays()

    @property
    def stage(self):
        """The stage under way (for OutOfTime's message)."""
        return self._at["stage"]

    def say(self, stage, message):
        """Reports `message` of `stage`, which becomes the stage under way (nothing in a quiet view)."""
        if self._speaks:
            self._at["stage"] = stage
            self.progress(stage, message)

    def quiet(self):
        """This context, saying nothing: the same cancel, deadline, stage and memos."""
        view = copy.copy(self)
        view._speaks = False
        return view

    def for_solve(self, cancel=None):
        """A fresh context for one solve inside the run this context times (the plane search's
        full solves): its own stage and memos, this context's progress (nothing from a quiet
        view), clock, budget and deadline (the run's one budget, not a fresh one per solve),
        cancelled when this one is or when `cancel()` (None: only then)."""
        mine = self.cancelled
        view = SolveContext(self.progress if self._speaks else None,
                            mine if cancel is None else (lambda: mine() or cancel()), clock=self.clock)
        view.budget, view.deadline = self.budget, self.deadline
        return view

    def out_of_time(self):
        return self.clock() > self.deadline

    def native_progress(self, stage, _fraction):
        """The native stages' callback: notes the stage, False to stop (cancelled or out of time)."""
        if isinstance(stage, str) and stage:
            self._at["stage"] = "layering" if stage in _LAYERING_PARTS else stage
        return not (self.cancelled() or self.out_of_time())

    def checkpoint(self):
        """Raises Cancelled when cancelled, OutOfTime when past the deadline."""
        if self.cancelled():
            raise Cancelled()
        if self.out_of_time():
            raise OutOfTime(self.budget, self.stage)

    def stopped(self):
        """The exception for a native stage that the callback stopped: OutOfTime when the
        deadline, not a cancel, stopped it, else Cancelled."""
        if not self.cancelled() and self.out_of_time():
            return OutOfTime(self.budget, self.stage)
        return Cancelled()
