"""A robot log's signals for whole-arm identification: zero-phase low-pass, derivatives,
the same filter on the torque ("parallel filtering"), decimation.

The inverse dynamic identification model (IDIM) needs ``q``, ``dq``, ``ddq`` at every sample;
a real arm logs a quantised position (an encoder) and a noisy torque. Following Gautier
(1997, "Dynamic identification of robots with power model") and Gautier, Janot and Vandanjon
(2013, IEEE T-CST, the IDIM-LS "done right"):

* the position is low-passed by a Butterworth filter of order 4 run forwards and backwards
  (``scipy.signal.filtfilt``: zero phase, order 8), and ``dq``, ``ddq`` are central
  differences of the filtered position;
* the torque passes through the *same* filter (parallel filtering), so that the filter acts
  alike on both sides of ``tau = Y beta``. The regressor is not taken at the low-passed
  states: ``Y(q_f, dq_f, ddq_f) beta`` is the low-passed rigid-body torque only to first
  order in the motion's high-frequency part, and in closed loop a joint's acceleration jumps
  where it stops or breaks away (by its friction over its inertia, within milliseconds), so
  the low-pass of ``M(q) ddq`` is not ``M(q_f) ddq_f`` on every joint it is coupled to.
  ``Y`` is computed at the log's rate, on states through a low-pass
  :data:`REGRESSOR_OVER_CUTOFF` times wider than the cut-off (only to take the encoder's steps
  out of the products), and then goes through the torque's filters, column by column:
  ``filter(Y(q, dq, ddq)) beta = filter(tau)`` where the wide low-pass passes the motion. On
  a 5 Hz PD-tracked Panda (``benchmarks/bench_robot.py --truth sim``, tuning seed 100, 20 s,
  no torque noise, the true parameters) the residual of joints 1-4 on the fitted rows fell
  from 0.56-1.01 times the filtered noise to 0.23-0.39 (the inertial term 0.44-0.94 of it,
  the velocity terms 0.11-0.13, gravity nil); it had followed the other joints' reversals
  (0.8-0.9 within 0.1 s of one, 0.15-0.5 beyond 0.2 s). The torque goes
  through that low-pass exactly once, as the states did: a drive tracking a quantised
  position in closed loop commands a broadband torque (its feedback of the encoder steps),
  which the arm follows; where the torque went through a second low-pass at the same cut-off
  that the states did not (or the reverse), that band's torque was left without its motion
  (on a 5 Hz PD-tracked Panda: 2 to 5 times the filtered noise, with the true parameters);
* each joint's friction is a law of the joint's *true* velocity, which is not smooth where a
  joint stops or reverses in closed loop (it sticks for some milliseconds, then breaks
  away), and the low-pass of ``F(v)`` is not ``F`` of the low-passed velocity there. The
  friction columns of such a log (``stops``) are ``F`` of a velocity through a wider low-pass
  (:data:`FRICTION_OVER_CUTOFF` times the cut-off: its encoder noise stays far below any
  Stribeck velocity), then through the torque's filter like the torque. Where the joints do
  not stick, the velocity through the cut-off itself times a reversal better (with the
  wider one, on the open-loop truth, the held-out error of some joints grew by a third);
* all are then decimated to a rate of about :data:`RATE_OVER_CUTOFF` times the cut-off, since
  the filtered signals carry nothing above it, and a filter transient of :data:`EDGE_PERIODS`
  periods of the cut-off is dropped at each end.

The cut-off ``f_c`` (:func:`choose_cutoff`) is the smallest of three bounds:

1. ``SIGNAL_FACTOR`` times the motion's bandwidth ``f_m`` (the frequency below which
   :data:`SIGNAL_POWER` of the velocity's power lies, from the differenced position's
   spectrum less the encoder's expected quantisation noise): the dynamics must pass
   undistorted;
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

from dataclasses import dataclass, replace

import numpy as np
import scipy.signal

from ....errors import DataError

__all__ = ["ArmSignals", "choose_cutoff", "encoder_step", "prepare_signals"]

#: Butterworth order (doubled by the forward-backward pass).
BUTTER_ORDER = 4
#: Share of the velocity's power below the motion's bandwidth.
SIGNAL_POWER = 0.99
#: Times its expected periodogram the encoder's noise is taken out of the velocity's spectrum
#: (a periodogram bin of noise alone is exponential: exceeding 5 times its mean has
#: probability e^-5).
NOISE_MARGIN = 5.0
#: Cut-off over the motion's bandwidth (bound 1).
SIGNAL_FACTOR = 8.0
#: The cut-off is never below this many times the motion's bandwidth.
MIN_OVER_MOTION = 3.0
#: Largest torque noise from the encoder (its acceleration noise times the inertia), over
#: the filtered torque noise (bound 2).
ENCODER_SHARE = 0.5
#: The log's rate over the cut-off, at least (bound 3).
MIN_RATE_OVER_CUTOFF = 5.0
#: The decimated rate over the cut-off.
RATE_OVER_CUTOFF = 5.0
#: The intermediate rate over the cut-off, at least.
MID_RATE_OVER_CUTOFF = 10.0
#: The anti-alias cut-off over the intermediate rate.
ANTI_ALIAS_SHARE = 0.4
#: Filter transient dropped at each end, in periods of the cut-off.
EDGE_PERIODS = 5.0
#: The friction velocity's low-pass over the cut-off (module notes).
FRICTION_OVER_CUTOFF = 6.0
#: The low-pass of the states the regressor is computed at, over the cut-off (module notes).
REGRESSOR_OVER_CUTOFF = 6.0
#: Samples per call when the regressor is computed at the log's rate (bounds the memory).
REGRESSOR_CHUNK = 8192


@dataclass(frozen=True)
class ArmSignals:
    """A log's signals at the identification rate (module notes), shape (N, n) each: the
    states ``q``, ``dq``, ``ddq`` the regressor is computed at, and the torque, already
    through both filters."""

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
    #: the filtered velocity's noise standard deviation from the encoder [rad/s]
    velocity_noise: np.ndarray
    #: the same of the friction's velocity (``full_dq``) [rad/s]
    friction_velocity_noise: np.ndarray
    #: the friction's velocity at the log's full rate (friction columns are computed on it),
    #: the position's derivative through a low-pass at ``friction_cutoff`` [Hz]
    full_dq: np.ndarray
    friction_cutoff: float
    #: the anti-alias filter and its decimation; the low-pass at the log's rate; the rows
    #: kept after decimation (edges cut, decimated)
    anti_alias: tuple[np.ndarray, np.ndarray]
    first: int
    low_pass: tuple[np.ndarray, np.ndarray]
    keep: slice
    #: the torque's change per sample through the same filters (:meth:`delayed`)
    dtau: np.ndarray | None = None
    #: the position at the log's rate through the regressor's wide low-pass (:meth:`regressor`)
    wide_position: np.ndarray | None = None
    #: each joint's stick columns at the kept rows (:mod:`._sticks`), where the joints stick
    stick: tuple[np.ndarray, ...] | None = None
    #: each joint's load torque at the log's full rate [N m] (:mod:`._load`), for the load
    #: families' columns
    full_load: np.ndarray | None = None

    def delayed(self, samples: float) -> ArmSignals:
        """These signals with the torque read ``samples`` sample periods earlier, ``tau(t -
        samples / rate)`` (to first order, which the low-pass makes exact to its pass band):
        a command held from one sample to the next acts half a period after its sample."""
        return replace(self, tau=self.tau - samples * self.dtau)

    def rows(self) -> np.ndarray:
        """The samples of the log (indices at its full rate) the decimated rows stand for."""
        n_mid = len(range(0, self.full_dq.shape[0], self.first))
        return np.arange(n_mid)[self.keep] * self.first

    def regressor(self, model, base) -> np.ndarray:
        """The base regressor ``Y_b`` (N, n, r) of the kept rows: computed at the log's rate on
        the wide-band states, then through what the torque went through (:meth:`parallel`),
        so that ``Y_b beta`` is the filtered rigid-body torque (module notes)."""
        if self.wide_position is None:  # no log-rate states: at the filtered ones
            return base.columns(model.regressor(self.q, self.dq, self.ddq))
        q = self.wide_position
        dq = np.gradient(q, axis=0) * self.rate
        ddq = np.gradient(dq, axis=0) * self.rate
        chunks = [slice(k, k + REGRESSOR_CHUNK) for k in range(0, q.shape[0], REGRESSOR_CHUNK)]
        Y = np.concatenate([base.columns(model.regressor(q[c], dq[c], ddq[c])) for c in chunks])
        n, r = Y.shape[1:]
        return self.parallel(Y.reshape(Y.shape[0], n * r)).reshape(-1, n, r)

    def friction_columns(self, jf, j: int) -> np.ndarray:
        """Joint ``j``'s friction columns (``jf``: its :class:`._friction.JointFriction`) at
        the log's full rate, from ``full_dq`` (and ``full_load``)."""
        load = None if self.full_load is None else self.full_load[:, j]
        return jf.columns(self.full_dq[:, j], load)

    def parallel(self, x: np.ndarray) -> np.ndarray:
        """``x`` (full rate, first axis time) through what the torque went through: the
        low-pass, the anti-alias filter, decimation, the kept rows (module notes)."""
        return _filt(self.anti_alias, _filt(self.low_pass, x))[:: self.first][self.keep]


