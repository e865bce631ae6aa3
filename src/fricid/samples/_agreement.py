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
:func:`windowed_velocity` gives the velocity to use instead: the position's difference over a
window long enough for its counts to resolve the log's slowest runs.
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
#: Relative tolerance for a known unit factor (the nearest one; 57.3 and 60 are 4.7 % apart).
FACTOR_TOLERANCE = 0.02


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
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
    edges = np.unique(np.linspace(0, n - 1, min(WINDOWS, n // 2) + 1).astype(int))
    dq, di = np.diff(q[edges]), np.diff(integral[edges])
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
            f"{small}, or the {small} as much too small)"
        )
    if scale < 0 and abs(size - 1.0) <= 1.0 - AGREEMENT[0]:
        return "one of the two columns has its sign reversed"
    return (
        f"{sign}a factor that is no known unit: a gear ratio between a motor-side and a "
        "joint-side channel, or a wrong unit or scale"
    )


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
#: A velocity reading 0 at this share of the rows where the position moves is coarse.
COARSE_ZEROS = 0.3


def coarse_velocity(time, position, velocity) -> str | None:
    """What is wrong when the velocity is a coarse encoder's finite difference, else None.

    Such a velocity is a whole number of ``step / dt`` (or half that, central differences)
    and reads 0 between steps while the joint moves slowly, so steady-state detection takes
    slow runs for rest. Judged where the position changes by a step or more over
    ``2`` :data:`MOVE_WINDOW` rows: when the velocity is 0 at over :data:`COARSE_ZEROS` of
    them and its non-zero values are such multiples (90 % within 1 %).
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
    if zeros <= COARSE_ZEROS or whole < 0.9:
        return None
    return (
        f"the velocity is the position's finite difference at a coarse encoder (steps of "
        f"{step:.3g} rad at {1 / dt:.4g} Hz): it reads 0 at {100 * zeros:.0f} % of the rows "
        "where the joint moves, so slow runs look like rest; log the drive's velocity "
        "estimate, or a position with more counts per turn"
    )


#: Encoder steps each row's window spans (one step is then at most 5 % of the row's
#: velocity). Tuned on a new-user trial's campaign (2^12 counts at 250 Hz, gravity, six
#: speeds, 2 s runs at 0.066 rad/s), checked on ``tests/extract``'s own generator. On the
#: trial's campaign 20 gave the clean log's six set-points within 0.02 %; 50, four (the
#: slow runs' plateaus lost, a spurious one at 0.004 rad/s); 10, seven (0.6 rad/s split in
#: two, frictions 0.066 and 0.080 against 0.088); 5, six but 0.069 rad/s for 0.066.
WINDOW_COUNTS = 20
#: The longest half-window [s] (rows slower than ``WINDOW_COUNTS`` steps in it: rest, or
#: nearly).
MAX_HALF_WINDOW = 2.0


def window_difference(t: np.ndarray, q: np.ndarray, half: np.ndarray) -> np.ndarray:
    """``(q[i + h] - q[i - h]) / (t[i + h] - t[i - h])`` with each row's half-window ``h``
    (``half``), cut short at the ends."""
    i = np.arange(q.size)
    lo, hi = np.maximum(i - half, 0), np.minimum(i + half, q.size - 1)
    span = t[hi] - t[lo]
    return np.divide(q[hi] - q[lo], span, out=np.zeros(q.size), where=span > 0)


def windowed_velocity(time, position, velocity) -> tuple[np.ndarray, tuple[int, int]]:
    """The velocity as the position's difference over a window per row, and the shortest and
    longest half-windows used [rows].

    The M/T method of encoder speed measurement: each row's window spans
    :data:`WINDOW_COUNTS` encoder steps, so one step is at most 5 % of the velocity. A row's
    window is found in two passes: the shortest of 1, 2, 4, ... rows each side over which
    the position changes by that many steps gives a rough speed; its median over that
    window gives the half-window ``ceil(WINDOW_COUNTS step / (2 dt speed))``. Chosen by each
    row's own count instead, a run whose speed sits near a threshold had rows that reach
    the count by a quantisation step and rows that miss it, and the run's mean came out 1 %
    fast (a 2^10-count encoder at 0.94 rad/s). The choice still depends on the quantised
    position, so a run at a speed where the window flips between two lengths keeps a small
    bias: over 1,563 runs (200 speeds from 0.01 to 3 rad/s, 2^10 to 2^14 counts, 100 Hz to
    1 kHz; those moving 20 steps in 2 s) the mean within a run was its speed to 0.001 % at
    the median, 0.16 % at the 99th percentile and 1.2 % at worst (0.064 rad/s through 2^10
    counts at 1 kHz: 21 steps in the longest window). A mean over four windows instead of
    the median did as well on that grid (0.69 % at worst) but split runs of one speed on a
    2^12-count campaign with gravity into set-points 4 % apart. Rows within a window of a
    run's ends mix in its neighbours, which steady-state detection trims.

    A row that does not reach the count within :data:`MAX_HALF_WINDOW` s keeps the logged
    ``velocity`` (at rest, 0). Given the longest window instead, rows at rest beside a run
    read one small speed for as long as the window reached into the run: a steady run to the
    steady-state detection (a 2^10-count encoder: 0.0092 rad/s at rest, kept as a set-point
    with the friction of rest). At the log's ends the windows are cut short (a window kept
    long but one-sided there made the first second of a log that starts at rest one flat,
    wrong velocity).
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
    rough = np.abs(window_difference(t, q, first))
    speed = rough.copy()
    for k, half in enumerate(ladder):  # the median speed within the row's first window
        rows = (level == k) & ~still
        if rows.any():
            speed[rows] = median_filter(rough, size=2 * half + 1, mode="nearest")[rows]
    with np.errstate(divide="ignore"):
        need = np.ceil(WINDOW_COUNTS * step / (2.0 * dt * np.maximum(speed, 1e-300)))
    wide = np.clip(need, 1, top).astype(int)
    v = np.asarray(velocity, dtype=float).copy()
    v[~still] = window_difference(t, q, wide)[~still]
    moved = wide[~still]
    return v, (int(moved.min()), int(moved.max())) if moved.size else (top, top)
