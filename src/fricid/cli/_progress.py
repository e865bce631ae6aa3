"""Progress on stderr for every step that can take more than a couple of seconds.

One display, three modes, chosen per run:

* **terminal** (stderr is a tty): a rich bar with the step's label, the count done, the
  elapsed time and an estimate of the time left; transient, so the results stay clean;
* **piped or CI** (stderr is not a tty): plain lines, one when a step has run for
  :data:`GRACE_S` seconds, then one each time another tenth of the work is done (at most every
  :data:`MIN_GAP_S` seconds) and at least every three :data:`HEARTBEAT_S` (every
  :data:`HEARTBEAT_S` seconds when the total is unknown), each with the elapsed time and, when
  the total is known and the rate of the completed work is (:mod:`fricid.cli._estimate`), an
  estimate of the time left, "about", corrected at every line; a line when a new stage
  starts; and a last ``done`` line. Steps that finish within :data:`GRACE_S` print nothing,
  so quick commands stay quiet in scripts::

      [   2.0 s] simulating: 4/35 (11 %), about 15 s left
      [  17.4 s] simulating: done (35/35)

* **quiet** (``--quiet`` on the command or on ``fricid`` itself): nothing.

Library code never prints: it takes a callback (``progress(label)``, ``on_chunk()``, the
optimisers' ``callback(intermediate_result)``), and the command turns the calls into
:meth:`Tracker.update` / :meth:`Tracker.advance` / :meth:`Tracker.stage`.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Annotated, Any

import typer
from rich.markup import escape
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
)

from ._app import err_console, is_quiet, set_quiet
from ._estimate import Estimator

__all__ = [
    "GRACE_S",
    "HEARTBEAT_S",
    "MIN_GAP_S",
    "QuietOption",
    "Tracker",
    "fit_budget",
    "fit_callback",
    "fit_progress",
    "is_quiet",
    "progress_bar",
    "set_quiet",
    "tracker",
]

#: Seconds a step runs before the first plain (piped) line.
GRACE_S = 2.0
#: Seconds between two plain lines of a step whose total is unknown.
HEARTBEAT_S = 10.0
#: Seconds at least between two plain lines of a step whose total is known.
MIN_GAP_S = 1.0

#: Options by which a population method ends on its own schedule (BAS family: iterations;
#: RWSAVSBAS: outer loops; GA: generations), so that its total is at most its default budget.
SCHEDULE_OPTIONS = ("n_iter", "n_outer", "n_gen")

QuietOption = Annotated[
    bool,
    typer.Option(
        "--quiet",
        "-q",
        help="No progress display on stderr (results, warnings and errors still print).",
    ),
]


def _seconds(s: float) -> str:
    """A short duration: ``8 s``, ``2 min 5 s``, ``1 h 3 min``."""
    s = max(0.0, float(s))
    if s < 60:
        return f"{s:.0f} s" if s >= 10 else f"{s:.1f} s"
    m, sec = divmod(round(s), 60)
    if m < 60:
        return f"{m} min {sec} s"
    h, m = divmod(m, 60)
    return f"{h} h {m} min"


class Tracker:
    """One step's progress: counts (``update``, ``advance``) and a label (``stage``).

    Made by :func:`tracker`; in the terminal mode it drives a rich bar, in the plain mode it
    prints the lines described in the module docstring, in the quiet mode nothing.
    """

    def __init__(
        self,
        label: str,
        total: float | None,
        mode: str,
        bar: Any = None,
        unit: str = "",
        clock: Callable[[], float] = time.perf_counter,
        timed: bool = True,
    ) -> None:
        self.label = self.title = label
        self.unit = unit
        self.total = total
        self.done = 0.0
        self.mode = mode
        self._clock = clock
        #: Whether the count can time what is left: False for steps of unequal cost (a
        #: paper's tables and figures, a trajectory's routes), whose rate is never known.
        self.timed = timed
        self._est = Estimator(total, clock)
        self._bar = bar
        self._task = bar.add_task(escape(label), total=total, left="") if bar is not None else None
        self._start = clock()
        self._last_line = -float("inf")
        self._last_tenth = -1
        self._printed = False
        self._lock = threading.Lock()

    @property
    def elapsed(self) -> float:
        """Seconds since the step started."""
        return self._clock() - self._start

    def estimate(self) -> float | None:
        """Seconds left, from the rate of the completed work (:class:`Estimator`); None until
        that rate is known, when the total is unknown, and for steps of unequal cost."""
        return self._est.remaining() if self.timed else None

    def _left(self) -> str:
        left = self.estimate()
        return f"about {_seconds(left)} left" if left else ""

    def line(self) -> str:
        """The plain line for the state now (without the time stamp)."""
        unit = f" {self.unit}" if self.unit else ""
        if self.total:
            count = (
                f"{self.done:,.0f}/{self.total:,.0f}{unit} ({100 * self.done / self.total:.0f} %)"
            )
            left = self._left() if self.done < self.total else ""
            return f"{self.label}: {count}" + (f", {left}" if left else "")
        if self.done:
            return f"{self.label}: {self.done:,.0f}{unit} so far"
        return f"{self.label}: still running" if self._printed else self.label

    def _emit(self, text: str) -> None:
        err_console.print(f"[{self.elapsed:7.1f} s] {escape(text)}", highlight=False, markup=True)
        self._printed = True
        self._last_line = self.elapsed

    def _maybe_print(self, *, force: bool = False) -> None:
        if self.mode != "plain":
            return
        with self._lock:
            t = self.elapsed
            if t < GRACE_S and not force:
                return
            if self.total and self.done >= self.total and not force:
                return  # the last line says "done"
            tenth = int(10 * self.done / self.total) if self.total else -1
            if force or not self._printed:
                due = True
            elif self.total:
                due = (tenth > self._last_tenth and t - self._last_line >= MIN_GAP_S) or (
                    t - self._last_line >= 3 * HEARTBEAT_S
                )
            else:
                due = t - self._last_line >= HEARTBEAT_S
            if due:
                self._last_tenth = tenth
                self._emit(self.line())

    def update(self, done: float, *, total: float | None = None) -> None:
        """Set the count done (and the total, when it becomes known)."""
        if total is not None:
            self.total = total
        self.done = float(min(done, self.total) if self.total else done)
        self._est.observe(self.done, self.total)
        if self._bar is not None:
            self._bar.update(self._task, completed=self.done, total=self.total, left=self._left())
        self._maybe_print()

    def advance(self, n: float = 1) -> None:
        """Count ``n`` more done."""
        self.update(self.done + n)

    def stage(
        self, label: str, *, done: float | None = None, restart: bool = False, force: bool = False
    ) -> None:
        """Name the work now under way: a new line in the plain mode once past the grace
        (``force``: at once); ``restart``: a new count with an unknown total (the old one is
        finished)."""
        self.label = label
        if restart:
            self.total, self.done, self.unit = None, 0.0, ""
            self._est = Estimator(None, self._clock)
        if done is not None:
            self.done = float(done)
            self._est.observe(self.done, self.total)
        if self._bar is not None:
            self._bar.update(
                self._task,
                description=escape(label),
                completed=self.done,
                total=self.total,
                left=self._left(),
            )
        if self.mode == "plain" and (force or self.elapsed >= GRACE_S):
            with self._lock:
                self._last_tenth = int(10 * self.done / self.total) if self.total else -1
                # a new stage names itself; "still running" is for the heartbeat lines
                self._emit(self.line() if self.total or self.done else label)

    def heartbeat(self) -> None:
        """Called every second by the plain mode's timer: a line when one is due."""
        self._maybe_print()

    def finish(self) -> None:
        """The last plain line, when the step printed a line or outlasted the grace."""
        if self.mode == "plain" and (self._printed or self.elapsed >= GRACE_S):
            unit = f" {self.unit}" if self.unit else ""
            count = (
                f" ({self.done:,.0f}/{self.total:,.0f}{unit})"
                if self.total
                else (f" ({self.done:,.0f}{unit})" if self.done else "")
            )
            with self._lock:
                self._emit(f"{self.title}: done{count}")


