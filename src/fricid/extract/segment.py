"""Find the constant-velocity portions of a (streamed) raw log.

A *run* is a maximal stretch of samples whose measured velocity has one sign (a velocity
within :data:`REST_RESIDUE` of zero counts as zero) without a gap in time
(:data:`GAP_FACTOR`). Its *plateau* is the median velocity of
the run's faster half (samples above half its 99th-percentile speed, so a rest or drift with
the move's sign does not pull it down), refined once: the median of the samples within the
band; its
*steady part* runs from the first to the last sample within ``velocity_tolerance`` of the
plateau (which drops the acceleration and deceleration ramps), minus ``settle_time`` at each
end (what is left of a ramp, and the drive settling). Runs whose steady part is shorter than
``min_samples`` are dropped: dwells at rest, sign flicker of a noisy velocity near zero,
aborted moves. (Where that median falls between two levels of equal length, so that too few
samples are within its band, the plateau is the most populated band instead.)

A run may hold several plateaus: a log that steps from one speed to the next without
stopping (a staircase) is one run of one sign. Beside a run's plateau, the stretches before
and after it are searched for more (recursively; the most populated velocity band of each),
and a plateau found there is a *step* when it holds its speed: within the band, the medians of
its first and last quarters are within :data:`STEP_TREND` of the band of each other, which an
acceleration ramp crossing the band is not. The steps' runs partition the run (ramps between
steps count as the neighbouring step's transient). Before, such a log kept one set-point (the
median of its faster half) and dropped the others as transient.

Logs may arrive in chunks: the last run of a chunk may continue in the next one, so it is
carried over and finished there. A chunk whose time does not continue the previous one (a new
file) closes the open run.
"""

from __future__ import annotations

import itertools
import logging
from collections.abc import Iterable, Iterator
from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError
from ..samples import RawLog
from ._stats import median, percentile

__all__ = [
    "GAP_FACTOR",
    "REST_RESIDUE",
    "Segment",
    "SegmentCounts",
    "as_log_stream",
    "cluster",
    "iter_segments",
]

#: rad/s; a velocity of at most this magnitude is numerically zero (float residue of a velocity
#: estimate at standstill, typically 1e-15) and separates runs like an exact zero does, so a
#: rest whose residue has the sign of the next move is not merged into that move's run. It is
#: 0.2 deg per 100 hours, far below any speed an encoder can measure. Whether a slower run is
#: rest is decided later, relative to the log's own velocity scale and encoder step
#: (:func:`fricid.extract.steady.rest_threshold`).
REST_RESIDUE = 1e-9

#: A step of a staircase (a plateau beside a run's own, module notes) holds its speed: the
#: medians of the first and last quarters of its stretch within the velocity band are within
#: this share of the band of each other (a ramp crossing the band drifts across 3/4 of it).
STEP_TREND = 0.5

#: A step in time longer than this many median sample periods is a gap in the recording (rows
#: missing, or logs of separate moves joined) and ends a run like a change of sign does.
GAP_FACTOR = 10.0

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class Segment:
    """The steady part of one constant-velocity run.

    ``row`` is the global 0-based index of the segment's first sample in the stream; ``plateau``
    the run's median velocity [rad/s] (signed); ``direction`` +1 or -1; ``log`` the samples.
    ``run_samples`` and ``run_duration`` [s] describe the whole run the segment was cut from;
    ``band_fraction`` is the share of the steady part's samples inside the velocity band (near
    1 at constant velocity, small for a move without a plateau, such as a return move).
    """

    row: int
    plateau: float
    direction: int
    log: RawLog
    run_samples: int = 0
    band_fraction: float = 1.0
    run_duration: float = 0.0

    @property
    def speed(self) -> float:
        """rad/s, the plateau's magnitude."""
        return abs(self.plateau)

    @property
    def trimmed(self) -> int:
        """Samples of the run outside the steady part (ramps and settle margins)."""
        return max(self.run_samples - len(self.log), 0)


@dataclass
class SegmentCounts:
    """What segmentation saw: rows read, runs found, runs kept and dropped (by reason), and
    the samples of dropped runs: ``dropped_samples`` at rest (zero velocity, runs shorter than
    ``min_samples``), ``unsteady_samples`` in runs without a (long enough) plateau."""

    rows: int = 0
    chunks: int = 0
    runs: int = 0
    kept: int = 0
    dropped_short_run: int = 0
    dropped_no_plateau: int = 0
    dropped_short_steady: int = 0
    dropped_samples: int = 0  # samples at rest: zero velocity, runs too short to be moves
    unsteady_samples: int = 0  # samples of runs without a (long enough) plateau


