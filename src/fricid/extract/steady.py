"""Trust in a steady segment: settling, outliers, saturation and rest (issue 11, defects 2-4).

The BAS-RBFNN paper averages the torque of constant-velocity runs (section 2.2: "all the data
samples are obtained by averaging", with a median filter on the current). Averaging is only
right over samples that are at steady state and not corrupted. Each test here works on one
segment (the steady part of one run, :mod:`.segment`) and uses the segment's own noise as its
scale, so it adapts to any drive and sampling rate:

* :func:`settled` trims leading and trailing stretches where the velocity **or** the torque
  has not settled (ramps, overshoot, a current controller winding down), judged on block means:
  velocity against its settled level (the mode of the block means), torque against a robust
  trend (eq. 7's constant, cos and sin of position: gravity and slow changes along the
  traverse), at
  :data:`SETTLE_SIGMAS` robust standard deviations.
* :func:`outliers` flags torque samples more than :data:`OUTLIER_SIGMAS` robust standard
  deviations (1.4826 MAD) from a running median of :data:`OUTLIER_WINDOW` samples: spike
  bursts that outlast the median filter.
* :func:`saturated` flags samples pinned at the segment's extreme value (a flat top: a clipped
  sensor or a current limit).
* :func:`rest_threshold` is the speed below which a "run" is standstill, not a set-point.

Every function returns masks or indices, never modifies its input, and has no Python loop over
samples.
"""

from __future__ import annotations

import numpy as np

from ._stats import far_from_running_median, median, median_filter

__all__ = [
    "OUTLIER_SIGMAS",
    "OUTLIER_WINDOW",
    "REST_RTOL",
    "SETTLE_BLOCK",
    "SETTLE_SIGMAS",
    "outliers",
    "rest_threshold",
    "robust_scale",
    "saturated",
    "settled",
]

#: A torque sample further than this many robust standard deviations (1.4826 MAD of the
#: residuals from a running median) is an outlier. 8 sigma: Gaussian noise exceeds it with
#: probability 1e-15, so clean data lose nothing (the real lead-screw recordings' largest
#: deviation is 5.9 sigma), while a spike of 12x the nominal torque sits at hundreds of sigma.
OUTLIER_SIGMAS = 8.0

#: Samples of the running median the outlier residuals are taken from (odd): far longer than
#: a spike burst, short enough to follow the torque's slow change along a traverse.
OUTLIER_WINDOW = 31

#: s, length of the blocks whose means :func:`settled` compares (at least 3 samples).
SETTLE_BLOCK = 0.05

#: A leading or trailing block whose mean velocity or torque is further than this many robust
#: standard deviations from the segment's trend has not settled.
SETTLE_SIGMAS = 5.0

#: A run whose speed is below this fraction of the log's fastest run is at rest (float residue
#: or drift of a held joint), three decades below the fastest set-point: the papers' designs
#: span 2.7 decades at most (0.1-50 deg/s, 0.005-4 rad/s).
REST_RTOL = 1e-3

_MAD = 1.4826  # MAD to standard deviation for Gaussian noise


def robust_scale(x: np.ndarray) -> float:
    """1.4826 times the median absolute deviation of ``x`` from its median (0 for no data)."""
    x = np.asarray(x, dtype=float)
    if x.size == 0:
        return 0.0
    return _MAD * median(np.abs(x - median(x)))


def _noise_scale(x: np.ndarray) -> float:
    """Sample-to-sample noise of ``x``: 1.4826 MAD of first differences over sqrt(2)
    (insensitive to slow trends)."""
    if x.size < 3:
        return 0.0
    return robust_scale(np.diff(x)) / np.sqrt(2.0)


#: Once an end is found unsettled (beyond ``SETTLE_SIGMAS``), trimming goes on while blocks
#: stay beyond this many robust standard deviations (hysteresis: the tail of a transient is
#: trimmed too, not only its loud start).
SETTLE_RELEASE = 2.0


