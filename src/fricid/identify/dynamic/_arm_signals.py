"""A robot log's signals for whole-arm identification: zero-phase low-pass, derivatives,
the same filter on the torque ("parallel filtering"), decimation.

The inverse dynamic identification model (IDIM) needs ``q``, ``dq``, ``ddq`` at every sample;
a real arm logs a quantised position (an encoder) and a noisy torque. Following Gautier
(1997, "Dynamic identification of robots with power model") and Gautier, Janot and Vandanjon
(2013, IEEE T-CST, the IDIM-LS "done right"):

* the position is low-passed by a Butterworth filter of order 4 run forwards and backwards
  (``scipy.signal.filtfilt``: zero phase, order 8), and ``dq``, ``ddq`` are central
  differences of the filtered position;
* the torque passes through the *same* filter (parallel filtering), so that the filter's
  small amplitude distortion in the pass band acts alike on both sides of ``tau = Y beta``;
* both are then decimated to a rate of about :data:`RATE_OVER_CUTOFF` times the cut-off, since
  the filtered signals carry nothing above it, and a filter transient of :data:`EDGE_PERIODS`
  periods of the cut-off is dropped at each end.

The cut-off ``f_c`` (:func:`choose_cutoff`) is the smallest of three bounds:

1. ``SIGNAL_FACTOR`` times the motion's bandwidth ``f_m`` (the frequency below which
   :data:`SIGNAL_POWER` of the velocity's power lies, from the differenced position's
   spectrum): the dynamics must pass undistorted;
2. the encoder bound: an encoder step ``Delta`` is uniform quantisation noise of variance
   ``Delta^2 / 12``, white up to ``f_s / 2``; twice differentiated and low-passed at ``f_c``
   its acceleration noise is ``sigma_ddq^2 = Delta^2 / 12 * 2 / f_s * (2 pi)^4 f_c^5 / 5``.
   ``f_c`` is kept where ``sigma_ddq`` is at most :data:`ENCODER_SHARE` of the acceleration's
   RMS, so that noise in the regressor (which biases least squares towards zero) stays small;
3. ``f_s /`` :data:`MIN_RATE_OVER_CUTOFF` (the filter needs room below Nyquist).

The encoder step is ``2 pi / counts`` when the counts per revolution are known, else the
smallest non-zero change of each joint's logged position.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.signal

from ...errors import DataError

__all__ = ["ArmSignals", "choose_cutoff", "encoder_step", "prepare_signals"]

#: Butterworth order (doubled by the forward-backward pass).
BUTTER_ORDER = 4
#: Share of the velocity's power below the motion's bandwidth.
SIGNAL_POWER = 0.995
#: Cut-off over the motion's bandwidth (bound 1).
SIGNAL_FACTOR = 10.0
#: Largest acceleration noise from the encoder, over the acceleration's RMS (bound 2).
ENCODER_SHARE = 0.01
#: The log's rate over the cut-off, at least (bound 3).
MIN_RATE_OVER_CUTOFF = 5.0
#: The decimated rate over the cut-off.
RATE_OVER_CUTOFF = 5.0
#: Filter transient dropped at each end, in periods of the cut-off.
EDGE_PERIODS = 2.0


@dataclass(frozen=True)
class ArmSignals:
    """Filtered, decimated signals of a robot log (module notes), shape (N, n) each."""

    time: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    tau: np.ndarray
    rate: float
    cutoff: float
    decimation: int
    encoder_step: np.ndarray
    bounds: dict[str, float]
    #: the velocity's noise standard deviation from the encoder after the filter [rad/s]
    velocity_noise: np.ndarray
    #: the filtered velocity at the log's full rate (friction columns are computed on it)
    full_dq: np.ndarray
    #: the filter's coefficients and the rows kept (edges cut, decimated)
    ba: tuple[np.ndarray, np.ndarray]
    keep: slice

    def parallel(self, x: np.ndarray) -> np.ndarray:
        """``x`` (full rate, first axis time) through the same filter, edges cut, decimated:
        the parallel filtering of a column of the regression (module notes)."""
        x = np.asarray(x, dtype=float)
        flat = np.ascontiguousarray(x.reshape(x.shape[0], -1).T)  # time last: contiguous runs
        out = scipy.signal.filtfilt(*self.ba, flat, axis=-1)[:, self.keep].T
        return out.reshape((out.shape[0], *x.shape[1:]))


def encoder_step(position: np.ndarray, counts: int | None) -> np.ndarray:
    """The encoder step per joint [rad] (module notes)."""
    n = position.shape[1]
    if counts is not None:
        return np.full(n, 2 * np.pi / float(counts))
    out = np.empty(n)
    for j in range(n):
        d = np.abs(np.diff(position[:, j]))
        d = d[d > 1e-15]
        out[j] = float(d.min()) if d.size else 0.0
    return out


def _bandwidth(q: np.ndarray, rate: float) -> float:
    """The frequency below which :data:`SIGNAL_POWER` of the velocity's power lies [Hz]."""
    v = np.diff(q, axis=0) * rate
    v = v - v.mean(axis=0)
    spec = np.abs(np.fft.rfft(v, axis=0)) ** 2
    total = spec.sum(axis=1)
    cum = np.cumsum(total)
    if cum[-1] <= 0:
        return rate / 2
    freqs = np.fft.rfftfreq(v.shape[0], 1.0 / rate)
    return float(freqs[min(np.searchsorted(cum, SIGNAL_POWER * cum[-1]), freqs.size - 1)])


