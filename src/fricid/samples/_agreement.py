"""Do a log's position and velocity agree? A units or sign mistake that nothing else catches.

A velocity column is the derivative of the position column, whatever the log's units, once
both are in SI. A column labelled in the wrong unit (radians labelled degrees), a sign
reversed on one channel, or a motor-side velocity beside a joint-side position breaks that,
and every fit that reads both columns (or reads the position for the dynamics) then returns
numbers off by the factor, with a good fit and no warning. :func:`velocity_mismatch` measures
the factor ``s`` in ``delta position = s * integral of velocity`` over :data:`WINDOWS` windows
of the log (the median of the windows' ratios, so a wrapped angle or a spike in one window
does not move it; the integral averages the velocity's noise out) and names the likely cause
when ``s`` is outside :data:`AGREEMENT`: a known unit factor (:data:`UNIT_FACTORS`), a
reversed sign, else a gear ratio or an unknown unit. :func:`wrapped_rows` finds an angle
wrapped to one turn (a jump the velocity does not explain, which the median above ignores but
a derivative filter does not). :func:`coarse_velocity` recognises a velocity that is a coarse
encoder's finite difference (zero between steps while the joint moves), and
:func:`windowed_velocity` gives the velocity to use instead: the position's least-squares
slope over a window per row that spans enough encoder steps to resolve the row's speed.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "AGREEMENT",
    "UNIT_FACTORS",
    "WINDOWS",
    "coarse_velocity",
    "velocity_mismatch",
    "velocity_scale",
    "windowed_velocity",
    "wrapped_rows",
]

#: The windows the log is cut into for the ratios.
WINDOWS = 40
#: The factors accepted as agreement (a drive's filtered velocity, a delay, the integration).
AGREEMENT = (0.8, 1.25)
#: A window counts when its integrated velocity is at least this share of the largest one.
MIN_SHARE = 0.1
#: Windows needed for a judgement (fewer: the log does not move enough to tell).
MIN_WINDOWS = 5
#: ... each with an integrated velocity over this many times the random walk its white
#: noise alone would give it.
NOISE_SIGMAS = 10.0
#: Known unit factors between a position and a velocity channel, and what each means.
UNIT_FACTORS: dict[float, str] = {
    180.0 / math.pi: "degrees against radians",
    2.0 * math.pi: "revolutions against radians",
    60.0: "per minute against per second",
    60.0 / (2.0 * math.pi): "rpm against rad/s",
    1000.0: "milli-units against units (mm or mrad)",
}
#: Time units whose factor to seconds is a factor above: a time column read in the wrong one
#: scales the integral of the velocity by it.
TIME_UNITS = {"ms": 1000.0, "min": 1.0 / 60.0}
#: Relative tolerance for a known unit factor (the nearest one; 57.3 and 60 are 4.7 % apart).
FACTOR_TOLERANCE = 0.02

#: A step in time over this many median periods is a cut in the log (rows removed, a pause
#: in the recording), not a sample period.
TIME_JUMP = 5.0


def velocity_scale(time, position, velocity) -> float | None:
    """The factor ``s`` with ``delta position = s * integral of velocity`` (module notes).

    Parameters
    ----------
    time, position, velocity : array_like, shape (n,)
        One joint's columns in SI units, time strictly increasing.

    Returns
    -------
    float or None
        The median ratio over the windows that move; None when fewer than
        :data:`MIN_WINDOWS` windows move (nothing to judge).
    """
    t = np.asarray(time, dtype=float)
    q = np.asarray(position, dtype=float)
    v = np.asarray(velocity, dtype=float)
    n = t.size
    if n < 2 * MIN_WINDOWS:
        return None
    # across a jump in time (rows cut out of the log) the velocity's integral is unknown:
    # such a step is left out of both sums
    steps = np.diff(t)
    cut = steps > TIME_JUMP * float(np.median(steps))
    moved = np.where(cut, 0.0, 0.5 * (v[1:] + v[:-1]) * steps)
    integral = np.concatenate([[0.0], np.cumsum(moved)])
    position = np.concatenate([[0.0], np.cumsum(np.where(cut, 0.0, np.diff(q)))])
    edges = np.unique(np.linspace(0, n - 1, min(WINDOWS, n // 2) + 1).astype(int))
    dq, di = np.diff(position[edges]), np.diff(integral[edges])
    top = float(np.max(np.abs(di)))
    if not top > 0:
        return None
    # a window's integral must stand out of what the velocity's white noise alone gives it
    # (a joint at rest with a noisy velocity sensor integrates to a random walk)
    dv = np.diff(v)
    noise = 1.4826 * float(np.median(np.abs(dv - np.median(dv)))) / math.sqrt(2.0)
    walk = NOISE_SIGMAS * noise * np.sqrt(np.diff(edges)) * float(np.median(np.diff(t)))
    keep = (np.abs(di) >= MIN_SHARE * top) & (np.abs(di) > walk)
    if keep.sum() < MIN_WINDOWS:
        return None
    return float(np.median(dq[keep] / di[keep]))


def _cause(scale: float) -> str:
    """The likely cause of a factor outside :data:`AGREEMENT`."""
    size = abs(scale)
    if size == 0:
        return "the position does not change while the velocity says the joint moves"
    sign = "reversed sign and " if scale < 0 else ""
    candidates = [
        (f, meaning, *pair)
        for factor, meaning in UNIT_FACTORS.items()
        for f, pair in ((factor, ("position", "velocity")), (1 / factor, ("velocity", "position")))
    ]
    f, meaning, big, small = min(candidates, key=lambda c: abs(math.log(size / c[0])))
    if abs(math.log(size / f)) <= math.log1p(FACTOR_TOLERANCE):
        return (
            f"{sign}units {meaning} (the {big} is {max(f, 1 / f):.4g}x too large for the "
            f"{small}, or the {small} as much too small)" + _time_unit(f)
        )
    if scale < 0 and abs(size - 1.0) <= 1.0 - AGREEMENT[0]:
        return "one of the two columns has its sign reversed"
    return (
        f"{sign}a factor that is no known unit: a gear ratio between a motor-side and a "
        "joint-side channel, or a wrong unit or scale"
    )


def _time_unit(factor: float) -> str:
    """The time column as a suspect for a factor that is a time unit's (:data:`TIME_UNITS`):
    the integral of the velocity scales with the time (a log in seconds under ``time [ms]``
    reads 1000x)."""
    for unit, f in TIME_UNITS.items():
        if math.isclose(factor, f, rel_tol=FACTOR_TOLERANCE):
            return f"; or the time column: times in seconds under a header in {unit}"
        if math.isclose(factor, 1 / f, rel_tol=FACTOR_TOLERANCE):
            return f"; or the time column: times in {unit} under a header in seconds"
    return ""


def velocity_mismatch(time, position, velocity, *, column: str | None = None) -> str | None:
    """What is wrong when the velocity is not the position's derivative, else None.

    Parameters
    ----------
    time, position, velocity : array_like, shape (n,)
        One joint's columns in SI units.
    column : str, optional
        The joint's name, to begin the message with (``"elbow: ..."``).

    Returns
    -------
    str or None
        E.g. ``"the position changes by 0.0175x the integral of the velocity (expected 1):
        units degrees against radians (...)"``; None when they agree or the log does not
        move enough to tell.
    """
    scale = velocity_scale(time, position, velocity)
    if scale is None or AGREEMENT[0] <= scale <= AGREEMENT[1]:
        return None
    prefix = f"{column}: " if column else ""
    return (
        f"{prefix}the position changes by {scale:.3g}x the integral of the velocity "
        f"(expected 1): {_cause(scale)}"
    )


def wrapped_rows(time, position, velocity) -> np.ndarray:
    """The rows where the position jumps by more than pi from the row before while the mean
    of the two velocities times the step explains less than half of it: an angle wrapped to
    one turn (``[-pi, pi)`` or ``[0, 2 pi)``), or a glitch of the position channel.

    Returns
    -------
    ndarray of int
        Row indices (the row after each jump), empty when there is none.
    """
    t = np.asarray(time, dtype=float)
    q = np.asarray(position, dtype=float)
    v = np.asarray(velocity, dtype=float)
    dq = np.diff(q)
    moved = 0.5 * (v[1:] + v[:-1]) * np.diff(t)
    return np.flatnonzero((np.abs(dq) > math.pi) & (np.abs(dq - moved) > 0.5 * np.abs(dq))) + 1


#: Half-width [samples] of the window over which the position is seen to move.
MOVE_WINDOW = 10
#: A velocity reading 0 at this share of the rows where the position moves is coarse ...
COARSE_ZEROS = 0.3
#: ... as is one of fewer steps per sample than this (median, where it is not 0): each
#: reading is then a whole number of steps over 5 % apart, and runs at 0.45 and 0.55 rad/s
#: through 2^12 counts at 250 Hz (1.2 and 1.4 steps per sample, few zeros) read one speed.
COARSE_STEPS = 20.0
#: ... when its readings change from one moving row to the next at over this share of them
#: (a speed between two whole counts per sample: a simulated ramp's exact velocity, a whole
#: number of its own steps per sample, does not flicker and is left as it is).
FLICKER = 0.2


def coarse_velocity(time, position, velocity) -> str | None:
    """What is wrong when the velocity is a coarse encoder's finite difference, else None.

    Such a velocity is a whole number of ``step / dt`` (or half that, central differences)
    and reads 0 between steps while the joint moves slowly, so steady-state detection takes
    slow runs for rest, and at a few steps per sample its readings are so far apart that
    runs a few per cent apart read one speed. Judged where the position changes by a step
    or more over ``2`` :data:`MOVE_WINDOW` rows: when its non-zero values are such multiples
    (90 % within 1 %) and it is 0 at over :data:`COARSE_ZEROS` of them or moves fewer than
    :data:`COARSE_STEPS` steps per sample (the median) with readings that flicker
    (:data:`FLICKER`).
    """
    t = np.asarray(time, dtype=float)
    q = np.asarray(position, dtype=float)
    v = np.asarray(velocity, dtype=float)
    m = MOVE_WINDOW
    if q.size <= 2 * m + 1:
        return None
    d = np.abs(np.diff(q))
    d = d[d > 1e-12]
    if not d.size:
        return None
    step, dt = float(d.min()), float(np.median(np.diff(t)))
    moves = np.zeros(q.size, dtype=bool)
    moves[m:-m] = np.abs(q[2 * m :] - q[: -2 * m]) >= 0.999 * step
    if moves.sum() < 10 * m:
        return None
    zeros = float(np.mean(v[moves] == 0))
    quantum = step / (2 * dt)
    k = v[moves & (v != 0)] / quantum
    whole = float(np.mean(np.abs(k - np.round(k)) < 0.01)) if k.size else 0.0
    per_sample = float(np.median(np.abs(k))) / 2 if k.size else 0.0  # steps per sample
    both = moves[1:] & moves[:-1]
    flicker = float(np.mean(v[1:][both] != v[:-1][both])) if both.any() else 0.0
    few = per_sample < COARSE_STEPS and flicker > FLICKER
    if whole < 0.9 or (zeros <= COARSE_ZEROS and not few):
        return None
    return (
        f"the velocity is the position's finite difference at a coarse encoder (steps of "
        f"{step:.3g} rad at {1 / dt:.4g} Hz): it reads 0 at {100 * zeros:.0f} % of the rows "
        f"where the joint moves and a median {per_sample:.3g} steps per sample elsewhere, so "
        "slow runs look like rest and runs a few per cent apart read one speed; log the "
        "drive's velocity estimate, or a position with more counts per turn"
    )


#: Encoder steps each row's window spans. Tuned on a new-user trial's campaign (2^12 counts
#: at 250 Hz, gravity, six speeds, 2 s runs at 0.066 rad/s) and a second trial's campaigns
#: (2^10 and 2^12 counts, 100 Hz-1 kHz, runs 2 % apart, staircases), checked on
#: ``tests/extract``'s own generator. 20 gave every set-point the encoder resolves, within
#: 0.33 % of its speed and 1.7 mN m of its friction; 50 lost the first campaign's
#: 0.01 rad/s; 10 read 2.015 for 2 rad/s and merged runs 2 % apart; 5 did as 20 on the
#: first campaign.
WINDOW_COUNTS = 20
#: A row's window is used where its two halves move alike: counts within this many, or this
#: share of the whole (a constant speed; near a run's end one half reaches into the ramp or
#: the rest, and the row keeps the logged velocity, which steady-state detection trims).
SIDE_COUNTS = 2.0
SIDE_SHARE = 0.1
#: The longest half-window [s] (rows slower than ``WINDOW_COUNTS`` steps in it: rest, or
#: nearly).
MAX_HALF_WINDOW = 2.0


def window_slope(t: np.ndarray, q: np.ndarray, half: np.ndarray) -> np.ndarray:
    """The least-squares slope of ``q`` over rows ``i - h .. i + h`` (each row's ``h`` in
    ``half``, cut short symmetrically at the ends; the sample period the median): a
    Savitzky-Golay first derivative of order one, from cumulative sums. Unlike the window's
    end-to-end difference, whose values are whole steps over the window (levels 5 % apart at
    20 steps: runs 2 % apart read one level), it averages every row's rounding."""
    n = q.size
    i = np.arange(n)
    h = np.minimum(np.minimum(half, i), n - 1 - i)
    dt = float(np.median(np.diff(t)))
    x = q - q[0]
    s0 = np.concatenate([[0.0], np.cumsum(x)])
    s1 = np.concatenate([[0.0], np.cumsum(i * x)])
    lo, hi = i - h, i + h + 1
    moment = (s1[hi] - s1[lo]) - i * (s0[hi] - s0[lo])  # sum of (k - i) x_k
    norm = h * (h + 1) * (2 * h + 1) / 3.0
    return np.divide(moment, norm * dt, out=np.zeros(n), where=norm > 0)