def as_log_stream(logs: RawLog | Iterable[RawLog]) -> Iterator[RawLog]:
    """One RawLog or an iterable of them, as an iterator (type-checked)."""
    if isinstance(logs, RawLog):
        yield logs
        return
    i = 0  # counted by hand: ``enumerate`` keeps its last item while fetching the next
    for log in logs:
        if not isinstance(log, RawLog):
            raise ConfigError(
                f"extract: item {i} of 'logs' is a {type(log).__name__}, not a RawLog"
            )
        yield log
        del log  # not held while the next chunk is read
        i += 1  # noqa: SIM113 (see above)


def _find(
    log: RawLog,
    start: int,
    stop: int,
    velocity_tolerance: float,
    settle_time: float,
    min_samples: int,
    counts: SegmentCounts | None = None,
    step: bool = False,
) -> tuple[int, int, int, int, float, float] | None:
    """The plateau of ``start:stop`` of ``log``: (a, b, a2, b2, plateau, band fraction), the
    samples ``a:b`` within the band and ``a2:b2`` its steady part; or None, the reason counted
    in ``counts`` when given. A ``step`` (a stretch beside a run's plateau, module notes) must
    also hold its speed: the first and last quarters of its stretch within the band within
    :data:`STEP_TREND` of the band of each other, which a ramp through the band is not."""
    if stop - start < min_samples:
        if counts is not None:
            counts.dropped_short_run += 1
            counts.dropped_samples += stop - start
        return None
    v = log.velocity[start:stop]
    # the median of the faster half: a rest (or slow drift) at either end of the run, with the
    # sign of the move, must not pull the plateau towards zero
    speed = np.abs(v)
    if step:  # several levels: the most populated band, not a median between two of them
        plateau = _densest(v, velocity_tolerance)
    else:
        plateau = median(v[speed >= 0.5 * percentile(speed, 99)])
    inside = np.flatnonzero(np.abs(v - plateau) <= velocity_tolerance * abs(plateau))
    if inside.size < min_samples and not step:  # a median fallen between two levels
        plateau = _densest(v, velocity_tolerance)
        inside = np.flatnonzero(np.abs(v - plateau) <= velocity_tolerance * abs(plateau))
    if inside.size:
        # refine: the run's median is pulled towards the ramps; the band's median is not
        plateau = median(v[inside])
        inside = np.flatnonzero(np.abs(v - plateau) <= velocity_tolerance * abs(plateau))
    if plateau == 0.0 or inside.size == 0:
        if counts is not None:
            counts.dropped_no_plateau += 1
            counts.unsteady_samples += stop - start
        return None
    a, b = start + int(inside[0]), start + int(inside[-1]) + 1
    t = log.time[a:b]
    # a sample within a thousandth of a period of the settle time counts as at it: the
    # comparison is otherwise decided by the rounding of the clock (a log's time shifted by
    # 31.3 s had moved the cut by a sample, and a knife-edge block of the settle test then
    # kept 119 samples of a sweep instead of 40)
    slack = 1e-3 * (t[-1] - t[0]) / max(t.size - 1, 1)
    a2 = a + int(np.searchsorted(t, t[0] + settle_time - slack, side="left"))
    b2 = a + int(np.searchsorted(t, t[-1] - settle_time + slack, side="right"))
    if b2 - a2 < min_samples:
        if counts is not None:
            counts.dropped_short_steady += 1
            counts.unsteady_samples += stop - start
        return None
    if step:  # the stretch within the band: a ramp crosses it, a step stays
        within = log.velocity[a:b]
        q = max(len(within) // 4, 1)
        drift = abs(median(within[-q:]) - median(within[:q]))
        if drift > STEP_TREND * velocity_tolerance * abs(plateau):
            return None
    v2 = log.velocity[a2:b2]
    band = float(np.mean(np.abs(v2 - plateau) <= velocity_tolerance * abs(plateau)))
    return a, b, a2, b2, plateau, band


def _densest(v: np.ndarray, velocity_tolerance: float) -> float:
    """The velocity whose band (``velocity_tolerance`` of it either side) holds the most of
    ``v`` (one sign)."""
    x = np.sort(v)
    width = velocity_tolerance * np.abs(x)
    count = np.searchsorted(x, x + width, side="right") - np.searchsorted(x, x - width)
    return float(x[int(np.argmax(count))])


def _steps_in(log: RawLog, lo: int, hi: int, *options) -> list[tuple[int, ...]]:
    """The steps of a staircase in ``lo:hi`` (module notes): (a2, b2, plateau, band, run_lo,
    run_hi) each, in order; their runs partition ``lo:hi`` when any (the stretch before a step
    is its own, the stretch after the last the last's), searched with a stack rather than by
    recursion, so that no log can run into Python's recursion limit."""
    cores, todo = [], [(lo, hi)]
    while todo:
        start, stop = todo.pop()
        core = _find(log, start, stop, *options, step=True)
        if core is not None:
            cores.append(core)
            todo += [(start, core[0]), (core[1], stop)]
    if not cores:
        return []
    cores.sort()
    ends = [b for _, b, *_ in cores[:-1]] + [hi]
    begins = [lo, *ends[:-1]]
    return [
        (a2, b2, plateau, band, begin, end)
        for (_, _, a2, b2, plateau, band), begin, end in zip(cores, begins, ends, strict=True)
    ]


def _steady(
    log: RawLog,
    start: int,
    stop: int,
    velocity_tolerance: float,
    settle_time: float,
    min_samples: int,
    counts: SegmentCounts,
) -> list[tuple[int, int, float, int, float, float]]:
    """The steady parts of the run ``start:stop`` of ``log`` (its plateau, and the steps of a
    staircase beside it): (start, stop, plateau, run samples, band fraction, run duration)
    each, the runs they stand for partitioning the run."""
    counts.runs += 1
    options = (velocity_tolerance, settle_time, min_samples)
    core = _find(log, start, stop, *options, counts=counts)
    if core is None:
        return []
    a, b, a2, b2, plateau, band = core
    left, right = _steps_in(log, start, a, *options), _steps_in(log, b, stop, *options)
    parts = [*left, (a2, b2, plateau, band, a if left else start, b if right else stop), *right]
    counts.kept += len(parts)
    return [
        (a2, b2, p, hi - lo, band, float(log.time[hi - 1] - log.time[lo]))
        for a2, b2, p, band, lo, hi in parts
    ]


def iter_segments(
    logs: RawLog | Iterable[RawLog],
    *,
    velocity_tolerance: float = 0.05,
    settle_time: float = 0.1,
    min_samples: int = 20,
    counts: SegmentCounts | None = None,
) -> Iterator[Segment]:
    """Yield the constant-velocity segments of a log stream, in order.

    Parameters
    ----------
    logs : RawLog or iterable of RawLog
        One log or consecutive chunks of one (memory is bounded by one chunk plus one run).
    velocity_tolerance : float
        Relative band around the plateau velocity that counts as steady.
    settle_time : float
        s trimmed from each end of the steady part.
    min_samples : int
        Shortest steady part kept.
    counts : SegmentCounts, optional
        Filled with what was found and dropped (runs by reason, samples by fate).

    Yields
    ------
    Segment
        The steady part of each run with a plateau, with its run's size, duration and band
        fraction (whether it is a set-point, rest or unsteady is decided by the caller,
        :class:`fricid.extract.accumulate.Accumulator`).
    """
    if not (0 < velocity_tolerance < 1):
        raise ConfigError(f"velocity_tolerance must be in (0, 1), got {velocity_tolerance!r}")
    if settle_time < 0:
        raise ConfigError(f"settle_time must be >= 0 s, got {settle_time!r}")
    if int(min_samples) != min_samples or min_samples < 1:
        raise ConfigError(f"min_samples must be a positive integer, got {min_samples!r}")
    counts = SegmentCounts() if counts is None else counts
    options = (velocity_tolerance, settle_time, int(min_samples), counts)

    carry: RawLog | None = None  # the open run, carried into the next chunk
    carry_sign = 0.0  # its velocity's sign (one run: one sign)
    carry_row = 0
    for chunk in as_log_stream(logs):
        counts.chunks += 1
        counts.rows += len(chunk)
        if len(chunk) == 0:
            continue
        if carry is not None and chunk.time[0] <= carry.time[-1]:
            # time restarts: a new file; the open run ends here
            for found in _steady(carry, 0, len(carry), *options):
                yield _segment(carry, carry_row, *found)
            carry_row += len(carry)
            carry = None
        # the runs of carry + chunk, found without joining the two: only the runs that start in
        # the carry are cut from a joined copy
        lc = 0 if carry is None else len(carry)
        n = lc + len(chunk)
        sign = _sign(chunk.velocity)
        edges = np.flatnonzero(sign[1:] != sign[:-1]) + (1 + lc)
        if lc and sign[0] != carry_sign:
            edges = np.concatenate(([lc], edges))
        if n > 2:  # a gap in the recording ends a run too
            # the median partitions the steps in place, which are then taken again: one
            # chunk-sized temporary at a time
            limit = GAP_FACTOR * median(_steps(carry, chunk), overwrite=True)
            gaps = np.flatnonzero(_steps(carry, chunk) > limit) + 1
            edges = np.union1d(edges, gaps)
        starts = np.concatenate(([0], edges))
        stops = np.concatenate((edges, [n]))
        in_carry = int(np.searchsorted(starts, lc))  # runs starting in the carry
        head = _join(carry, chunk, int(stops[in_carry - 1])) if in_carry else None
        for i, (start, stop) in enumerate(zip(starts[:-1], stops[:-1], strict=True)):
            log, offset = (head, 0) if i < in_carry else (chunk, lc)
            if (carry_sign if i < in_carry else sign[start - lc]) == 0:
                counts.dropped_samples += int(stop - start)
                continue
            for found in _steady(log, int(start) - offset, int(stop) - offset, *options):
                yield _segment(log, carry_row + offset, *found)
        last = int(starts[-1])
        if last < lc:  # the open run goes on through the whole chunk (``head`` holds it)
            carry = head.slice(last, n)
        else:
            # a copy: a view would keep the whole chunk alive while the next is read
            carry = RawLog.concatenate([chunk.slice(last - lc, len(chunk))])
            carry_sign = float(sign[last - lc])
        carry_row += last
        chunk = head = log = sign = None  # not held while the next chunk is read
    if carry is not None and len(carry) and abs(carry.velocity[0]) > REST_RESIDUE:
        for found in _steady(carry, 0, len(carry), *options):
            yield _segment(carry, carry_row, *found)
    elif carry is not None:
        counts.dropped_samples += len(carry)
    logger.debug("segmentation: %s", counts)


def _sign(velocity: np.ndarray) -> np.ndarray:
    """The sign of each velocity (int8); 0 within :data:`REST_RESIDUE` of zero (float residue:
    not moving)."""
    sign = (velocity > REST_RESIDUE).view(np.int8)
    sign -= velocity < -REST_RESIDUE
    return sign


def _steps(carry: RawLog | None, chunk: RawLog) -> np.ndarray:
    """The time steps of ``carry`` (if any) followed by ``chunk``."""
    dt = np.diff(chunk.time)
    if carry is None or len(carry) == 0:
        return dt
    return np.concatenate((np.diff(carry.time), chunk.time[:1] - carry.time[-1], dt))


def _join(carry: RawLog | None, chunk: RawLog, stop: int) -> RawLog:
    """Rows ``[0, stop)`` of ``carry`` followed by ``chunk`` (a copy only where they meet)."""
    if carry is None or len(carry) == 0:
        return chunk.slice(0, stop)
    if stop <= len(carry):
        return carry.slice(0, stop)
    return RawLog.concatenate([carry, chunk.slice(0, stop - len(carry))])


def _segment(
    log: RawLog,
    row0: int,
    start: int,
    stop: int,
    plateau: float,
    run_samples: int,
    band: float,
    duration: float,
) -> Segment:
    return Segment(
        row=row0 + start,
        plateau=plateau,
        direction=1 if plateau > 0 else -1,
        log=log.slice(start, stop),
        run_samples=run_samples,
        band_fraction=band,
        run_duration=duration,
    )


def cluster(
    values: np.ndarray, tolerance: float, *, relative: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Group 1-D values into set-points whose span is bounded, so groups cannot chain.

    Sorted, a new group starts where the gap to the previous value exceeds ``tolerance``
    (relative to that value when ``relative``); then every group whose span (largest minus
    smallest value) exceeds ``tolerance`` (times the magnitude of its median when
    ``relative``) is split at its widest gap, recursively. Closely spaced values (speeds 3 %
    apart over a decade) thus form groups no wider than the tolerance around their centre,
    instead of one chain whose neighbours are each within the tolerance.

    Returns (labels (n,), centres (k,)): labels number the groups in ascending order and each
    centre is its group's median.
    """
    values = np.asarray(values, dtype=float)
    if values.size == 0:
        return np.zeros(0, dtype=np.intp), np.zeros(0)
    order = np.argsort(values, kind="stable")
    s = values[order]
    gap = np.diff(s)
    limit = tolerance * np.abs(s[:-1]) if relative else tolerance
    cuts = list(np.flatnonzero(gap > limit) + 1)
    bounds = [0, *cuts, s.size]
    pending = list(itertools.pairwise(bounds))
    starts = []
    while pending:
        a, b = pending.pop()
        span = s[b - 1] - s[a]
        allowed = tolerance * abs(float(np.median(s[a:b]))) if relative else tolerance
        if b - a < 2 or span <= allowed:
            starts.append(a)
            continue
        cut = a + 1 + int(np.argmax(np.diff(s[a:b])))
        pending += [(a, cut), (cut, b)]
    new = np.zeros(s.size, dtype=np.intp)
    new[sorted(starts)[1:]] = 1
    sorted_labels = np.cumsum(new)
    labels = np.empty_like(sorted_labels)
    labels[order] = sorted_labels
    k = int(sorted_labels[-1]) + 1
    centres = np.array([np.median(s[sorted_labels == j]) for j in range(k)])
    return labels, centres