def _ends(z: np.ndarray, sigmas: float) -> tuple[int, int]:
    """Blocks to trim at the start and at the end, given the blocks' deviations ``z`` in
    robust standard deviations: nothing unless the end block is beyond ``sigmas``, then up to
    the first block within :data:`SETTLE_RELEASE`."""

    def run(z: np.ndarray) -> int:
        if z.size == 0 or z[0] <= sigmas:
            return 0
        within = np.flatnonzero(z <= min(SETTLE_RELEASE, sigmas))
        return int(within[0]) if within.size else z.size

    return run(z), run(z[::-1])


#: Relative resolution of the torque trend: SVD directions weaker than this share of the
#: strongest are dropped (they would only extrapolate noise), and the trend is trusted to this
#: share of the block means' spread (what a noiseless log needs).
TREND_RESOLUTION = 1e-6


def _torque_ends(
    means: np.ndarray, position: np.ndarray, floor: float, sigmas: float
) -> tuple[int, int]:
    """Leading and trailing blocks whose torque strays from the run's robust trend.

    The trend is ``c0 + c1 cos(theta) + c2 sin(theta)`` in the block's mean position
    ``theta``: eq. 7's gravity plus a friction linear in the load (eq. 12) is exactly of this
    form at constant velocity, and over a short traverse it is a quadratic in position (any
    slow change); over many turns (a lead screw's motor) a once-per-turn ripple. It is fitted
    through the SVD, directions weaker than :data:`TREND_RESOLUTION` dropped, first to the
    central 60 % of the blocks, then to every block not flagged so far (three rounds), so a
    transient at an end cannot bend the trend towards itself. The scale is the largest of
    1.4826 MAD of the fitted blocks' residuals (corrected for the fitted parameters), ``floor``
    (the noise a block mean must carry) and :data:`TREND_RESOLUTION` times the spread of the
    block means, widened at each block by the trend's own uncertainty there (its leverage), so
    an extrapolated trend is not over-trusted.
    """
    k = means.size
    x = np.linspace(-1.0, 1.0, k)
    A = np.column_stack([np.ones(k), np.cos(position), np.sin(position)])
    use = np.abs(x) <= 0.6
    lead = trail = 0
    for _ in range(3):
        U, sv, Vt = np.linalg.svd(A[use], full_matrices=False)
        r = int(np.sum(sv > TREND_RESOLUTION * sv[0]))
        proj = A @ Vt[:r].T / sv[:r]  # rows: A_i V_r S_r^-1
        resid = means - proj @ (U[:, :r].T @ means[use])
        leverage = np.sum(proj * proj, axis=1)
        m = int(use.sum())
        # the floor also covers the trend's resolution (directions dropped by the SVD)
        spread = float(np.ptp(means)) * TREND_RESOLUTION
        scale = max(robust_scale(resid[use]) * np.sqrt(m / max(m - r, 1)), floor, spread)
        lead, trail = _ends(np.abs(resid) / (scale * np.sqrt(1.0 + leverage)), sigmas)
        new = np.ones(k, dtype=bool)
        new[:lead] = False
        new[k - trail :] = False
        if new.sum() < 6 or np.array_equal(new, use):
            break
        use = new
    return lead, trail


def _near_windows(s: np.ndarray, width: float) -> tuple[np.ndarray, np.ndarray]:
    """For sorted ``s``: ``lo, hi`` such that ``abs(s[j] - s[i]) <= width`` exactly when
    ``lo[i] <= j < hi[i]``.

    In floating point ``abs(s[j] - s[i])`` is monotone along a sorted array (rounding is
    monotone and symmetric), so each ``i``'s neighbours are one contiguous window. Its edges are
    first found by ``searchsorted`` on ``s +- width`` (whose rounding may differ from the
    difference's by an ulp), then moved, a run of equal values at a time, until the exact test
    holds at both edges. O(k log k), no k x k matrix.
    """
    k = s.size
    idx = np.arange(k)

    def near(j: np.ndarray) -> np.ndarray:
        return np.abs(s[j] - s) <= width

    lo = np.searchsorted(s, s - width, side="left")
    hi = np.searchsorted(s, s + width, side="right")
    while True:  # the last neighbour is s[hi - 1]
        nxt = np.minimum(hi, k - 1)
        grow = (hi < k) & near(nxt)
        hi = np.where(grow, np.searchsorted(s, s[nxt], side="right"), hi)
        shrink = (hi > idx + 1) & ~near(hi - 1)
        hi = np.where(shrink, np.searchsorted(s, s[hi - 1], side="left"), hi)
        if not (grow.any() or shrink.any()):
            break
    while True:  # the first neighbour is s[lo]
        prev = np.maximum(lo - 1, 0)
        grow = (lo > 0) & near(prev)
        lo = np.where(grow, np.searchsorted(s, s[prev], side="left"), lo)
        shrink = (lo < idx) & ~near(lo)
        lo = np.where(shrink, np.searchsorted(s, s[lo], side="right"), lo)
        if not (grow.any() or shrink.any()):
            break
    return lo, hi