def windowed_velocity(time, position, velocity) -> tuple[np.ndarray, tuple[int, int]]:
    """The velocity as the position's least-squares slope over a window per row, and the
    shortest and longest half-windows used [rows].

    The M/T method of encoder speed measurement, with the least-squares slope over the
    window (:func:`window_slope`) in place of its end-to-end difference: each row's window
    spans :data:`WINDOW_COUNTS` encoder steps. A row's window is found in two passes: the
    shortest of 1, 2, 4, ... rows each side over which the position changes by that many
    steps gives a rough speed; its median over that window gives the half-window
    ``ceil(WINDOW_COUNTS step / (2 dt speed))``. Chosen by each row's own count instead, a
    run whose speed sits near a threshold had rows that reach the count by a quantisation
    step and rows that miss it, and the run's mean came out 1 % fast (a 2^10-count encoder
    at 0.94 rad/s); the end-to-end difference's values are whole steps over the window,
    levels 5 % apart, and runs 2 % apart read one level. Over 939 runs (120 speeds from
    0.01 to 3 rad/s, 2^10 to 2^14 counts, 100 Hz to 1 kHz; those moving 20 steps in 2 s)
    the mean within a run was its speed to 0.001 % at the median, 0.04 % at the 99th
    percentile and 0.13 % at worst; a row, to 0.45 %, 4.7 % and 7 % (at a speed just above
    a whole count per sample, whose rounding beats more slowly than the window). Rows
    within a window of a run's ends mix in its neighbours, which steady-state detection
    trims.

    A row whose window's two halves do not move alike (:data:`SIDE_COUNTS`,
    :data:`SIDE_SHARE`: the window reaches past the run's end into a ramp or a rest) keeps
    the logged ``velocity``: near the end of a 4 s run at 0.01 rad/s through 2^12 counts at
    1 kHz, such rows had put the set-point 5.5 % slow. So does a row that does not reach
    the count within :data:`MAX_HALF_WINDOW` s (at rest, 0). Given the longest window
    instead, rows at rest beside a run read one small speed for as long as the window
    reached into the run: a steady run to the steady-state detection (a 2^10-count encoder:
    0.0092 rad/s at rest, kept as a set-point with the friction of rest). At the log's ends
    the windows are cut short (a window kept long but one-sided there made the first second
    of a log that starts at rest one flat, wrong velocity).
    """
    from scipy.ndimage import median_filter

    t = np.asarray(time, dtype=float)
    q = np.asarray(position, dtype=float)
    n = q.size
    if n < 3:
        return np.zeros(n), (1, 1)
    d = np.abs(np.diff(q))
    d = d[d > 1e-12]
    step = float(d.min()) if d.size else np.inf
    dt = float(np.median(np.diff(t)))
    top = max(round(MAX_HALF_WINDOW / dt), 1)
    ladder = [1 << k for k in range(top.bit_length()) if 1 << k < top] + [top]
    i = np.arange(n)
    level = np.full(n, len(ladder))  # the ladder's index of each row's first window
    for k, half in enumerate(ladder):  # each row's own count
        change = q[np.minimum(i + half, n - 1)] - q[np.maximum(i - half, 0)]
        level[(level == len(ladder)) & (np.abs(change) >= WINDOW_COUNTS * step)] = k
    still = level == len(ladder)
    first = np.array(ladder)[np.minimum(level, len(ladder) - 1)]
    rough = np.abs(window_slope(t, q, first))
    speed = rough.copy()
    for k, half in enumerate(ladder):  # the median speed within the row's first window
        rows = (level == k) & ~still
        if rows.any():
            speed[rows] = median_filter(rough, size=2 * half + 1, mode="nearest")[rows]
    with np.errstate(divide="ignore"):
        need = np.ceil(WINDOW_COUNTS * step / (2.0 * dt * np.maximum(speed, 1e-300)))
    wide = np.clip(need, 1, top).astype(int)
    lo, hi = np.maximum(i - wide, 0), np.minimum(i + wide, n - 1)
    left, right = (q[i] - q[lo]) / step, (q[hi] - q[i]) / step
    even = np.abs(left - right) <= np.maximum(SIDE_COUNTS, SIDE_SHARE * np.abs(left + right))
    use = ~still & even
    v = np.asarray(velocity, dtype=float).copy()
    v[use] = window_slope(t, q, wide)[use]
    moved = wide[use]
    return v, (int(moved.min()), int(moved.max())) if moved.size else (top, top)