@contextmanager
def tracker(
    label: str,
    total: float | None = None,
    *,
    unit: str = "",
    quiet: bool = False,
    timed: bool = True,
) -> Iterator[Tracker]:
    """Progress of one step on stderr; yields a :class:`Tracker`.

    Parameters
    ----------
    label : str
        What is under way ("simulating", "fitting stribeck (rwsavsbas)").
    total : float, optional
        The count at the end (chunks, evaluations, joints); None when unknown.
    unit : str, optional
        What is counted ("chunks", "evaluations"), for the plain lines.
    quiet : bool, default False
        No output (also when ``--quiet`` was given to ``fricid`` itself).
    timed : bool, default True
        False: a count of steps of unequal cost, shown without a time left (their rate
        says nothing of the time the rest takes).
    """
    if quiet or is_quiet():
        yield Tracker(label, total, "quiet", unit=unit, timed=timed)
        return
    if not err_console.is_terminal:
        t = Tracker(label, total, "plain", unit=unit, timed=timed)
        stop = threading.Event()

        def beat() -> None:
            while not stop.wait(1.0):
                t.heartbeat()

        timer = threading.Thread(target=beat, name="fricid-progress", daemon=True)
        timer.start()
        try:
            yield t
        finally:
            stop.set()
            timer.join()
        t.finish()
        return
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        TextColumn("{task.fields[left]}"),
        console=err_console,
        transient=True,
    ) as bar:
        yield Tracker(label, total, "terminal", bar, unit=unit, timed=timed)


