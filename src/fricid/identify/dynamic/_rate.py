"""The break-away discretisation bias of the ``filtered`` route at the log's rate.

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

from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from ...errors import FricidError
from ...models import lugre
from ._data import Series
from ._encoder import measured_velocity, quantise
from ._filtered import LOG_BOX, ParallelFilter, filtered_route
from ._routes import _Stage

__all__ = ["GAINS", "SUB_STEPS", "rate_bias", "simulated_log"]

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
        The log's measurement model (:func:`._encoder.measurement`): with a ``quantum`` the
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
    theta = np.asarray(stage.values[:7], dtype=float)
    quantum = (encoder or {}).get("quantum")
    out: dict[str, Any] = {"internal_rate": SUB_STEPS / series.dt, "log_rate": 1.0 / series.dt}
    out["quantised"] = (encoder or {}).get("counts_per_rev") if quantum else None
    again = simulated_log(series, stage.values, encoder)
    if again is None:
        return {**out, "skipped": "the simulation at the estimate diverged"}
    try:
        if refine is None:
            redo, _, _ = filtered_route(
                again, theta, static_bounds, gravity, method, seed, None, 0.5, n_sub, filt
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
) -> Series | None:
    """The log a joint with ``values`` (LuGre's seven, then J, p_x, p_y) would have given:
    simulated at :data:`SUB_STEPS` sub-steps per period under ``feed`` (default the logged
    torque) with PD tracking (:data:`GAINS`) of the measured position, read through the log's
    ``encoder`` (its velocity formed as the log's was), the applied torque logged plus
    ``noise`` (``(n,)``, default none). None when the simulation diverges."""
    theta = np.asarray(values[:7], dtype=float)
    joint = [*values[7:], 0.0, 0.0]
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
