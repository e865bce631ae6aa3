"""The encoder behind a position column: its quantum read from the position's own steps, and
what the quantum says of the column's unit.

A drive logs the position quantised to its encoder, ``q_k = c_k Delta`` with ``c_k`` an
integer count and ``Delta = 2 pi / N`` for ``N`` counts per revolution (in the column's
unit: ``360 / N`` in degrees). :func:`encoder_quantum` finds ``Delta`` from the steps (every
step a whole multiple of the smallest). Read in radians, ``2 pi / Delta`` is then ``N``,
a power of two for a binary encoder. A column in degrees labelled radians reads
``N pi / 180`` counts per revolution instead (2287.6 for 2^17), in revolutions ``2 pi N``:
:func:`position_unit_problem` names that mistake where the counts read are no power of two
and the counts in degrees or revolutions are one (or, a column in radians labelled degrees,
``180 N / pi``). The position and velocity of such a log
agree with each other (both in the wrong unit, :func:`fricid.samples.velocity_mismatch`
sees nothing), and a trajectory fit then returns an inertia 57.3^2 times off with a good
fit.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["encoder_quantum", "position_unit_problem"]

#: Largest distance of a step's count from a whole number for the log to read as quantised
#: (a log written with 7 decimals puts a 2^17 count's steps up to 0.0022 off; a continuous
#: position has steps at every fraction of a count).
COUNT_TOLERANCE = 0.05

#: The most a step's rounding when the file was written widens :data:`COUNT_TOLERANCE`, in
#: counts.
MAX_WRITTEN = 0.2

#: Steps of at most this many counts refine the candidate quantum (:func:`_refined`).
SMALL_COUNTS = 8

#: Fewest non-zero position steps from which a quantum is read.
MIN_STEPS = 20

#: The smallest step is tried as 1, 2, ... up to this many counts.
MAX_SPLIT = 4

#: Relative distance from a power of two within which counts read are taken as it (a log
#: written with 7 decimals read 2^20 as 1048597: 2e-5 off).
POWER_SNAP = 1e-4

#: Mistakes of a position column's unit: (the column is in ..., the counts per revolution
#: read in SI over the encoder's counts).
MISREAD = (
    ("degrees labelled radians", math.pi / 180.0),
    ("revolutions labelled radians", 2.0 * math.pi),
    ("radians labelled degrees", 180.0 / math.pi),
)


def encoder_quantum(position: np.ndarray) -> float | None:
    """The encoder's quantum [rad] read from the position steps, or None when the steps have
    no common quantum (a continuous or interpolated position) or are too few.

    The smallest non-zero step, or its half, third or quarter (a fast motion may never move
    by one count between samples), or the smallest gap between two steps
    (:func:`_guesses`), refined on the small steps, is the candidate; the log is
    quantised when every step is a whole multiple of it, within :data:`COUNT_TOLERANCE` of a
    count plus the step's rounding when the file was written (read from the digits each
    position was written with: a 2^18-count log written with 7 significant digits is 0.04
    counts off by its rounding alone, and had been read as continuous).
    """
    position = np.asarray(position, dtype=float)
    steps = np.abs(np.diff(position))
    scale = float(np.max(np.abs(position))) if np.size(position) else 0.0
    moved = steps > 1e-12 * max(scale, 1.0)
    nonzero = steps[moved]
    if nonzero.size < MIN_STEPS:
        return None
    grain = _decimal_grain(position)
    written = (0.5 * (grain[:-1] + grain[1:]))[moved]  # each step's rounding, at most
    for guess in _guesses(nonzero, written):
        quantum = _refined(nonzero, guess)
        counts = np.round(nonzero / quantum)
        off = np.abs(nonzero / quantum - counts)
        # capped: a value that happens to end in zeros ("0.5") reads a coarse grain, and
        # steps that are whole multiples of the digits themselves need no allowance
        if np.all(off <= COUNT_TOLERANCE + np.minimum(written / quantum, MAX_WRITTEN)):
            break
    else:
        return None
    # refine by the positions themselves: q_k = offset + quantum c_k over the whole span of
    # counts (a written log's rounding of each position then averages out)
    q = np.asarray(position, dtype=float)
    quantum = float(np.mean(nonzero / counts))
    c = np.round((q - q[0]) / quantum)
    if np.ptp(c) < 1:
        return quantum
    slope = np.polyfit(c, q, 1)[0]
    return float(slope)


def _guesses(steps: np.ndarray, written: np.ndarray) -> list[float]:
    """The quantum's candidates: the smallest step and its half, third, ... (up to
    :data:`MAX_SPLIT`), then the smallest gap between two different steps, for a motion that
    never moves by fewer than :data:`MAX_SPLIT` counts (steps of 13 and 14 counts differ by
    one: 10 of 4,000 motions of the property test, at 2^10 to 2^20 counts and never slower
    than 5 counts a sample, had been read as continuous); gaps within the file's rounding
    are not gaps."""
    smallest = float(np.min(steps))
    out = [smallest / split for split in range(1, MAX_SPLIT + 1)]
    ordered = np.sort(steps)
    gaps = np.diff(ordered)
    apart = gaps > max(2.0 * float(np.median(written)), 1e-9 * smallest)  # a few end in 0s
    if apart.any():
        out.append(float(np.min(gaps[apart])))
    return out


def _refined(steps: np.ndarray, quantum: float) -> float:
    """The candidate ``quantum`` refined on the steps of at most :data:`SMALL_COUNTS` counts
    (their counts cannot be miscounted by its error), then on steps of up to four times as
    many counts at a time while larger ones remain: the smallest step carries the file's
    rounding, and a large step's count multiplies it (a 2^18-count log written with 9
    significant digits read its smallest step 0.99965 counts, and a step of 150 counts then
    0.05 off a whole one; written with 7 and moving up to 268 counts a sample, the small
    steps' refinement still left the largest 0.06 off)."""
    top = float(np.max(steps)) / quantum if steps.size else 0.0
    limit = float(SMALL_COUNTS)
    while True:
        for _ in range(3):
            small = steps[steps <= (limit + 0.5) * quantum]
            counts = np.round(small / quantum)
            if small.size == 0 or counts.sum() <= 0:
                break
            quantum = float(small.sum() / counts.sum())
        if limit >= top:
            return quantum
        limit *= 4.0