def _filt(ba: tuple[np.ndarray, np.ndarray], x: np.ndarray) -> np.ndarray:
    """Zero-phase filter along the first axis (time), any trailing shape."""
    x = np.asarray(x, dtype=float)
    flat = np.ascontiguousarray(x.reshape(x.shape[0], -1).T)  # time last: contiguous runs
    out = scipy.signal.filtfilt(*ba, flat, axis=-1).T
    return out.reshape(x.shape)


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


def _bandwidth(q: np.ndarray, rate: float, step: np.ndarray | None = None) -> float:
    """The frequency below which :data:`SIGNAL_POWER` of the velocity's power lies [Hz]
    (Hann-windowed spectrum of the differenced position, summed over the joints), with each
    joint's encoder noise taken out: ``step`` quantisation, white of variance ``step^2 / 12``,
    differenced has the expected periodogram ``sum(w^2) step^2 / 12 f_s^2 4 sin^2(pi f /
    f_s)``, and :data:`NOISE_MARGIN` times it is subtracted (floored at 0), so that a coarse
    encoder's noise, which rises to Nyquist, is not read as motion (a 2^14-count encoder at
    1 kHz had put the bandwidth at 479 Hz and every joint below its noise threshold)."""
    v = np.diff(q, axis=0) * rate
    w = np.hanning(v.shape[0])
    v = (v - v.mean(axis=0)) * w[:, None]
    power = np.abs(np.fft.rfft(v, axis=0)) ** 2
    freqs = np.fft.rfftfreq(v.shape[0], 1.0 / rate)
    if step is not None:
        shape = (w @ w) * rate**2 * 4 * np.sin(np.pi * freqs / rate) ** 2 / 12
        power = np.maximum(power - NOISE_MARGIN * shape[:, None] * step[None, :] ** 2, 0.0)
    cum = np.cumsum(power.sum(axis=1))
    if cum[-1] <= 0:
        return rate / 2
    return float(freqs[min(np.searchsorted(cum, SIGNAL_POWER * cum[-1]), freqs.size - 1)])


