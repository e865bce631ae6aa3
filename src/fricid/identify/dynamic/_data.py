"""Helpers of :mod:`fricid.identify.dynamic.trajectory`: a log on a uniform grid, zero-phase
derivatives, the low-speed windows of the simulation-error route, and cluster-robust
covariances.

Derivatives (the filter's choice and settings go into the result's provenance):

* ``savgol`` (default): Savitzky-Golay (Savitzky and Golay 1964), a local polynomial of
  ``order`` over ``window`` seconds, fitted to the measured position (``source="position"``,
  the default: its first and second derivatives are the velocity and the acceleration) or
  to the measured velocity (its value and derivative). Symmetric, hence zero phase.
* ``butter``: a Butterworth low-pass of ``butter_order`` at ``cutoff`` Hz run forwards and
  backwards (``scipy.signal.filtfilt``, zero phase, the order doubled) on the velocity (or the
  central difference of the position); the acceleration is the central difference of the
  filtered velocity, filtered again.

Why the position by default: a drive's velocity estimate is often noisier than its encoder,
and noise in the velocity biases the static friction (measured on the virtual joint: 0.5 %
relative velocity noise moved tau_c by -0.5 % and sigma_2 by +0.5 %, several times the
interval's half-width; from the position, with a 24-bit encoder, the bias was gone).

Covariances: residuals of a trajectory are correlated in time (the derivative filter smooths
over its window; a simulation error carries over a window), so the plain ``s^2 (J^T J)^-1``
is too narrow. :func:`cluster_covariance` is the cluster-robust (sandwich) estimate of Liang
and Zeger (1986) with contiguous blocks of samples as clusters, scaled by ``G / (G - 1)
(n - 1) / (n - p)``; each standard error is the larger of it and the plain one.

Calibration (``benchmarks/calib_trajectory.py``: the ``filtered`` route, LuGre truth, 60 s
multi-sine at 1 kHz with the trajectory noise, ``lm``, seeds 10-49: 40 logs, G = 120 blocks
of 0.5 s; the Monte-Carlo standard deviation of the estimates over the mean reported standard
error, then the 95 % intervals' coverage): sigma_2 1.05, 37/40; tau_c 1.01, 37/40; tau_s
1.02, 39/40; w_s 1.01, 39/40; delta 1.02, 38/40; J 1.01, 38/40; p_x 0.99, 37/40; p_y 0.98,
39/40; sigma_0 and sigma_1 (log10) 0.75 and 0.70, 40/40 each (their mean errors, +0.64 and
-0.90 Monte-Carlo standard deviations, are the break-away bias of :mod:`._trajectory_rate`);
270/280 LuGre intervals covered. The Stribeck parameters' intervals are not too narrow. The
cluster jackknife linearised at the optimum (CR3: Cameron and Miller 2015; MacKinnon,
Nielsen and Webb 2023; ``bread . sum_g J_g' (I - H_gg)^-1 r_g r_g' (I - H_gg)^-1 J_g .
bread . (G - 1) / G``) was tried on the same 40 logs: its standard errors were 1.005-1.015
times CR1's (no block holds much leverage) and every parameter's coverage was unchanged, so
it was not kept.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from ...errors import ConfigError, DataError
from ...samples import RawLog
from ..static.uncertainty import covariance_svd, floored_covariance

__all__ = [
    "FILTERS",
    "DerivativeFilter",
    "Series",
    "cluster_covariance",
    "derivatives",
    "low_speed_windows",
    "rest_share",
    "sliding",
    "temperature_range",
    "torque_noise",
    "uniform_series",
]

#: Derivative filters.
FILTERS = ("savgol", "butter")

#: The guard after a slow stretch is at most this share of the median sliding stretch, for
#: the static models (:func:`sliding`).
GUARD_SHARE = 0.25

#: Largest relative deviation of a sample period from the median before the log is resampled.
JITTER = 0.01


@dataclass(frozen=True)
class DerivativeFilter:
    """How the velocity is smoothed and differentiated (see the module notes).

    ``window`` [s] and ``order`` for ``savgol``; ``cutoff`` [Hz] and ``butter_order`` for
    ``butter``.
    """

    method: str = "savgol"
    source: str = "position"
    window: float = 0.021
    order: int = 3
    cutoff: float = 40.0
    butter_order: int = 4

    def __post_init__(self) -> None:
        if self.method not in FILTERS:
            raise ConfigError(f"unknown derivative filter '{self.method}'; one of: savgol, butter")
        if self.source not in ("position", "velocity"):
            raise ConfigError(
                f"derivative source must be position or velocity, got '{self.source}'"
            )
        if not (self.window > 0 and self.cutoff > 0 and self.order >= 2 and self.butter_order >= 1):
            raise ConfigError("derivative filter: window and cutoff > 0, order >= 2")

    def describe(self, rate: float) -> dict[str, Any]:
        """The settings, as recorded in provenance (window also in samples)."""
        d = asdict(self)
        keep = (
            ("method", "source", "window", "order")
            if self.method == "savgol"
            else ("method", "source", "cutoff", "butter_order")
        )
        out = {k: d[k] for k in keep}
        if self.method == "savgol":
            out["window_samples"] = self.samples(rate)
        out["zero_phase"] = True
        return out

    def samples(self, rate: float) -> int:
        """The Savitzky-Golay window in samples: odd, above the order."""
        m = max(round(self.window * rate), self.order + 2)
        return m if m % 2 else m + 1


@dataclass(frozen=True)
class Series:
    """A log on a uniform time grid: time, position, velocity, torque, temperature."""

    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    torque: np.ndarray
    temperature: np.ndarray
    dt: float
    resampled: bool


def uniform_series(log: RawLog) -> Series:
    """The log's columns on a uniform grid (linear interpolation at the median period when
    any period deviates from it by more than :data:`JITTER`, as bag stamps do)."""
    t = log.time
    if t.size < 16:
        raise DataError(f"a trajectory needs at least 16 samples, got {t.size}", file=log.source)
    steps = np.diff(t)
    dt = float(np.median(steps))
    cols = (log.position, log.velocity, log.motor_torque, log.temperature)
    if np.max(np.abs(steps - dt)) <= JITTER * dt:
        return Series(t, *cols, dt=dt, resampled=False)
    grid = t[0] + dt * np.arange(int(np.floor((t[-1] - t[0]) / dt)) + 1)
    return Series(grid, *(np.interp(grid, t, c) for c in cols), dt=dt, resampled=True)


def temperature_range(log: RawLog, series: Series) -> dict[str, list[float]]:
    """``{"temperature": [low, high]}`` [degC] of the log for a model's operating range; empty
    for a log that logged none (its column a placeholder: :attr:`RawLog.temperature_measured`)."""
    if not log.temperature_measured:
        return {}
    return {"temperature": [float(series.temperature.min()), float(series.temperature.max())]}


def derivatives(series: Series, filt: DerivativeFilter) -> tuple[np.ndarray, np.ndarray]:
    """Smoothed velocity and acceleration ``(n,)`` by the zero-phase filter ``filt``."""
    from scipy import signal

    v = series.velocity
    rate = 1.0 / series.dt
    if filt.method == "savgol":
        m = filt.samples(rate)
        if m > v.size:
            raise DataError(f"the log ({v.size} samples) is shorter than the filter window ({m})")
        if filt.source == "position":
            q = series.position
            vf = signal.savgol_filter(q, m, filt.order, deriv=1, delta=series.dt)
            a = signal.savgol_filter(q, m, filt.order, deriv=2, delta=series.dt)
            return vf, a
        vf = signal.savgol_filter(v, m, filt.order)
        a = signal.savgol_filter(v, m, filt.order, deriv=1, delta=series.dt)
        return vf, a
    if filt.source == "position":
        v = np.gradient(series.position, series.dt)
    nyq = 0.5 * rate
    if filt.cutoff >= nyq:
        raise ConfigError(f"Butterworth cutoff {filt.cutoff} Hz is not below Nyquist ({nyq} Hz)")
    b, a_ = signal.butter(filt.butter_order, filt.cutoff / nyq)
    vf = signal.filtfilt(b, a_, v)
    acc = signal.filtfilt(b, a_, np.gradient(vf, series.dt))
    return vf, acc


def sliding(
    series: Series, filt: DerivativeFilter, v_slide: float, guard: float, *, short: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The derivatives (:func:`derivatives`) and the samples that slide: ``|v| >= v_slide``
    away from the stretches below it and from every reversal (by half the filter's window
    before, and ``guard`` seconds or that after), the filter's extrapolated edges left out.
    A reversal between two samples both faster than ``v_slide`` counts: a new user's log
    reversing at 40 rad/s^2 had none below 0.02 rad/s, and the bristles' transient after it
    (1.6 N m of a 2 N m torque for two samples) was graded as sliding.

    ``short``: the guard is at most :data:`GUARD_SHARE` of the median stretch between two
    slow ones. A joint oscillating at 2-5 Hz through 36 encoder counts slows down every 0.1 s,
    and a 0.2 s guard had left 114 of 20001 samples (a static fit of them gave f_c = 278 N m
    for 0.3, with caveats only); a friction transient after a reversal lasts the bristles'
    time, milliseconds, not the motion's."""
    rate = 1.0 / series.dt
    vf, acc = derivatives(series, filt)
    half = filt.samples(rate) // 2 if filt.method == "savgol" else int(rate / filt.cutoff)
    below = np.abs(vf) < v_slide
    # a reversal is slow however fast it is: where the velocity changes sign between two
    # samples without one below v_slide (40 rad/s^2 at 1 kHz crosses 0.02 rad/s within a
    # sample), both samples count as below, so its guard is kept too
    flip = np.signbit(vf[1:]) != np.signbit(vf[:-1])
    below[1:] |= flip
    below[:-1] |= flip
    after = round(guard * rate)
    stretches = [b - a for a, b in runs(~dilate(below, half, half))] if short else []
    if stretches:
        after = min(after, round(GUARD_SHARE * float(np.median(stretches))))
    mask = ~dilate(below, half, max(half, after))
    mask[:half], mask[mask.size - half :] = False, False
    return vf, acc, mask