def _velocity_ends(means: np.ndarray, floor: float, sigmas: float) -> tuple[int, int]:
    """Leading and trailing blocks whose velocity is off the run's settled level.

    At constant velocity the block means are flat, so the settled level is their *mode*: the
    median of the largest cluster of block means within ``2 floor`` of one another (a creeping
    ramp or a ringing overshoot spreads its blocks over many levels; the settled stretch piles
    them on one). Blocks further than ``sigmas`` times the scale (the larger of 1.4826 MAD of
    the cluster and ``floor``) from it are unsettled.

    The cluster is centred on the first block (in time) with the most neighbours; the
    neighbours are counted on the sorted means (:func:`_near_windows`, O(k log k) for k
    blocks).
    """
    order = np.argsort(means, kind="stable")
    s = means[order]
    lo, hi = _near_windows(s, 2.0 * floor)
    count = np.empty(means.size, dtype=np.intp)
    count[order] = hi - lo
    centre = int(np.argmax(count))  # the first block in time with the most neighbours
    at = int(np.flatnonzero(order == centre)[0])
    cluster = s[lo[at] : hi[at]]
    level = median(cluster)
    scale = max(robust_scale(cluster), floor)
    return _ends(np.abs(means - level) / scale, sigmas)


def settled(
    time: np.ndarray,
    position: np.ndarray,
    velocity: np.ndarray,
    torque: np.ndarray,
    raw: np.ndarray | None = None,
    *,
    block: float = SETTLE_BLOCK,
    sigmas: float = SETTLE_SIGMAS,
) -> tuple[int, int]:
    """The settled part ``[start, stop)`` of a steady segment.

    The segment is cut into blocks of ``block`` seconds (at least 3 samples). Velocity has
    settled where its block means sit at the run's settled level (their mode,
    :func:`_velocity_ends`); torque where its block means follow the run's robust trend
    (eq. 7's constant, cos and sin of position, :func:`_torque_ends`). An end
    whose first block is beyond ``sigmas`` robust standard deviations is trimmed up to the
    first block back within :data:`SETTLE_RELEASE` (the tail of the transient goes too), for
    both signals, plus one more block (where the transient fades out, only partly clean).
    Each scale has a floor, the block mean's own noise: the larger of the sample-to-sample
    noise (from first differences of ``raw``, the unfiltered torque, default ``torque``; of the
    velocity) over the square root of the block length, and the block-to-block noise (from
    first differences of the block means, which sees correlated noise, as in a drive's
    averaged channels, and ignores a steady slope), so a noiseless or quantised trend is not
    mistaken for a transient and neither is coloured noise. Segments of fewer than 8 blocks
    are returned whole (too short to tell a trend from a transient).

    Parameters
    ----------
    time, position, velocity, torque : numpy.ndarray
        The segment's samples (s, rad, rad/s, N m; the torque median-filtered).
    raw : numpy.ndarray, optional
        N m, the unfiltered torque (sets the torque's noise floor).
    block : float
        s, block length.
    sigmas : float
        Threshold in robust standard deviations.

    Returns
    -------
    tuple of int
        ``(start, stop)`` sample indices.
    """
    n = time.size
    if n < 2:
        return 0, n
    dt = median(np.diff(time))
    w = max(3, round(block / dt)) if dt > 0 else 3
    k = n // w
    if k < 8:
        return 0, n
    raw = torque if raw is None else raw

    def blocks(x: np.ndarray, noisy: np.ndarray) -> tuple[np.ndarray, float]:
        means = x[: k * w].reshape(k, w).mean(axis=1)
        floor = max(
            _noise_scale(noisy) / np.sqrt(w),  # white noise averaged over a block
            _noise_scale(means),  # block to block: correlated noise, insensitive to a slope
            1e-12 * float(np.max(np.abs(means))),
        )
        return means, floor

    v_means, v_floor = blocks(velocity, velocity)
    t_means, t_floor = blocks(torque, raw)
    theta = position[: k * w].reshape(k, w).mean(axis=1)
    ends = [
        _velocity_ends(v_means, v_floor, sigmas),
        _torque_ends(t_means, theta, t_floor, sigmas),
    ]
    lead = max(e[0] for e in ends)
    trail = max(e[1] for e in ends)
    if lead + trail >= k:
        return 0, 0
    start = (lead + (lead > 0)) * w
    stop = n - (trail + (trail > 0)) * w if trail else n
    return start, max(stop, start)


