"""Faults of a real measurement campaign, injected into the virtual joint's logs on request.

A clean campaign (:func:`fricid.sim.simulate` without faults) is what the BAS-RBFNN paper's
section 2 assumes: trapezoidal traverses, short dwells, constant velocity over the measured
range. Real logs are messier (issue 11, defects 2-4); :class:`Faults` adds, each switched on by
its own option and all off by default:

rest between runs
    ``rest_time`` s of standstill after each traverse (added to the dwell). At rest the logged
    velocity is float residue of magnitude about ``rest_residue`` (1e-15 rad/s) with one sign per
    rest, not zero and not sensor noise; the motor holds a random torque inside the stiction band
    (friction of either sign). Extraction must reject it, not take it as a set-point.
settling transients
    after the acceleration ramp the velocity overshoots by ``overshoot`` (relative) and rings at
    ``settle_frequency``, and the torque carries an extra ``settle_torque`` N m (a current
    controller winding down); both decay with ``settle_tau`` s. The velocity is inside a 5 %
    band long before the torque has settled.
ramps
    the cruise starts at ``(1 - ramp_fraction) v`` and creeps linearly to ``v`` over
    ``ramp_time`` s, and creeps back down before the deceleration: slow ramps at the ends of a
    run, inside a 5 % velocity band.
return moves
    after each period, an unmeasured repositioning move out and back at up to ``return_speed``
    rad/s (a ``sin^2`` velocity profile of ``return_time`` s per leg, no plateau).
spike bursts
    ``burst_rate`` bursts per traverse of ``burst_length`` consecutive samples offset by
    ``burst_size`` A (random sign): longer than a running-median window, so the median filter
    cannot remove them.
saturation
    the current sensor reads at most ``current_range`` A in magnitude (values beyond are clipped).

With any of the motion faults on, each traverse is lengthened by ``fault_run_up`` (the
creep and the settling) at both ends, so the measured range is still crossed at constant,
settled velocity once the transients are trimmed: the oracle's true samples stay the truth.
Faults draw from their own random stream (``SeedSequence(entropy, spawn_key=(temperature,
velocity, repetition, 1))``), so same seed, same faulty log, and a scenario without faults gives
bit-identical logs to one simulated before faults existed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from ..errors import ConfigError
from .design import Profile, Traverse

__all__ = ["FAULT_KINDS", "Faults", "PeriodFaults"]

#: Fault kinds, as named in ``preset("paper1+rest+spikes")`` (``+faults`` switches all on).
FAULT_KINDS: tuple[str, ...] = ("rest", "settling", "ramps", "returns", "spikes", "saturation")


@dataclass(frozen=True)
class Faults:
    """Faults to inject into a simulated campaign (all off by default).

    Attributes
    ----------
    rest_time : float
        s of standstill added after each traverse (0: only the design's dwells, logged with
        ordinary sensor noise).
    rest_residue : float
        rad/s, typical magnitude of the float residue logged as velocity at rest (with
        ``rest_time > 0``; each sample is ``rest_residue * 10**U(-1, 1)``, one sign per rest).
    settle_torque : float
        N m, extra torque at the start of each cruise, decaying with ``settle_tau``.
    overshoot : float
        relative velocity overshoot at the start of each cruise, ringing at
        ``settle_frequency`` and decaying with ``settle_tau``.
    settle_tau : float
        s, time constant of the settling transients.
    settle_frequency : float
        Hz, ringing frequency of the velocity overshoot.
    ramp_fraction : float
        the cruise starts ``ramp_fraction`` below the set-point speed and ends as far below it,
        creeping linearly over ``ramp_time``.
    ramp_time : float
        s, duration of each creep.
    return_speed : float
        rad/s, peak speed of a return move after each period (0: none).
    return_time : float
        s, duration of each leg (out, back) of a return move.
    burst_rate : float
        mean number of spike bursts per traverse (Poisson).
    burst_length : int
        samples per burst.
    burst_size : float
        A, magnitude of a burst's current offset.
    current_range : float
        A, full scale of the current sensor (0: unlimited).
    """

    rest_time: float = 0.0
    rest_residue: float = 1e-15
    settle_torque: float = 0.0
    overshoot: float = 0.0
    settle_tau: float = 0.1
    settle_frequency: float = 4.0
    ramp_fraction: float = 0.0
    ramp_time: float = 0.5
    return_speed: float = 0.0
    return_time: float = 0.6
    burst_rate: float = 0.0
    burst_length: int = 6
    burst_size: float = 3.0
    current_range: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
                raise ConfigError(f"Faults: '{f.name}' must be a number >= 0, got {value!r}")
        if self.ramp_fraction >= 0.5:
            raise ConfigError(f"Faults: 'ramp_fraction' must be < 0.5, got {self.ramp_fraction!r}")
        for name in ("settle_tau", "ramp_time", "return_time"):
            if getattr(self, name) <= 0:
                raise ConfigError(f"Faults: '{name}' must be > 0")
        if int(self.burst_length) != self.burst_length or self.burst_length < 1:
            raise ConfigError("Faults: 'burst_length' must be a positive integer")

    @property
    def active(self) -> bool:
        """True when any fault is switched on."""
        return any(
            (
                self.rest_time,
                self.settle_torque,
                self.overshoot,
                self.ramp_fraction,
                self.return_speed,
                self.burst_rate,
                self.current_range,
            )
        )

    @property
    def motion(self) -> bool:
        """True when the motion itself differs from the clean design's."""
        return bool(
            self.rest_time
            or self.settle_torque
            or self.overshoot
            or self.ramp_fraction
            or self.return_speed
        )

    @property
    def fault_run_up(self) -> float:
        """s of extra cruise at each end of a traverse: the creep plus four settling time
        constants (the transients have decayed to 2 % of their amplitude by then, so the
        measured range is crossed at settled velocity and torque, but an average over the
        whole traverse still includes them)."""
        t = 0.0
        if self.ramp_fraction:
            t += self.ramp_time
        if self.settle_torque or self.overshoot:
            t += 4.0 * self.settle_tau
        return t

    @classmethod
    def typical(cls, kinds=FAULT_KINDS, *, max_speed: float, max_current: float) -> Faults:
        """Faults of the given kinds (:data:`FAULT_KINDS`) at typical magnitudes for a design
        whose fastest set-point is ``max_speed`` rad/s and whose largest steady current is
        ``max_current`` A: 1.5 s of rest, a 50 mN m torque transient and 3 % velocity overshoot
        decaying in 0.15 s, 3 % creeps over 0.5 s, return moves peaking at 1.5x the fastest
        set-point, one 6-sample burst of 3 A every other traverse, and a current range of
        ``1.6 max_current`` (it clips the bursts, not the steady state).

        Parameters
        ----------
        kinds : iterable of str
            Fault kinds to switch on, from :data:`FAULT_KINDS`.
        max_speed : float
            rad/s, the design's fastest set-point.
        max_current : float
            A, the design's largest steady motor current.

        Returns
        -------
        Faults

        Raises
        ------
        ConfigError
            An unknown kind (the message lists the known ones).
        """
        unknown = [k for k in kinds if k not in FAULT_KINDS]
        if unknown:
            raise ConfigError(
                f"unknown fault '{unknown[0]}'; choose from: {', '.join(FAULT_KINDS)} or 'faults'"
            )
        on = set(kinds)
        return cls(
            rest_time=1.5 if "rest" in on else 0.0,
            settle_torque=0.05 if "settling" in on else 0.0,
            overshoot=0.03 if "settling" in on else 0.0,
            settle_tau=0.15,
            ramp_fraction=0.03 if "ramps" in on else 0.0,
            return_speed=1.5 * max_speed if "returns" in on else 0.0,
            burst_rate=0.5 if "spikes" in on else 0.0,
            current_range=1.6 * max_current if "saturation" in on else 0.0,
        )

    def lengthen(self, traverse: Traverse) -> Traverse:
        """The traverse with ``fault_run_up`` of extra cruise at each end."""
        extra = traverse.velocity * self.fault_run_up
        return replace(traverse, start=traverse.start - extra, end=traverse.end + extra)

    def period_length(self, traverse: Traverse) -> int:
        """Samples in one faulty period (see :class:`PeriodFaults`)."""
        t = self.lengthen(traverse)
        fs = t.sample_rate
        n_rest = round((t.dwell + self.rest_time) * fs)
        n_move = math.ceil(t.move_time * fs)
        n_return = 2 * math.ceil(self.return_time * fs) if self.return_speed else 0
        return 2 * (n_rest + n_move) + n_return