def _decimal_grain(values: np.ndarray) -> np.ndarray:
    """Each value's last written decimal place (``10^-k`` for the fewest decimals ``k`` that
    give it; 0 for a value written to full precision): its rounding when the file was
    written is at most half of it."""
    grain = np.zeros(values.shape)
    left = np.ones(values.shape, dtype=bool)
    for k in range(13):
        scaled = values * 10.0**k
        whole = np.abs(scaled - np.round(scaled)) <= 1e-6 + 4e-16 * np.abs(scaled)
        grain[left & whole] = 10.0**-k
        left &= ~whole
    return grain


def _power_of_two(counts: float) -> int | None:
    """``counts`` as the power of two it is within :data:`POWER_SNAP`, else None."""
    if not (math.isfinite(counts) and counts >= 2):
        return None
    power = 2 ** round(math.log2(counts))
    return power if abs(counts / power - 1.0) <= POWER_SNAP else None


def position_unit_problem(position) -> str | None:
    """What is wrong with a position column [rad, as read] whose steps are a binary
    encoder's counts in another unit (:data:`MISREAD`, module notes), else None (no quantum
    found, or the counts read a power of two, or no mistake makes them one)."""
    quantum = encoder_quantum(np.asarray(position, dtype=float))
    if quantum is None:
        return None
    counts = 2.0 * math.pi / quantum
    if _power_of_two(counts) is not None:
        return None
    for mistake, factor in MISREAD:
        encoder = _power_of_two(counts / factor)
        if encoder is not None:
            return (
                f"its steps are the counts of a {encoder}-count encoder with the column in "
                f"{mistake} ({counts:.6g} counts per revolution as read, a power of two "
                "the other way)"
            )
    return None