def outliers(
    torque: np.ndarray,
    raw: np.ndarray | None = None,
    *,
    sigmas: float = OUTLIER_SIGMAS,
    window: int = OUTLIER_WINDOW,
) -> np.ndarray:
    """Boolean mask of torque samples far from their neighbours (spikes, bursts).

    The residual of each sample of ``torque`` (the median-filtered torque that is averaged)
    from a running median of ``window`` samples is compared with ``sigmas`` times the noise
    scale: 1.4826 MAD of the same residuals of the unfiltered ``raw`` torque (default:
    ``torque`` itself). The raw torque sets the scale because a median filter on quantised
    data leaves flat stretches whose MAD understates the noise. For noiseless or quantised data
    with MAD 0, the scale is the median nonzero residual; with none, nothing is an outlier.
    """
    torque = np.asarray(torque, dtype=float)
    raw = torque if raw is None else np.asarray(raw, dtype=float)
    if torque.size < 3:
        return np.zeros(torque.shape, dtype=bool)
    size = max(min(int(window), torque.size - (1 - torque.size % 2)), 1)
    noise = raw - median_filter(raw, size)
    scale = robust_scale(noise)
    if scale == 0.0:
        nonzero = np.abs(noise[noise != 0])
        if nonzero.size == 0:
            return np.zeros(torque.shape, dtype=bool)
        scale = median(nonzero)
    return far_from_running_median(torque, size, sigmas * scale)


def saturated(torque: np.ndarray, *, min_share: float = 0.01, min_count: int = 5) -> np.ndarray:
    """Boolean mask of samples pinned at the segment's largest or smallest value (a rail).

    A clipped signal piles up at its rail: the extreme value is a rail when at least
    ``max(min_count, min_share * n)`` samples equal it exactly and more than three times as
    many as equal the next value inside it (a Gaussian tail, quantised or not, thins out
    towards its extreme instead). Limitation: a segment clipped entirely (every sample on the
    rail) cannot be told from a noiseless one and is not flagged.
    """
    torque = np.asarray(torque, dtype=float)
    mask = np.zeros(torque.shape, dtype=bool)
    if torque.size < min_count:
        return mask
    need = max(min_count, int(np.ceil(min_share * torque.size)))
    top, bottom = torque.max(), torque.min()
    if top == bottom:
        return mask
    for rail, nearest in ((top, np.max), (bottom, np.min)):
        on = torque == rail
        n_rail = int(np.count_nonzero(on))
        if n_rail < need:
            continue
        after = nearest(torque[~on])  # the next value inside the rail
        if n_rail > 3 * int(np.count_nonzero(torque == after)):
            mask |= on
    return mask


def rest_threshold(max_speed: float, *, quantum: float, duration: np.ndarray) -> np.ndarray:
    """Speeds [rad/s] below which runs of the given durations [s] are standstill.

    A run is at rest when its speed is below :data:`REST_RTOL` times the log's fastest run
    (relative to the log's own velocity scale) or when it moved less than one encoder count
    ``quantum`` [rad] over its duration (the encoder saw no motion; the velocity is residue of
    a filter or of float arithmetic, e.g. 1e-15 rad/s).
    """
    duration = np.maximum(np.asarray(duration, dtype=float), 1e-12)
    return np.maximum(REST_RTOL * float(max_speed), float(quantum) / duration)
