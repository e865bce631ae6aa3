"""The measurement of a trajectory log, its encoder and its rate, and the biases they leave.

Encoder: its resolution and how the velocity was formed from its counts.

A drive logs the position quantised to its encoder, ``q_k = c_k Delta`` with ``c_k`` an
integer count and ``Delta = 2 pi / N`` for ``N`` counts per revolution, and usually the
velocity by differences of those counts. The rounding error of one reading is uniform on
``[-Delta/2, Delta/2]`` (variance ``Delta^2 / 12``; Widrow and Kollar 2008, ch. 4); a
backward difference ``(q_k - q_{k-1}) / dt`` carries ``2 Delta^2 / (12 dt^2)``, and any
linear derivative filter with taps ``h`` carries ``Delta^2 / 12 sum h_j^2``.

:func:`encoder_quantum` finds ``Delta`` from the log's own position steps (every step a
whole multiple of the smallest); :func:`measurement` records it (or the ``encoder_counts``
given) with the velocity's form and the propagated quantisation errors: of the logged
velocity, of the parallel filter's acceleration regressor, and of the bristle state driven
by the measured motion (an error of ``Delta / sqrt(12)`` in the bristles' deflection is
``sigma_0 Delta / sqrt(12)`` of torque: at 2^17 counts/rev and sigma_0 = 2e4 N m/rad, 0.28 N m,
of the order of the Coulomb level, which is why a coarse encoder can leave sigma_0 and sigma_1
undetermined by an equation error however long the log). :func:`quantise` reproduces the
measurement on a simulated motion, for the bias check by simulation at the estimate
(:func:`rate_bias`).

Rate: the break-away discretisation bias of the ``filtered`` route at the log's rate.

The filtered route drives the bristle state with the cubic Hermite interpolant of the logged
motion (:mod:`._trajectory_filtered`). In the one sample period in which the joint breaks
away at a reversal the velocity jumps within a fraction of a millisecond, a shape no
interpolant of the samples knows; at 1 kHz that biases sigma_0 up and sigma_1 down
(noise-free, 20 s multi-sine, seed 11: +3.5 % and -20 %), while at 10 kHz every parameter
is within 0.3 per mille.

:func:`rate_bias` estimates that bias by the parametric bootstrap of the estimate's own
discretisation (the bias correction of the indirect-inference kind: Gourieroux, Monfort and
Renault 1993; MacKinnon and Smith 1998): the joint with a LuGre truth equal to the estimate
(and its J, p_x, p_y) is simulated at ``n_sub`` (16) sub-steps per period under the
measured torque, tracking the measured position with PD gains so the motion stays the
measured one, logged noise-free at the log's rate and identified again from the estimate
by the same route: ``b = theta* - theta_hat`` (sigma_0 and sigma_1 on their log10 search
scale). Measured (noise-free, seed 11, 20 s): the true errors of log10 sigma_0 and
log10 sigma_1 +0.0150 and -0.0979, the estimates of them +0.0116 and -0.1165;
``2 theta_hat - theta*`` left 1.5 and 1.7 standard errors of 6.5 and 8.8.

Measured over seeds (``benchmarks/calib_trajectory.py``; log10 scale, mean error, then RMS
error over the reported standard error, as estimated -> as corrected):

* noise-free, 20 s, seeds 10-19: sigma_0 +0.0164 -> +0.0024 (+3.8 % -> +0.6 %), 7.9 -> 1.5;
  sigma_1 -0.104 -> +0.033 (-21 % -> +8 %), 10.1 -> 3.1; coverage 0/10 -> 8/10 and 4/10;
* trajectory noise, 60 s, seeds 10-49: sigma_0 +0.0124 -> -0.0004, 0.86 -> 0.78; sigma_1
  -0.084 -> +0.041 (-18 % -> +10 %), 0.74 -> 0.71; coverage 40/40 either way.

So the estimate finds the bias's size and sign, but sigma_1's over-corrects by about half:
it is evaluated at a noisy estimate and grows as sigma_1's estimate falls (60 s, log10:
seed 13, -0.31 at an estimate 0.22 low; seed 15, -0.075 at one 0.055 high; a 15 s log,
seed 22, put it at -74 %), an uncertainty the correction would have to carry and that is
not estimated here. fricid therefore applies nothing: the bias and the corrected values go
into the provenance, and :func:`fricid.identify.dynamic.trajectory.fit_trajectory` warns
(:class:`fricid.identify.dynamic.trajectory.RateBiasWarning`) when the bias exceeds half a standard
error, naming ten times the log's rate as the rate that removes it (10 kHz put every
parameter within 0.3 per mille, :mod:`._trajectory_filtered`). It costs one simulation and
one re-identification from the estimate: about the filtered route's own time again.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from ...errors import ConfigError, FricidError, FricidWarning, user_stacklevel
from ...models import lugre
from ...samples import encoder_quantum
from ..static.uncertainty import jacobian
from ._data import Series, blocks, cluster_covariance
from ._filtered import LOG_BOX, ParallelFilter, filtered_route, joint_columns, law_of
from ._routes import _Stage

__all__ = [
    "DELAY_SAMPLES",
    "DELAY_Z",
    "GAINS",
    "SUB_STEPS",
    "VELOCITY_FORMS",
    "TorqueDelayWarning",
    "delay_caveat",
    "encoder_quantum",
    "measurement",
    "quantise",
    "rate_bias",
    "simulated_log",
    "torque_delay",
    "velocity_form",
    "warn_delay",
]


#: Relative distance of the counts read from a power of two within which they are taken as
#: that power (a log written with 7 decimals read 2^20 as 1048597: 2e-5 off).
POWER_SNAP = 1e-4

#: Relative amount by which the position's steps may be finer than the counts given before
#: the counts are refused (a 4096-count log taken for 1024 had been accepted without a word).
FINER = 0.01

#: How the logged velocity can be formed from the positions.
VELOCITY_FORMS = ("backward", "central", "logged")


def velocity_form(position: np.ndarray, velocity: np.ndarray, dt, time=None) -> str:
    """How the logged velocity relates to the positions: ``backward`` (``(q_k - q_{k-1}) /
    dt``), ``central`` (:func:`numpy.gradient`) or ``logged`` (neither: the drive's own).
    ``dt``: the sample period, or each step's (``(n - 1,)``) with the stamps ``time``."""
    scale = max(float(np.max(np.abs(velocity))), 1e-12)
    back = np.diff(position) / dt
    tol = 1e-3 * scale  # the columns' rounding in a written log
    if np.max(np.abs(velocity[1:] - back)) <= tol:
        return "backward"
    central = np.gradient(position, dt if time is None else time)
    if np.max(np.abs(velocity - central)) <= tol:
        return "central"
    return "logged"


def quantise(position: np.ndarray, quantum: float, offset: float = 0.0) -> np.ndarray:
    """``position`` read by an encoder of ``quantum`` [rad] whose counts sit at ``offset +
    k quantum`` (rounding to the nearest count)."""
    return offset + np.round((np.asarray(position) - offset) / quantum) * quantum


def measurement(
    position: np.ndarray,
    velocity: np.ndarray,
    dt: float,
    encoder_counts: float | None,
    raw: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> dict[str, Any]:
    """The log's measurement model (module notes), as recorded in the provenance.

    Parameters
    ----------
    position, velocity : ndarray (n,)
        The logged position [rad] and velocity [rad/s] on a uniform grid.
    dt : float
        Sample period [s].
    encoder_counts : float, optional
        Counts per revolution given by the user; None reads them from the position steps.
    raw : (time, position, velocity), optional
        The log as written, when ``position`` and ``velocity`` were resampled onto the
        uniform grid: the steps and the velocity's form are read from it (interpolated
        positions sit between counts: a log with rows dropped had read three times its
        encoder's counts).

    Returns
    -------
    dict
        ``counts_per_rev`` (None: no quantisation found), ``quantum`` [rad], ``source``
        (``option``, ``position steps`` or ``none found``), ``offset`` [rad] (where the
        counts sit), ``velocity_form``, ``velocity_std`` [rad/s] (the logged velocity's
        quantisation error).

    Raises
    ------
    ConfigError
        ``encoder_counts`` not a positive finite number, or coarser than the position's own
        steps.
    """
    if raw is not None:
        t_raw, position, v_raw = (np.asarray(x, dtype=float) for x in raw)
        form = velocity_form(position, v_raw, np.diff(t_raw), t_raw)
    else:
        form = velocity_form(position, velocity, dt)
    if encoder_counts is not None:
        if not (math.isfinite(encoder_counts) and encoder_counts > 0):
            raise ConfigError(f"encoder_counts must be a positive number, got {encoder_counts}")
        quantum, source = 2.0 * math.pi / float(encoder_counts), "option"
        seen = encoder_quantum(position)
        if seen is not None and seen < quantum * (1.0 - FINER):
            own = 2.0 * math.pi / seen
            raise ConfigError(
                f"{encoder_counts:g} encoder counts per revolution give steps of {quantum:.4g} "
                f"rad, but the position moves in steps of {seen:.4g} rad ({own:.6g} counts per "
                "revolution): leave the counts out to read them from the position, or give the "
                "encoder's own"
            )
    else:
        quantum, source = encoder_quantum(position), "position steps"
    if quantum is None:
        return {
            "counts_per_rev": None,
            "quantum": None,
            "source": "none found",
            "velocity_form": form,
        }
    counts = 2.0 * math.pi / quantum
    power = 2.0 ** round(math.log2(counts))
    if source != "option" and abs(counts / power - 1.0) <= POWER_SNAP:
        counts, quantum = power, 2.0 * math.pi / power  # a binary encoder, read to rounding
    elif abs(counts - round(counts)) <= 1e-3 * counts:
        counts = float(round(counts))
    offset = float(position[0] - np.round(position[0] / quantum) * quantum)
    std = quantum / math.sqrt(12.0)
    v_std = {"backward": math.sqrt(2.0) * std / dt, "central": std / (math.sqrt(2.0) * dt)}
    return {
        "counts_per_rev": counts,
        "quantum": quantum,
        "source": source,
        "offset": offset,
        "velocity_form": form,
        "velocity_std": v_std.get(form),
    }


def measured_velocity(position: np.ndarray, velocity: np.ndarray, dt: float, form: str):
    """The velocity a drive of velocity form ``form`` logs for ``position`` (``logged``: the
    given ``velocity``, unchanged)."""
    if form == "backward":
        return np.concatenate([velocity[:1], np.diff(position) / dt])
    if form == "central":
        return np.gradient(position, dt)
    return velocity


#: Sub-steps per logged period of the simulation at the estimate (as the virtual joint's).
SUB_STEPS = 16

#: PD gains [N m/rad, N m s/rad] that keep the simulated joint on the measured motion.
GAINS = (200.0, 5.0)


def rate_bias(
    series: Series,
    stage: _Stage,
    static_bounds: np.ndarray,
    gravity: str,
    method: str,
    seed: int,
    n_sub: int,
    filt: ParallelFilter,
    encoder: dict[str, Any] | None = None,
    refine: Callable[[Series, _Stage], tuple[_Stage, Any, Any]] | None = None,
) -> dict[str, Any]:
    """The filtered route's discretisation bias of sigma_0 and sigma_1 (module notes).

    Parameters
    ----------
    series : Series
        The log on a uniform grid (its time, measured position and torque are used).
    stage : _Stage
        The filtered route's estimate (LuGre's seven parameters, then J, p_x, p_y).
    static_bounds, gravity, method, seed, n_sub, filt
        As given to :func:`._trajectory_filtered.filtered_route`.
    encoder : dict, optional
        The log's measurement model (:func:`measurement`): with a ``quantum`` the
        simulated position is read by the same encoder and the velocity formed from it as the
        log's was, so the bias includes the quantisation's.
    refine : callable, optional
        The step after the filtered route that gave ``stage`` (the output error,
        :mod:`._output`), ``refine(series, stage) -> (stage, y, r)``: the re-identification
        is then that step, from the estimate.

    Returns
    -------
    dict
        ``sigma_0`` and ``sigma_1``: ``{"log10_bias", "relative", "corrected"}`` (the bias on
        the log10 scale, as a relative change ``10**b - 1``, and ``10**(2 log10 theta_hat -
        log10 theta*)``); ``parameters``: every parameter of the stage by name, ``{"bias",
        "relative", "corrected", "scale"}`` (the bias in the search's coordinates, ``scale``
        ``log10`` or ``linear``); ``quantised``: the encoder's counts per revolution
        applied (None: none); ``internal_rate`` [Hz], ``log_rate`` [Hz], ``seconds`` of the
        re-identification's route; or, instead of the estimates, ``skipped`` with the reason
        (the simulation at the estimate diverged, or its identification failed).
    """
    law = law_of(stage.names)
    theta = np.asarray(stage.values[: len(law.names)], dtype=float)
    quantum = (encoder or {}).get("quantum")
    out: dict[str, Any] = {"internal_rate": SUB_STEPS / series.dt, "log_rate": 1.0 / series.dt}
    out["quantised"] = (encoder or {}).get("counts_per_rev") if quantum else None
    again = simulated_log(series, stage.values, encoder, width=len(law.names))
    if again is None:
        return {**out, "skipped": "the simulation at the estimate diverged"}
    try:
        if refine is None:
            redo, _, _ = filtered_route(
                again, theta, static_bounds, gravity, method, seed, None, 0.5, n_sub, filt, law=law
            )
        else:  # the step that gave the estimate, from it (the simulation's truth)
            redo, _, _ = refine(again, stage)
        seconds = redo.seconds
    except FricidError as exc:
        return {**out, "skipped": f"the re-identification failed: {exc}"}
    out["seconds"] = seconds
    out["parameters"] = _biases(stage, redo)
    for i, name in enumerate(LOG_BOX):
        b = float(np.log10(redo.values[i]) - np.log10(theta[i]))
        out[name] = {
            "log10_bias": b,
            "relative": float(10.0**b - 1.0),
            "corrected": float(theta[i] * 10.0 ** (-b)),
        }
    return out


def simulated_log(
    series: Series,
    values: np.ndarray,
    encoder: dict[str, Any] | None = None,
    feed: np.ndarray | None = None,
    noise: np.ndarray | None = None,
    width: int = 7,
) -> Series | None:
    """The log a joint with ``values`` (LuGre's ``width`` parameters, 10 per direction, then
    J, p_x, p_y) would have given:
    simulated at :data:`SUB_STEPS` sub-steps per period under ``feed`` (default the logged
    torque) with PD tracking (:data:`GAINS`) of the measured position, read through the log's
    ``encoder`` (its velocity formed as the log's was), the applied torque logged plus
    ``noise`` (``(n,)``, default none). None when the simulation diverges."""
    theta = np.asarray(values[:width], dtype=float)
    joint = [*values[width:], 0.0, 0.0]
    dt, q = series.dt, series.position
    sim = lugre.simulate_joint(
        theta,
        joint[0],
        joint[1],
        joint[2],
        np.full(q.size, dt),
        series.torque if feed is None else feed,
        q0=q[0],
        v0=series.velocity[0],
        z0=np.sign(series.velocity[0])
        * lugre.stribeck_curve(theta, series.velocity[:1])[0]
        / theta[0],
        reference=(q, np.gradient(q, dt)),
        gains=GAINS,
        n_sub=SUB_STEPS,
    )
    if not all(np.isfinite(sim[k]).all() for k in ("position", "velocity", "torque")):
        return None
    position, velocity = sim["position"], sim["velocity"]
    quantum = (encoder or {}).get("quantum")
    if quantum:
        position = quantise(position, quantum, encoder.get("offset", 0.0))
        velocity = measured_velocity(position, velocity, dt, encoder["velocity_form"])
    torque = sim["torque"] if noise is None else sim["torque"] + noise
    return replace(series, position=position, velocity=velocity, torque=torque)


def _biases(stage: _Stage, redo: _Stage) -> dict[str, dict[str, Any]]:
    """Every parameter's bias ``redo - stage`` in the search's coordinates (log10 for those
    of :data:`LOG_BOX`), as a relative change, and the value it corrects the estimate to."""
    out = {}
    for i, name in enumerate(stage.names):
        v, w = float(stage.values[i]), float(redo.values[i])
        if name in LOG_BOX:
            b = float(np.log10(w) - np.log10(v))
            out[name] = {
                "bias": b,
                "relative": float(10.0**b - 1.0),
                "corrected": float(v * 10.0 ** (-b)),
                "scale": "log10",
            }
        else:
            b = w - v
            rel = b / abs(v) if v != 0 else float("nan")
            out[name] = {"bias": b, "relative": rel, "corrected": v - b, "scale": "linear"}
    return out


def torque_delay(
    series: Series, stage: _Stage, filt: ParallelFilter, gravity: str, cluster_time: float
) -> dict[str, Any]:
    """The logged torque's delay behind the logged motion [s], from the final stage's
    residual (positive: the torque logged late).

    A torque logged ``d`` late leaves the residual ``-d u'`` (the filtered torque's
    derivative), which the fitted parameters take up in part (on a new user's log 2 ms late,
    J -1.1 % and sigma_2 +2.9 % inside closed intervals, nothing said). ``d`` is the
    least-squares coefficient of ``-u'`` on the residual at the estimate, both with the
    stage's Jacobian columns (and the filtered route's projected joint columns) partialled
    out (Frisch and Waugh 1933: the estimate refitted with the delay, to first order), its
    standard error cluster-robust over blocks of ``cluster_time`` like the stage's own.
    Costs one Jacobian of the stage: its parameters' count of simulations or filtered
    friction evaluations. Returns ``{"seconds", "stderr", "samples", "z", "clusters",
    "route"}`` or ``{"skipped": why}``."""
    problem = stage.problem
    if problem is None or stage.result is None:
        return {"skipped": "the stage searched nothing"}
    dt, n = series.dt, series.time.size
    rate = 1.0 / dt
    low, keep = filt.lowpass(rate), filt.kept(rate, n)
    Jm, r = jacobian(problem.residuals, np.asarray(stage.result.x, dtype=float))
    output = "inertia" in problem.names
    if output:  # the output error: the joint searched, its torque as is
        basis, y_full = Jm, low(series.torque)
    else:  # the filtered route: the joint's columns projected out of its residual
        basis = np.column_stack([Jm, joint_columns(series, low, keep, gravity)[0]])
        y_full = low(np.concatenate([series.torque[:1], series.torque[:-1]]))
    x = -np.gradient(y_full, dt)[keep]
    Q, _ = np.linalg.qr(np.nan_to_num(basis))
    xm = x - Q @ (Q.T @ x)
    rm = r - Q @ (Q.T @ r)
    size = float(xm @ xm)
    if not (size > 0 and np.isfinite(rm).all()):
        return {"skipped": "the torque does not change"}
    d = float(xm @ rm) / size
    labels = blocks(n, max(round(cluster_time * rate), 1))[keep]
    _, se, g = cluster_covariance(xm[:, None], rm - d * xm, labels)
    stderr = float(se[0])
    z = d / stderr if stderr > 0 else float("inf")
    route = "output error" if output else "equation error"
    out = {"seconds": d, "stderr": stderr, "samples": d / dt, "z": z, "clusters": int(g)}
    return {**out, "route": route}


#: A torque delay is said where it exceeds :data:`DELAY_Z` standard errors and
#: :data:`DELAY_SAMPLES` sample periods. fricid takes each torque sample to act over the
#: period after it, so a torque sampled with the position reads up to half a sample late
#: (a second new-user trial: 0.3-0.5 samples, z up to 105, on logs sampled together). Measured
#: on ``benchmarks/_lugre_truth.py``'s logs (three joints, PD-tracked chirps and trapezoids,
#: torque steps, 1 kHz and 200 Hz, 2^17 and 2^20 counts/rev, 10 s; a throwaway script), said
#: as logged / with the torque 2 samples late: seed 0, 0 / 27 of 36; seed 1, 1 / 26 of 36 (the
#: one a 200 Hz trapezoid the model misfits, -1.33 samples). The trial's own simulator (LuGre
#: fits): 5 of 57 aligned logs, 36 of 72 logs 1-5 samples late, 4 of 17 sampled together (13
#: of 17 at a quarter sample, the first threshold). The output error reads a delay short (as
#: little as a fiftieth of it), the equation error at 0.7-1.0 of it on chirps and steps.
DELAY_Z = 4.0
DELAY_SAMPLES = 0.5


class TorqueDelayWarning(FricidWarning):
    """The logged torque appears late (or early) behind the logged motion."""


def delay_caveat(record: dict[str, Any] | None) -> str:
    """The caveat of a torque delay past :data:`DELAY_Z` and :data:`DELAY_SAMPLES` ("" when
    none was found or checked). A reading of the torque *early* puts the model's misfit
    first: in a second new-user trial (its own simulator; 60 logs as logged, 12 said, 6 of
    them Dahl fits of LuGre joints) 10 of the 12 said on well-aligned logs read early, by
    0.3-9 samples, while its logs with the torque 1-5 samples late read late (45 of 78
    said)."""
    if not record or "skipped" in record:
        return ""
    s, z = float(record["samples"]), float(record["z"])
    if not (abs(z) > DELAY_Z and abs(s) > DELAY_SAMPLES):
        return ""
    read = (
        f"the residual follows the torque's rate of change as a torque logged {abs(s):.2g} "
        f"sample periods ({1e3 * abs(record['seconds']):.2g} ms) "
        f"{'late behind' if s > 0 else 'early before'} the position would leave it (z = "
        f"{z:.3g}; fricid takes each torque sample to act over the period after it)"
    )
    short = (  # the output error's loop takes part of a delay up
        "; this fit's output error reads a delay short, as little as a fiftieth of it"
        if record.get("route") == "output error"
        else ""
    )
    late = "its torque late (a bus, a sensor's low-pass filter)"
    timing = (
        f"if the drive logs {late if s > 0 else 'its position late'}, J and the viscous term "
        "are biased (a log 2 ms late at 1 kHz: J -1.1 %, sigma_2 +2.9 % inside closed "
        f"intervals{short})"
    )
    misfit = "the model misses the joint where its torque changes"
    if s > 0:
        return f"{read}: {timing}, else {misfit}"
    trial = "in a trial, 10 of the 12 aligned logs it was said on read early"
    return f"{read}: most often {misfit} ({trial}); else, {timing}"


def warn_delay(record: dict[str, Any] | None) -> None:
    """:class:`TorqueDelayWarning` with :func:`delay_caveat`'s text, where it has one."""
    text = delay_caveat(record)
    if text:
        warnings.warn(text, TorqueDelayWarning, stacklevel=user_stacklevel())