def guarded_sliding(
    series: Series, filt: DerivativeFilter, v_slide: float, guard: float, short: bool, least: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool, int]:
    """:func:`sliding`, and with ``short`` guards when the full ones leave fewer than
    ``least`` of the samples faster than ``v_slide`` (slips shorter than the guard: fricid's
    own stick-slip log, whose 0.2 s guard after each stick had left none, went to the
    pre-sliding route); also whether the guards were cut short and how many samples move
    faster than ``v_slide`` before the guards."""
    vf, acc, mask = sliding(series, filt, v_slide, guard, short=short)
    moving = int(np.sum(np.abs(vf) >= v_slide))
    if mask.sum() < least <= moving and not short:
        short = True
        vf, acc, mask = sliding(series, filt, v_slide, guard, short=short)
    return vf, acc, mask, short, moving


def dilate(mask: np.ndarray, before: int, after: int) -> np.ndarray:
    """``mask`` grown by ``before`` samples to the left and ``after`` to the right."""
    out = mask.copy()
    idx = np.flatnonzero(mask)
    n = mask.size
    for shift in range(1, max(before, after) + 1):
        if shift <= before:
            out[np.clip(idx - shift, 0, n - 1)] = True
        if shift <= after:
            out[np.clip(idx + shift, 0, n - 1)] = True
    return out


def runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """The ``[start, stop)`` index ranges where ``mask`` is True."""
    m = np.concatenate([[False], mask, [False]]).astype(np.int8)
    d = np.diff(m)
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1), strict=True))


#: :func:`rest_share`: the speed [rad/s] below which the joint rests, the shortest rest [s],
#: and the Savitzky-Golay window [s] of its velocity (order 3, at least 7 samples).
REST_SPEED = 0.02
REST_MIN = 0.1
REST_WINDOW = 0.021


def rest_share(series: Series) -> float:
    """The share of the log's time the joint rests: stretches of at least :data:`REST_MIN`
    seconds with the speed below :data:`REST_SPEED`, the velocity a Savitzky-Golay derivative
    of the position (its own window, :data:`REST_WINDOW`, so that the share does not depend
    on the fit's derivative settings). It chooses LuGre's calibrated widening
    (:func:`fricid.identify.dynamic._outcome.widen_calibrated`). On
    tuning logs of ``benchmarks/bench_lugre.py`` (seeds 0-5, 10 s, as the fit reads them):
    PD-tracked chirps 0-0.08, trapezoids with their dwells 0.27-0.59, open-loop torque steps
    0-0.10 or 0.24-0.76; on the shared foreign logs, another simulator's, trapezoids 0.15."""
    from scipy.signal import savgol_filter

    q, dt = np.asarray(series.position, dtype=float), float(series.dt)
    window = max(round(REST_WINDOW / dt) | 1, 7)
    if q.size < window:
        return 0.0
    v = savgol_filter(q, window, 3, deriv=1, delta=dt)
    rests = [b - a for a, b in runs(np.abs(v) < REST_SPEED) if (b - a) * dt >= REST_MIN]
    return float(sum(rests)) / q.size


def low_speed_windows(
    speed: np.ndarray, threshold: float, before: int, after: int, longest: int
) -> list[tuple[int, int, int]]:
    """Windows around the stretches with ``speed < threshold``, grown by ``before`` and
    ``after`` samples and cut into segments of at most ``longest``: ``(start, stop, window)``
    with ``[start, stop)`` a segment and ``window`` the number of the window it belongs to."""
    out = []
    for w, (start, stop) in enumerate(runs(dilate(speed < threshold, before, after))):
        for s in range(start, stop, longest):
            if min(stop, s + longest) - s >= 4:
                out.append((s, min(stop, s + longest), w))
    return out