def choose_cutoff(q: np.ndarray, rate: float, step: np.ndarray) -> tuple[float, dict[str, float]]:
    """The low-pass cut-off [Hz] and its three bounds (module notes)."""
    f_m = max(_bandwidth(q, rate), 10.0 / (q.shape[0] / rate))
    signal = SIGNAL_FACTOR * f_m
    nyquist = rate / MIN_RATE_OVER_CUTOFF
    # the acceleration's RMS, from a gentle estimate (cut at the signal bound)
    b, a = scipy.signal.butter(BUTTER_ORDER, min(signal, nyquist) / (rate / 2))
    qf = scipy.signal.filtfilt(b, a, q, axis=0)
    acc = np.gradient(np.gradient(qf, axis=0), axis=0) * rate**2
    rms = np.sqrt(np.mean(acc**2, axis=0))
    moving = (step > 0) & (rms > 0)
    encoder = np.inf
    if moving.any():
        # sigma_ddq(f_c) = ENCODER_SHARE * rms, solved for f_c per joint; the tightest joint
        per = (ENCODER_SHARE * rms[moving]) ** 2 * 12 * 5 * rate / (2 * (2 * np.pi) ** 4)
        encoder = float(np.min((per / step[moving] ** 2) ** 0.2))
    cutoff = min(signal, nyquist, encoder)
    cutoff = max(cutoff, 2.0 * f_m)  # never below the motion itself
    return cutoff, {"signal": signal, "encoder": encoder, "rate": nyquist, "motion": f_m}


def _velocity_noise(step: np.ndarray, rate: float, cutoff: float) -> np.ndarray:
    """The encoder's velocity noise after the filter [rad/s] (module notes, one derivative)."""
    return np.sqrt(step**2 / 12 * 2 / rate * (2 * np.pi) ** 2 * cutoff**3 / 3)


def prepare_signals(
    time: np.ndarray,
    position: np.ndarray,
    torque: np.ndarray,
    *,
    counts: int | None = None,
    cutoff: float | None = None,
    source: str | None = None,
) -> ArmSignals:
    """Filter, differentiate and decimate a log's position and torque (module notes).

    Parameters
    ----------
    time : ndarray (N,)
    position, torque : ndarray (N, n)
    counts : int, optional
        Encoder counts per revolution (else read from the position's steps).
    cutoff : float, optional
        The low-pass cut-off [Hz] (else :func:`choose_cutoff`).
    source : str, optional
        The log's file, named in errors.
    """
    dt = np.diff(time)
    rate = 1.0 / float(np.median(dt))
    if np.max(np.abs(dt * rate - 1.0)) > 0.05:
        raise DataError(
            "whole-arm identification needs a uniformly sampled log (the sample interval "
            f"varies from {dt.min():.3g} s to {dt.max():.3g} s)",
            file=source,
            column="time",
        )
    step = encoder_step(position, counts)
    bounds: dict[str, float] = {}
    if cutoff is None:
        cutoff, bounds = choose_cutoff(position, rate, step)
    cutoff = min(float(cutoff), 0.45 * rate)
    edge = int(np.ceil(EDGE_PERIODS * rate / cutoff))
    if position.shape[0] < 4 * edge + 20:
        raise DataError(
            f"the log is too short ({position.shape[0]} samples) for a low-pass at "
            f"{cutoff:.3g} Hz",
            file=source,
        )
    b, a = scipy.signal.butter(BUTTER_ORDER, cutoff / (rate / 2))
    q = scipy.signal.filtfilt(b, a, position, axis=0)
    tau = scipy.signal.filtfilt(b, a, torque, axis=0)
    dq = np.gradient(q, axis=0) * rate
    ddq = np.gradient(dq, axis=0) * rate
    factor = max(1, int(rate / (RATE_OVER_CUTOFF * cutoff)))
    keep = slice(edge, position.shape[0] - edge, factor)
    return ArmSignals(
        time=time[keep],
        q=q[keep],
        dq=dq[keep],
        ddq=ddq[keep],
        tau=tau[keep],
        rate=rate,
        cutoff=cutoff,
        decimation=factor,
        encoder_step=step,
        bounds=bounds,
        velocity_noise=_velocity_noise(step, rate, cutoff),
        full_dq=dq,
        ba=(b, a),
        keep=keep,
    )