@contextmanager
def progress_bar(
    label: str, total: int | None, *, unit: str = "", quiet: bool = False
) -> Iterator[Callable[..., None]]:
    """:func:`tracker` for a plain count; yields ``advance(n=1)`` (extra arguments ignored,
    so it can be a library's ``on_chunk`` or per-item callback directly)."""
    with tracker(label, total, unit=unit, quiet=quiet) as t:

        def advance(n: Any = 1, *_: Any, **__: Any) -> None:
            t.advance(n if isinstance(n, int | float) and not isinstance(n, bool) else 1)

        yield advance


def fit_callback(t: Tracker, budget: int | None) -> Callable[[Any], None]:
    """An optimiser ``callback(intermediate_result)`` that moves ``t`` by evaluations.

    ``budget`` is the run's evaluation budget (the total). The callback never stops the run.
    """
    if budget:
        t.update(0, total=float(budget))

    def callback(res: Any) -> None:
        nfev = getattr(res, "nfev", None)
        if nfev is None and isinstance(res, dict):
            nfev = res.get("nfev")
        if nfev is not None:
            t.update(float(nfev))

    return callback


def fit_budget(
    model: str, method: str, fixed: dict[str, float] | None, max_evals: int | None
) -> int | None:
    """The evaluation budget of an analytic fit by a population method (the progress total);
    None for a least-squares method (it stops when converged, far below its budget), a model
    without named parameters (``rbf``, ``auto``) or a name the fit itself will refuse."""
    from ..models import STATEFUL, get_model
    from ..optim import METHODS

    key, meth = model.strip().lower(), method.strip().lower()
    if key in STATEFUL or key == "auto" or meth not in METHODS or METHODS[meth].uses_residuals:
        return None
    try:
        names = get_model(key).param_names
        dim = max(1, sum(1 for n in names if n not in (fixed or {})))
        solver = METHODS[meth]({}, dim=dim)
        natural = int(solver.default_budget())
    except Exception:  # an unknown model: fit raises the clear error
        return None
    if max_evals is None:
        return natural
    # a method with its own schedule (iterations, generations) ends there, budget or not
    scheduled = any(k in solver.opts for k in SCHEDULE_OPTIONS)
    return min(int(max_evals), natural) if scheduled else int(max_evals)


#: Models trained without a fricid optimiser method (the GP by scikit-learn's marginal
#: likelihood); the RBF networks and the hybrid name theirs (``--method``: BAS, GA, ...).
_OWN_TRAINING = frozenset({"gp"})


@contextmanager
def fit_progress(
    model: str,
    method: str,
    *,
    fixed: dict[str, float] | None = None,
    max_evals: int | None = None,
    quiet: bool = False,
) -> Iterator[tuple[Tracker, Callable[[Any], None] | None]]:
    """Progress of ``fricid fit``; yields ``(tracker, callback)``.

    ``callback`` is the optimiser callback to pass to :func:`fricid.identify.fit` (None for
    models that take none, ``rbf`` and ``auto``, and with ``--quiet``): it counts evaluations
    against the budget (:func:`fit_budget`), and once the budget is spent names what the fit
    does next (certifying convergence by a local polish, the 95 % intervals).
    """
    from ..models import STATEFUL

    key = model.strip().lower()
    # the learned models train by their own means: no optimiser method to name
    label = f"fitting {key}" if key in _OWN_TRAINING else f"fitting {key} ({method})"
    budget = fit_budget(model, method, fixed, max_evals)
    with tracker(label, budget, unit="evaluations", quiet=quiet) as t:
        if key in STATEFUL or key == "auto" or t.mode == "quiet":
            yield t, None  # no callback at all when quiet: not even its small cost
            return
        inner = fit_callback(t, budget)
        spent = [False]

        def callback(res: Any) -> None:
            inner(res)
            if budget and not spent[0] and t.done >= budget:
                spent[0] = True
                t.stage(f"{label}: budget spent; certifying convergence, intervals")

        yield t, callback
