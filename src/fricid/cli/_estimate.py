"""Honest estimates of the time a step has left, from the rate of its completed work.

A naive estimate (time so far over the fraction done) is wrong in the two ways users see:
a step that spends its first minute compiling or loading at 0 % and then runs fast says
"about 9 min left" seconds before it ends; a step that speeds up or slows down keeps an
estimate from its start. :class:`Estimator` therefore

* gives no estimate until the rate is known from completed work: work must have been
  reported at two moments at least :data:`MIN_SPAN_S` apart, after the first report, and
  :data:`MIN_FRACTION` of the total must be done;
* measures the rate from the first report on (what came before it, start-up included, is
  not counted: its duration says nothing of the rate), over the recent half of that span, so
  the estimate follows a change of pace;
* divides by the time up to *now*, not up to the last report, so a stall lengthens the
  estimate rather than freezing it;
* is read again at every line, so it is corrected as it goes; the lines say "about".

The clock is injected (``clock``), so the logic is tested without sleeping.
"""

from __future__ import annotations

import time
from collections.abc import Callable

__all__ = ["MIN_FRACTION", "MIN_SPAN_S", "Estimator"]

#: The fraction of the total that must be done before any estimate.
MIN_FRACTION = 0.05
#: Seconds of completed work (from the first report) before any estimate.
MIN_SPAN_S = 1.0


class Estimator:
    """Seconds left of a step whose total is known, from the rate of its completed work.

    Parameters
    ----------
    total : float or None
        The count at the end (None: unknown, no estimate).
    clock : callable, default time.perf_counter
        Seconds, monotonic.

    Examples
    --------
    >>> now = [0.0]
    >>> est = Estimator(100, clock=lambda: now[0])
    >>> now[0] = 58.0; est.observe(1)      # a minute of start-up, then the work starts
    >>> est.remaining() is None             # one report: no rate yet
    True
    >>> now[0] = 60.0; est.observe(21)      # 20 more in 2 s: 10 per second
    >>> round(est.remaining(), 6)            # 79 left at 10/s, not 79 * 60 / 21
    7.9
    """

    def __init__(self, total: float | None, clock: Callable[[], float] = time.perf_counter):
        self.total = total
        self.clock = clock
        self.start = clock()
        self.done = 0.0
        #: ``(time, done)`` at each report that moved the count, from the first one on.
        self.points: list[tuple[float, float]] = []

    def observe(self, done: float, total: float | None = None) -> None:
        """Record the count done now (and the total, when it becomes known or changes)."""
        if total is not None:
            self.total = total
        if done < self.done:  # a new count (a stage restarted): the old rate does not apply
            self.points.clear()
        if (done != self.done or not self.points) and done > 0:
            self.points.append((self.clock(), float(done)))
        self.done = float(done)

    def rate(self) -> float | None:
        """Work per second over the recent half of the span since the first report, or None
        while it is not known (:data:`MIN_SPAN_S`)."""
        if len(self.points) < 2:
            return None
        now = self.clock()
        t_first = self.points[0][0]
        if self.points[-1][0] - t_first < MIN_SPAN_S:
            return None
        cut = now - 0.5 * (now - t_first)
        ref = self.points[0]
        for point in self.points:
            if point[0] <= cut:
                ref = point
            else:
                break
        if ref is self.points[-1]:  # every recent report is older than the cut: a stall
            ref = self.points[-2] if len(self.points) >= 2 else ref
        work = self.done - ref[1]
        span = now - ref[0]
        return work / span if work > 0 and span > 0 else None

    def remaining(self) -> float | None:
        """Seconds left, or None: unknown total, finished, too little done
        (:data:`MIN_FRACTION`) or no rate yet (:meth:`rate`)."""
        if not self.total or self.done >= self.total:
            return None
        if self.done < MIN_FRACTION * self.total:
            return None
        rate = self.rate()
        if rate is None:
            return None
        return (self.total - self.done) / rate
