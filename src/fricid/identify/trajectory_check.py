"""A model identified from a trajectory, run along a log: predicted against measured torque.

:func:`predict_trajectory` evaluates the equation of motion of
:mod:`fricid.identify.dynamic.trajectory` (there, fricid's sign convention)::

    u = J qdd + f(qd, state) - (p_x cos q - p_y sin q)

along a log with the fitted J, p_x, p_y (``provenance["trajectory"]["joint"]``) and friction
law, as the ``filtered`` route does, without its low-pass: over each sample period (the drive
holds the torque ``u_{i-1}`` over the period ending at sample ``i``) the friction is the law's
exact period mean with the bristle state (LuGre) or friction state (Dahl) driven by the
measured motion (the cubic Hermite interpolant of the measured positions and velocities,
``n_sub`` sub-steps per period, from the steady state at the first sample:
:data:`fricid.identify.dynamic._filtered.LUGRE`, ``DAHL``), gravity at the period's mid
position, and the acceleration the mean over the period of the fit's own derivative filter's
(``provenance["trajectory"]["derivative"]``: the regression's). A static law (``stribeck``,
``coulomb_viscous`` from a trajectory) is run as its regression ran: the torque ``u_i``
against the state at sample ``i`` (the filter's velocity and acceleration there, gravity at
``q_i``). It was the filtered route's period means, which at 100 Hz put half a period of
torque change into the error: a ``stribeck`` fit whose residual was 0.038 N m where it slides
read 0.247 N m there (a 10 s multi-sine of the virtual joint decimated to 100 Hz). The measured
friction is the torque with the inertia and gravity terms removed, ``u - J qdd + p_x cos q -
p_y sin q``: the model's friction against it is the hysteresis a report draws.

The acceleration was the difference over the period of the filtered velocity. That
difference passes the encoder's steps the filter's second derivative smooths: on a 4096-count
log whose static fit had every interval holding the truth (residual RMS 0.030 N m where it
slides, torque noise 5 mN m), the report gave 0.196 N m, 37 % of the RMS torque, against
0.064 with the filter's acceleration (``tests/identify/test_trajectory_check.py``).

The error is also given on the samples the regression route fits, those sliding away from
the slow stretches (:func:`fricid.identify.dynamic._data.sliding` with the fit's speed and the
default guard: ``TrajectoryPrediction.sliding``): a static law has no break-away to follow,
and its error there is the one its fit reports.

The raw residual holds the measurement noise and, at every break-away, the derivative
filter's smoothing of the acceleration's jump (on the virtual joint's 10 s multi-sine at
1 kHz: median |residual| 4 mN m, 99th percentile 0.26 N m, at 0.05-0.1 rad/s just after the
reversals). So the prediction also carries both sides low-passed by the fit's parallel filter
(``provenance["trajectory"]["parallel_filter"]``: Butterworth, zero phase, its start-up
trimmed; NaN there), the residual the ``filtered`` route minimised: at the estimate its RMS is
the route's (``tests/identify/test_trajectory_check.py``).

Reversals are where the filtered velocity changes sign; :meth:`TrajectoryPrediction.reversals`
gives, per reversal, the samples around it slower than a fraction of the log's largest speed
(the pre-sliding and break-away region), for loops of friction against velocity and against
the position travelled since the reversal.

On a second log (held-out validation) the same function gives the error of a model on data it
was not identified from; nothing is refitted.

The verdict graded on a second log (:func:`heldout_trust`; ``fricid report MODEL LOG
HELDOUT``). ``fricid fit --trajectory`` has nothing to hold out and no repeated set-points
to measure the torque's scatter with, so its verdict stays "with caveats" ("no measurement
scatter to compare the error with"). A second log the model was not identified from gives
both:

- the held-out error: the RMS torque error of the model run along it
  (:func:`predict_trajectory`, nothing refitted), on the
  samples a static law claims (sliding away from the slow stretches:
  ``TrajectoryPrediction.sliding``). A dynamic law (LuGre, Dahl) is graded there too, with a
  caveat that its pre-sliding is not: the raw error at the reversals is the derivative
  filter's smoothing of the acceleration's jump more than the model's (the virtual joint's
  10 s multi-sine, a LuGre fit whose low-passed held-out error was 1.0 mN m: 80 mN m on every
  sample, 16 times the scatter, 4.9 mN m where it slides);
- the scatter: the torque's own sample-to-sample scatter on the same log's sliding samples,
  from its second differences (``u[k+1] - 2 u[k] + u[k-1]`` has variance ``6 sigma^2`` for
  white noise of ``sigma``; the motion's own share at 1 kHz is negligible), robustly (the
  median absolute deviation, so the steps of break-away do not inflate it). A torque
  low-passed before it was logged hides its noise from second differences (a 5 Hz low-pass:
  7.5e-5 N m, which read as a 1,550-fold miss); its third differences then fall far below
  what noise gives beside the second ones (:func:`_smooth_share`), and such a log is not
  graded, with the reason.

The verdict says which samples were graded (``Trust.heldout_scheme``: a static law's error
below them, in the Stribeck region, is not graded; the independent simulator's PD-tracked chirp
at 2^20 counts/rev (``../shared/data/foreign/lugre``), whose Stribeck velocity is 0.02 rad/s: a
``coulomb_viscous`` fit from its trapezoid run along it, 0.032 N m where it slides, as the
truth's LuGre law, against a scatter of 0.043 N m, the drive's own sample-to-sample torque,
four times the logged noise). On those logs
(``tests/identify/test_trajectory_heldout_trust.py``'s setup: the truth's steady-state law with
its joint, run along each) the ratio was 0.74-0.75 on the chirps and 1.26-1.28 on the
trapezoids (both encoders); with the Coulomb level 5 % high, 1.02 and 1.84; 30 % high, 4.3 and
8.1. The ratio of the two is graded with the thresholds of every other verdict
(:mod:`fricid.identify.trust`: within ``NOISE_RATIO`` "yes" as far as the error goes, beyond
``MISS_RATIO`` "no"), with the file's own reasons (convergence, determination) kept.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from ..errors import DataError
from ..fitted import FittedModel
from ..metrics import verdict
from ..samples import RawLog, check_trajectory_log
from ._scatter import SECOND_DIFFERENCES
from .dynamic._data import DerivativeFilter, sliding, uniform_series
from .dynamic._filtered import DAHL, LUGRE, LUGRE_ASYM, _sub_velocity
from .trust import SECOND_LOG, Trust, _grade

__all__ = [
    "DYNAMIC",
    "MIN_GRADED",
    "MIN_SHARE",
    "MIN_TRIPLES",
    "PRESLIDING_UNGRADED",
    "REVERSAL_SPEED",
    "WHITE_SHARE",
    "TrajectoryPrediction",
    "heldout_grading",
    "heldout_trust",
    "is_trajectory_model",
    "predict_trajectory",
    "torque_scatter",
]

#: A reversal's neighbourhood: speeds below this fraction of the log's largest speed.
REVERSAL_SPEED = 0.1


def is_trajectory_model(fitted: FittedModel) -> bool:
    """Whether ``fitted`` was identified from a trajectory (its joint's J is recorded)."""
    info = (fitted.provenance or {}).get("trajectory")
    return isinstance(info, dict) and isinstance(info.get("joint"), dict)


@dataclass(frozen=True)
class TrajectoryPrediction:
    """A model along a log, one entry per sample period (samples 1 to n - 1 of the log).

    Attributes
    ----------
    source : the log's file (or None).
    time : s, the end of each period.
    position, velocity, acceleration : rad, rad/s, rad/s^2: the period's mid position, the
        filtered velocity at its end and the acceleration over it.
    torque, predicted : N m, the measured torque held over the period and the model's.
    friction, friction_predicted : N m, the measured friction (torque less inertia and
        gravity) and the model's.
    torque_filtered, predicted_filtered : N m, both sides low-passed by the fit's parallel
        filter (NaN in its trimmed start-up, and everywhere when the fit recorded none).
    cutoff : Hz, that filter's cut-off (NaN without one).
    sliding : bool, the periods the regression route fits (sliding, away from slow stretches).
    """

    source: str | None
    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    torque: np.ndarray
    predicted: np.ndarray
    friction: np.ndarray
    friction_predicted: np.ndarray
    torque_filtered: np.ndarray
    predicted_filtered: np.ndarray
    cutoff: float = math.nan
    sliding: np.ndarray | None = None

    @property
    def residual(self) -> np.ndarray:
        """Measured minus predicted torque [N m] (also the friction's residual)."""
        return self.torque - self.predicted

    @property
    def residual_filtered(self) -> np.ndarray:
        """The low-passed residual [N m] (NaN where the filter is trimmed)."""
        return self.torque_filtered - self.predicted_filtered

    def metrics(self) -> dict[str, float]:
        """``n``; ``rmse``, ``max_abs_error``, ``median_abs_error`` [N m] of the raw
        residual; ``signal_rms`` [N m] (of the measured torque about its mean) and
        ``relative`` (``rmse`` over it); ``fitness`` (R^2); ``rmse_filtered`` [N m], the
        low-passed residual's (NaN without a filter); ``rmse_sliding`` [N m] and
        ``n_sliding``, the raw residual's on the periods the regression fits (NaN, 0 when
        none slide)."""
        r = self.residual
        rmse = float(np.sqrt(np.mean(r**2)))
        spread = float(np.std(self.torque))
        rf = self.residual_filtered
        rf = rf[np.isfinite(rf)]
        rs = r[self.sliding] if self.sliding is not None else r[:0]
        return {
            "n": float(r.size),
            "rmse": rmse,
            "median_abs_error": float(np.median(np.abs(r))),
            "max_abs_error": float(np.max(np.abs(r))),
            "signal_rms": spread,
            "relative": rmse / spread if spread > 0 else math.nan,
            "fitness": 1.0 - (rmse / spread) ** 2 if spread > 0 else math.nan,
            "rmse_filtered": float(np.sqrt(np.mean(rf**2))) if rf.size else math.nan,
            "rmse_sliding": float(np.sqrt(np.mean(rs**2))) if rs.size else math.nan,
            "n_sliding": float(rs.size),
        }

    def reversals(self, speed: float = REVERSAL_SPEED) -> list[np.ndarray]:
        """Per velocity reversal, the indices of the contiguous samples around it slower than
        ``speed`` times the largest ``|velocity|`` (a reversal inside a stretch of rest
        counts once)."""
        v = self.velocity
        slow = np.abs(v) < speed * float(np.max(np.abs(v)))
        sign = np.sign(v)
        flips = np.flatnonzero(sign[1:] * sign[:-1] < 0) + 1
        out: list[np.ndarray] = []
        for k in flips:
            if not slow[k]:
                continue
            lo = k
            while lo > 0 and slow[lo - 1]:
                lo -= 1
            hi = k
            while hi + 1 < v.size and slow[hi + 1]:
                hi += 1
            if out and out[-1][-1] >= lo:
                continue
            out.append(np.arange(lo, hi + 1))
        return out


def _joint(fitted: FittedModel, source: str | None) -> tuple[float, float, float]:
    if not is_trajectory_model(fitted):
        raise DataError(
            f"model '{fitted.model}' was not identified from a trajectory (its file holds no "
            "joint inertia and gravity): a log needs a model from `fricid fit --trajectory`",
            file=source,
        )
    if fitted.provenance["trajectory"].get("route") == "presliding":
        raise DataError(
            "the model was identified by the pre-sliding route (a log that never slides), "
            "which does not determine J, p_x, p_y or the sliding friction: no torque along a "
            "log can be predicted from it (what it determines is in its parameter records and "
            "provenance['trajectory']['presliding'])",
            file=source,
        )
    joint = fitted.provenance["trajectory"]["joint"]

    def value(name: str) -> float:
        row = joint.get(name)
        return float(row["value"]) if isinstance(row, dict) else 0.0

    return value("inertia"), value("p_x"), value("p_y")


def _derivative_filter(info: dict[str, Any]) -> DerivativeFilter:
    recorded = info.get("derivative") or {}
    names = {f.name for f in fields(DerivativeFilter)}
    return DerivativeFilter(**{k: v for k, v in recorded.items() if k in names})


def _friction(fitted: FittedModel, series, velocity: np.ndarray, n_sub: int) -> np.ndarray:
    """The model's mean friction over each period, entry ``i`` the period ending at ``i``."""
    name = str(fitted.model).strip().lower()
    laws = {"lugre": LUGRE, "lugre_asym": LUGRE_ASYM, "dahl": DAHL}
    if name in laws:
        law = laws[name]
        theta = np.array([[float(fitted.params[k]) for k in law.names]])
        v_sub = _sub_velocity(series, n_sub)
        return law.mean_friction(theta, v_sub, series.dt, n_sub)[0]
    X = np.column_stack([velocity, np.zeros_like(velocity), series.temperature])
    return np.asarray(fitted.predict(X, warn=False), dtype=float)


def predict_trajectory(fitted: FittedModel, log: RawLog) -> TrajectoryPrediction:
    """Run ``fitted`` (identified from a trajectory) along ``log`` (module docstring).

    Raises
    ------
    DataError
        ``fitted`` holds no joint from a trajectory fit, the log is too short, or it fails
        the fit's own checks (:func:`fricid.samples.check_trajectory_log`: a column's unit or
        sign, holes in the time).
    """
    source = None if log.source is None else str(log.source)
    J, p_x, p_y = _joint(fitted, source)
    check_trajectory_log(log)  # as the fit checks it: a unit, a sign, a hole in the time
    info = fitted.provenance["trajectory"]
    series = uniform_series(log)
    static = str(fitted.model).strip().lower() not in DYNAMIC
    v_slide = float(info.get("v_slide") or 0.02)
    v, a, slides = sliding(series, _derivative_filter(info), v_slide, 0.2, short=static)
    n_sub = max(int(info.get("n_sub") or 4), 1)
    friction_all = _friction(fitted, series, v, n_sub)
    friction = friction_all[1:]
    q = series.position
    if static:  # at the samples, as the regression: u_i against the state at sample i
        q_mid, acc, u = q[1:], a[1:], series.torque[1:]
    else:  # the period's means, as the filtered route: u held over the period it ends
        q_mid, acc, u = 0.5 * (q[1:] + q[:-1]), 0.5 * (a[1:] + a[:-1]), series.torque[:-1]
    gravity = -(p_x * np.cos(q_mid) - p_y * np.sin(q_mid))
    low = _low_pass(info.get("parallel_filter"), series.dt, u.size + 1)
    if low is None:
        u_f = p_f = np.full(u.size, np.nan)
        cutoff = math.nan
    else:
        apply, cutoff = low
        q_mid_all = np.concatenate([q[:1], q_mid])
        u_all = np.concatenate([series.torque[:1], u]) if not static else series.torque
        acc_f = np.diff(np.gradient(apply(q), series.dt)) / series.dt
        gravity_f = -(p_x * apply(np.cos(q_mid_all)) - p_y * apply(np.sin(q_mid_all)))
        u_f = apply(u_all)[1:]
        p_f = J * acc_f + apply(friction_all)[1:] + gravity_f[1:]
    return TrajectoryPrediction(
        source=source,
        time=series.time[1:],
        position=q_mid,
        velocity=v[1:],
        acceleration=acc,
        torque=u,
        predicted=J * acc + friction + gravity,
        friction=u - J * acc - gravity,
        friction_predicted=friction,
        torque_filtered=u_f,
        predicted_filtered=p_f,
        cutoff=cutoff,
        sliding=slides[1:] if static else slides[1:] & slides[:-1],
    )


def _low_pass(recorded: dict | None, dt: float, n: int):
    """``(apply, cutoff)``: the fit's parallel filter on an ``(n,)`` series with its start-up
    set to NaN, as the route trims it (entry 0 is dropped by the caller); None without one."""
    if not isinstance(recorded, dict) or "cutoff" not in recorded:
        return None
    from scipy import signal

    cutoff, order = float(recorded["cutoff"]), int(recorded.get("order", 4))
    if not 0 < cutoff < 0.5 / dt:
        return None
    sos = signal.butter(order, cutoff * 2 * dt, output="sos")
    m = max(round(float(recorded.get("trim", 0.25)) / dt), 1)
    if n <= 2 * m + 30:
        return None

    def apply(x: np.ndarray) -> np.ndarray:
        y = signal.sosfiltfilt(sos, x)
        y[:m] = np.nan
        y[n - m :] = np.nan
        return y

    return apply, cutoff


#: The laws with a friction state (module notes).
DYNAMIC = ("lugre", "lugre_asym", "dahl")

#: The caveat of a dynamic law graded on a second log.
PRESLIDING_UNGRADED = (
    "the second log grades it where it slides; its pre-sliding and break-away are not graded "
    "(see the report's low-passed error and hysteresis loops)"
)

#: Fewest sliding samples a second log grades a model on, and the share of its samples below
#: which the verdict says how few were graded.
MIN_GRADED, MIN_SHARE = 200, 0.5

#: :func:`_smooth_share` below which the torque is taken for low-passed, not noisy (white
#: noise gives about 1: the virtual joint 1.03, the independent simulator's PD logs 1.00-1.01,
#: 100 Hz 0.94; low-passed at 5 Hz, 0.006).
WHITE_SHARE = 0.7

#: Fewest runs of three sliding samples a scatter is estimated from.
MIN_TRIPLES = 50


def _runs(slide: np.ndarray, k: int) -> np.ndarray:
    """Where ``k`` consecutive samples all slide (entry ``i``: samples ``i .. i + k - 1``)."""
    inside = slide[: slide.size - k + 1].copy()
    for j in range(1, k):
        inside &= slide[j : slide.size - k + 1 + j]
    return inside


def _mad_scatter(d: np.ndarray, white_variance: float) -> float:
    if d.size < MIN_TRIPLES:
        return math.nan
    return 1.4826 * float(np.median(np.abs(d - np.median(d)))) / math.sqrt(white_variance)


def torque_scatter(prediction: TrajectoryPrediction) -> float:
    """The torque's scatter [N m] on the log's sliding samples (module notes); NaN with fewer
    than :data:`MIN_TRIPLES` runs of three consecutive sliding samples."""
    u = np.asarray(prediction.torque, dtype=float)
    slide = prediction.sliding
    if slide is None or u.size < 4:
        return math.nan
    return _mad_scatter((u[2:] - 2.0 * u[1:-1] + u[:-2])[_runs(slide, 3)], 6.0)


def _smooth_share(prediction: TrajectoryPrediction, scatter: float) -> float:
    """The third differences' scatter over the second's, each scaled for white noise: about 1
    for a torque whose sample-to-sample content is noise, far below for one low-passed before
    it was logged (its second differences then measure the filter, not the noise); ``scatter``
    the second differences' (:func:`torque_scatter`)."""
    u = np.asarray(prediction.torque, dtype=float)
    d3 = (u[3:] - 3.0 * u[2:-1] + 3.0 * u[1:-2] - u[:-3])[_runs(prediction.sliding, 4)]
    return _mad_scatter(d3, 20.0) / scatter


def heldout_grading(fitted: FittedModel, heldout: TrajectoryPrediction) -> tuple[Trust | None, str]:
    """The file's verdict graded again with the held-out error over the held-out log's torque
    scatter (module notes), and one line on what was graded; ``(None, why)`` when the file
    holds no trust record or the log cannot grade it (fewer than :data:`MIN_GRADED` sliding
    samples, no scatter)."""
    record = fitted.trust
    if not isinstance(record, dict):
        return None, "the model file holds no verdict to grade"
    try:
        trust = Trust.from_dict(record)
    except (KeyError, TypeError, ValueError):
        return None, "the model file's verdict is not readable"
    slide = heldout.sliding if heldout.sliding is not None else np.zeros(0, dtype=bool)
    n, total = int(slide.sum()), int(heldout.residual.size)
    scatter = torque_scatter(heldout)
    error = heldout.metrics()["rmse_sliding"]
    if n >= MIN_GRADED and math.isfinite(scatter) and scatter > 0:
        white = _smooth_share(heldout, scatter)
        if not white >= WHITE_SHARE:
            return None, (
                f"not graded: its torque is smooth from one sample to the next (third "
                f"differences {white:.2g} of what noise gives beside its second ones): low-passed "
                "before it was logged, so its scatter cannot be told from its differences"
            )
    if n < MIN_GRADED or not (math.isfinite(scatter) and scatter > 0 and math.isfinite(error)):
        return None, (
            f"not graded: {n} of its {total} samples slide away from the slow stretches "
            f"(at least {MIN_GRADED} needed, with a torque scatter to compare with)"
        )
    trust.heldout_rmse, trust.scatter = float(error), float(scatter)
    trust.heldout_ratio = float(error / scatter)
    trust.heldout_source = SECOND_LOG
    speed = np.abs(np.asarray(heldout.velocity, dtype=float)[slide])
    share = n / total
    trust.heldout_scheme = (
        f"graded where it slides: {n} of {total} samples ({100 * share:.0f} %), at "
        f"{speed.min():.3g} rad/s and faster; error {error:.3g} N m, "
        f"{trust.heldout_ratio:.2f}x the torque's scatter {scatter:.3g} N m"
    )
    trust.scatter_method = SECOND_DIFFERENCES
    trust.verdict = verdict(trust.heldout_ratio)
    trust.validation_note = ""
    caveats = [PRESLIDING_UNGRADED if fitted.model in DYNAMIC else ""]
    if share < MIN_SHARE:
        caveats.append(
            f"the second log grades it on {100 * share:.0f} % of its samples only (those that "
            "slide); the rest are not graded"
        )
    _grade(trust, fitted, caveats, [])
    return trust, trust.heldout_scheme


def heldout_trust(fitted: FittedModel, heldout: TrajectoryPrediction) -> Trust | None:
    """The graded verdict of :func:`heldout_grading` (None where it gives none)."""
    return heldout_grading(fitted, heldout)[0]