@dataclass(frozen=True, eq=False)
class PeriodFaults:
    """One faulty period: its motion and what the sensors add.

    Attributes
    ----------
    profile : Profile
        positions, velocities, accelerations and pass index along the period (rest, forward
        traverse, rest, backward traverse, return move out and back).
    extra_torque : numpy.ndarray
        N m, the settling torque transient (signed with the motion).
    rest : numpy.ndarray
        bool, samples at rest (the rest stretches; the return move is motion).
    rest_id : numpy.ndarray
        int, which rest stretch (0 or 1) each rest sample belongs to, -1 elsewhere.
    """

    profile: Profile
    extra_torque: np.ndarray
    rest: np.ndarray
    rest_id: np.ndarray


def _move(faults: Faults, t: Traverse, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distance, speed and extra torque along one faulty traverse of ``n`` samples."""
    fs = t.sample_rate
    tau = np.arange(n) / fs
    _, speed, _ = t._move(tau)
    ta, tm = t.accel_time, t.move_time
    cruise = (tau >= ta) & (tau <= tm - ta)
    since = np.maximum(tau - ta, 0.0)
    left = np.maximum(tm - ta - tau, 0.0)
    f = faults.ramp_fraction
    if f:
        start = np.clip(1.0 - since / faults.ramp_time, 0, 1)
        end = np.clip(1.0 - left / faults.ramp_time, 0, 1)
        creep = f * (start + end)
        scale = np.where(cruise, 1.0 - np.minimum(creep, f), 1.0 - f)
        speed = speed * scale
    decay = np.where(cruise, np.exp(-since / faults.settle_tau), 0.0)
    if faults.overshoot:
        ring = np.cos(2.0 * math.pi * faults.settle_frequency * since)
        speed = speed * (1.0 + faults.overshoot * decay * ring)
    distance = np.concatenate(([0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) / fs)))
    return distance, speed, faults.settle_torque * decay


def period(faults: Faults, traverse: Traverse, rng: np.random.Generator) -> PeriodFaults:
    """The motion of one faulty period (rest, forward, rest, backward, return move)."""
    t = faults.lengthen(traverse)
    fs = t.sample_rate
    n_rest = round((t.dwell + faults.rest_time) * fs)
    n_move = math.ceil(t.move_time * fs)
    s, speed, extra = _move(faults, t, n_move)
    acc = np.gradient(speed, 1.0 / fs) if n_move > 1 else np.zeros(n_move)
    zeros = np.zeros(n_rest)
    parts_pos = [np.full(n_rest, t.start), t.start + s, np.full(n_rest, t.start + s[-1])]
    parts_pos.append(t.start + s[-1] - s)
    parts_vel = [zeros, speed, zeros, -speed]
    parts_acc = [zeros, acc, zeros, -acc]
    parts_tau = [zeros, extra, zeros, -extra]
    moving = np.zeros(n_move)
    parts_pass = [zeros, moving, zeros, moving + 1]
    rest_id = [zeros, moving - 1, zeros + 1, moving - 1]
    if faults.return_speed:
        n_ret = math.ceil(faults.return_time * fs)
        T = n_ret / fs
        x = np.arange(n_ret) / fs
        v = faults.return_speed * np.sin(math.pi * x / T) ** 2
        d = faults.return_speed * (x / 2.0 - T * np.sin(2.0 * math.pi * x / T) / (4.0 * math.pi))
        a = faults.return_speed * math.pi / T * np.sin(2.0 * math.pi * x / T)
        end = t.start
        parts_pos += [end + d, end + d[-1] - d]
        parts_vel += [v, -v]
        parts_acc += [a, -a]
        parts_tau += [np.zeros(n_ret)] * 2
        parts_pass += [np.zeros(n_ret), np.ones(n_ret)]
        rest_id += [np.full(n_ret, -1.0)] * 2
    rid = np.concatenate(rest_id).astype(np.intp)
    profile = Profile(
        position=np.concatenate(parts_pos),
        velocity=np.concatenate(parts_vel),
        acceleration=np.concatenate(parts_acc),
        pass_index=np.concatenate(parts_pass).astype(np.intp),
    )
    return PeriodFaults(profile, np.concatenate(parts_tau), rid >= 0, rid)


def rest_velocity(faults: Faults, rest_id: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Float residue logged as velocity at rest: ``rest_residue * 10**U(-1, 1)`` per sample,
    one random sign per rest stretch (``rest_id`` 0 or 1; other samples get 0)."""
    signs = np.where(rng.random(2) < 0.5, -1.0, 1.0)
    mag = faults.rest_residue * 10.0 ** rng.uniform(-1.0, 1.0, rest_id.size)
    return np.where(rest_id >= 0, signs[np.maximum(rest_id, 0)] * mag, 0.0)


def bursts(faults: Faults, n: int, rng: np.random.Generator) -> np.ndarray:
    """Current offsets [A] of the spike bursts of one period (two traverses), length ``n``."""
    out = np.zeros(n)
    k = rng.poisson(2.0 * faults.burst_rate)
    length = int(faults.burst_length)
    if k == 0 or n <= length:
        return out
    starts = rng.integers(0, n - length, k)
    signs = np.where(rng.random(k) < 0.5, -1.0, 1.0)
    for start, sign in zip(starts, signs, strict=True):  # k is a handful per period
        out[start : start + length] = sign * faults.burst_size
    return out