def torque_noise(torque: np.ndarray) -> np.ndarray:
    """Each joint's torque noise at the log's rate [N m], from second differences (white
    noise: ``var(d^2 tau) = 6 sigma^2``; a smooth torque adds little at 1 kHz)."""
    d2 = np.diff(torque, 2, axis=0)
    return np.sqrt(np.median(d2**2, axis=0) / 0.4549 / 6)  # median of chi^2_1 is 0.4549


def choose_cutoff(
    q: np.ndarray, rate: float, step: np.ndarray, noise: np.ndarray, inertia: np.ndarray
) -> tuple[float, dict[str, float]]:
    """The low-pass cut-off [Hz] and its bounds (module notes).

    ``noise`` is each joint's torque noise at the log's rate, ``inertia`` its mean diagonal
    of the mass matrix: the encoder's acceleration noise times the inertia is kept below
    :data:`ENCODER_SHARE` times the filtered torque noise.
    """
    f_m = max(_bandwidth(q, rate, step), 10.0 / (q.shape[0] / rate))
    signal = SIGNAL_FACTOR * f_m
    nyquist = rate / MIN_RATE_OVER_CUTOFF
    ok = (step > 0) & (inertia > 0) & (noise > 0)
    encoder = np.inf
    if ok.any():
        per = (
            ENCODER_SHARE * noise[ok] * np.sqrt(60.0) / (inertia[ok] * step[ok] * (2 * np.pi) ** 2)
        )
        encoder = float(np.sqrt(per.min()))
    cutoff = max(min(signal, nyquist, encoder), MIN_OVER_MOTION * f_m)
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
    inertia: np.ndarray | None = None,
    source: str | None = None,
    stops: bool = False,
    part: str = "the log",
) -> ArmSignals:
    """Filter, differentiate and decimate a log's position and torque (module notes);
    ``part`` names the rows in a "too short" message (e.g. the held-out part).

    Parameters
    ----------
    time : ndarray (N,)
    position, torque : ndarray (N, n)
    counts : int, optional
        Encoder counts per revolution (else read from the position's steps).
    cutoff : float, optional
        The low-pass cut-off [Hz] (else :func:`choose_cutoff`).
    inertia : ndarray (n,), optional
        Each joint's mean diagonal of the mass matrix [kg m^2] (the encoder bound; without
        it, that bound is not applied).
    source : str, optional
        The log's file, named in errors.
    stops : bool
        The joints stop and stick (a log recorded in closed loop): the friction's velocity
        through a low-pass :data:`FRICTION_OVER_CUTOFF` times wider than the cut-off, else
        through the cut-off itself (a smooth motion's reversal is timed better by it than by
        a wider low-pass of the encoder's steps).
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
    shortest = 3 * (BUTTER_ORDER + 1) + 1  # scipy's filtfilt pads 3 filter lengths
    if position.shape[0] < shortest:
        raise DataError(
            f"{part} is too short ({position.shape[0]} samples) for the zero-phase low-pass "
            f"of whole-arm identification (it needs far more than {shortest})",
            file=source,
        )
    step = encoder_step(position, counts)
    bounds: dict[str, float] = {}
    if cutoff is None:
        inertia = np.zeros(position.shape[1]) if inertia is None else np.asarray(inertia)
        cutoff, bounds = choose_cutoff(position, rate, step, torque_noise(torque), inertia)
    cutoff = min(float(cutoff), 0.45 * rate)
    low = scipy.signal.butter(BUTTER_ORDER, cutoff / (rate / 2))
    qf = _filt(low, position)
    dq = np.gradient(qf, axis=0) * rate
    ddq = np.gradient(dq, axis=0) * rate
    # the friction's velocity: the same position through a wider low-pass (module notes)
    f_cut = min(FRICTION_OVER_CUTOFF * cutoff, rate / MIN_RATE_OVER_CUTOFF) if stops else cutoff
    wide = scipy.signal.butter(BUTTER_ORDER, f_cut / (rate / 2))
    dq_friction = np.gradient(_filt(wide, position), axis=0) * rate
    r_cut = min(REGRESSOR_OVER_CUTOFF * cutoff, rate / MIN_RATE_OVER_CUTOFF)
    wide_position = _filt(scipy.signal.butter(BUTTER_ORDER, r_cut / (rate / 2)), position)
    # the anti-alias filter far above the cut-off (no droop where the signals are), decimate
    first = max(1, int(rate / (MID_RATE_OVER_CUTOFF * cutoff)))
    mid_rate = rate / first
    anti = scipy.signal.butter(
        BUTTER_ORDER, min(ANTI_ALIAS_SHARE * mid_rate, 0.9 * rate / 2) / (rate / 2)
    )
    edge = int(np.ceil(EDGE_PERIODS * mid_rate / cutoff))
    n_mid = len(range(0, position.shape[0], first))
    if n_mid < 4 * edge + 20:
        raise DataError(
            f"{part} is too short ({position.shape[0]} samples) for a low-pass at {cutoff:.3g} Hz",
            file=source,
        )
    factor = max(1, int(mid_rate / (RATE_OVER_CUTOFF * cutoff)))
    keep = slice(edge, n_mid - edge, factor)
    tau = _filt(anti, _filt(low, torque))[::first][keep]
    dtau = _filt(anti, _filt(low, np.gradient(torque, axis=0)))[::first][keep]
    pick = np.arange(n_mid)[keep] * first
    return ArmSignals(
        time=time[pick],
        q=qf[pick],
        dq=dq[pick],
        ddq=ddq[pick],
        tau=tau,
        rate=rate,
        cutoff=cutoff,
        decimation=first * factor,
        encoder_step=step,
        bounds=bounds,
        velocity_noise=_velocity_noise(step, rate, cutoff),
        friction_velocity_noise=_velocity_noise(step, rate, f_cut),
        full_dq=dq_friction,
        friction_cutoff=f_cut,
        anti_alias=anti,
        first=first,
        low_pass=low,
        keep=keep,
        dtau=dtau,
        wide_position=wide_position,
    )