def blocks(n: int, length: int) -> np.ndarray:
    """Cluster labels of ``n`` samples in contiguous blocks of ``length``."""
    return np.arange(n) // max(int(length), 1)


def cluster_covariance(
    J: np.ndarray, r: np.ndarray, labels: np.ndarray
) -> tuple[np.ndarray, np.ndarray, int]:
    """Cluster-robust covariance of least-squares estimates (module notes).

    Parameters
    ----------
    J : ndarray (n, p)
        Jacobian of the residuals at the optimum.
    r : ndarray (n,)
        Residuals there.
    labels : ndarray (n,)
        Cluster of each residual.

    Returns
    -------
    cov : ndarray (p, p)
        Covariance (NaN rows and columns for undetermined parameters), its diagonal raised to
        the plain estimate's where that is larger. The determined parameters' covariance is
        taken with the others held at their estimates (a Stribeck law fitted to a log without
        a rise leaves ``w_s`` and ``delta`` without effect; their NaN rows had made every
        standard error NaN, J's and the gravity's too).
    stderr : ndarray (p,)
    clusters : int
        The number of clusters G (the t quantile takes G - 1 degrees of freedom).
    """
    n, p = J.shape
    dof = max(n - p, 1)
    plain, determined = covariance_svd(J, float(r @ r) / dof)
    if 0 < determined.sum() < p:
        sub, sub_se, g = cluster_covariance(J[:, determined], r, labels)
        cov, se = np.full((p, p), np.nan), np.full(p, np.nan)
        cov[np.ix_(determined, determined)], se[determined] = sub, sub_se
        return cov, se, g
    bread, _ = covariance_svd(J, 1.0)
    uniq, inv = np.unique(labels, return_inverse=True)
    g = len(uniq)
    scores = np.zeros((g, p))
    np.add.at(scores, inv, J * r[:, None])
    meat = scores.T @ scores
    scale = g / max(g - 1, 1) * (n - 1) / dof
    with np.errstate(invalid="ignore"):
        cov = scale * bread @ meat @ bread
    cov, se = floored_covariance(cov, np.diag(plain), determined)
    return cov, se, g


def torque_noise(u: np.ndarray) -> float:
    """The torque's white-noise level [N m]: the median absolute deviation of its sample
    differences over sqrt(2) (a smooth signal's differences are far smaller)."""
    d = np.diff(u)
    return float(1.4826 * np.median(np.abs(d - np.median(d))) / np.sqrt(2.0))


#: A Coulomb level this many cluster-robust standard errors below zero is a reversed sign.
REVERSED_T = 5.0


def check_dissipates(
    series: Series, vf: np.ndarray, acc: np.ndarray, mask: np.ndarray, cluster_n: int, source
) -> None:
    """Refuse a log whose torque works against its own friction (a reversed sign).

    Friction dissipates, so on the sliding samples (``mask``) the torque left after inertia
    and gravity has the velocity's sign. The linear regression ``u = J a + p_x cos q - p_y
    sin q + c + F_c sign(v) + F_v v`` (no bounds, cluster-robust errors over blocks of
    ``cluster_n``) gives ``F_c`` far below zero (:data:`REVERSED_T` standard errors) only
    when the torque's sign, or the position's and velocity's, is reversed; a bounded fit
    would then clamp the friction to 0 and fit nothing, with a verdict of caveats.

    Raises
    ------
    DataError
        Naming ``source``, the Coulomb and viscous levels found and what to flip.
    """
    v, q, u = vf[mask], series.position[mask], series.torque[mask]
    if v.size < 8:
        return
    A = np.column_stack([acc[mask], np.cos(q), np.sin(q), np.ones_like(v), np.sign(v), v])
    theta, *_ = np.linalg.lstsq(A, u, rcond=None)
    _cov, se, _g = cluster_covariance(A, u - A @ theta, blocks(v.size, cluster_n))
    f_c, f_v = float(theta[4]), float(theta[5])
    if not (np.isfinite(se[4]) and se[4] > 0 and f_c < -REVERSED_T * se[4]):
        return
    raise DataError(
        f"the torque works against friction: after inertia and gravity it has the opposite "
        f"sign to the velocity (a linear fit gives a Coulomb level of {f_c:.3g} +- "
        f"{se[4]:.2g} N m and a viscous one of {f_v:.3g} N m s/rad; friction only "
        "dissipates): the torque's (or current's) sign, or the position's and the "
        "velocity's, is reversed; flip one",
        file=source,
    )
