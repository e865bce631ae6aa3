"""Trajectory experiments on the virtual joint: any motion, static or LuGre truth, raw logs.

The joint (BAS-RBFNN paper eq. 6-7, fricid's sign convention of :class:`~fricid.sim.Joint`)::

    u = J qdd + f(qd, load, T, state) - (p_x cos q - p_y sin q)

with ``u`` the motor torque. Experiments (:class:`Experiment`, built by the functions below):

* ``sine``, ``chirp``, ``multisine``: a position reference crossing zero velocity; the joint
  tracks it under a PD controller with feed-forward ``J qdd_ref - tau_g(q_ref)``;
* ``slow_multisine``: a designed experiment for the Stribeck region, tracked the same way:
  constant-speed plateaus at slow speeds in both directions, then the multi-sine faded in
  (one continuous reference);
* ``stick_slip``: the motor acts as a spring of stiffness ``k`` (N m/rad) pulling the joint
  towards a point moving at a constant speed (the classic spring-load stick-slip rig);
* ``presliding``: a slow torque oscillation below the break-away level: the joint never
  slides, the displacement is the bristles' (micro-radians).

Truths: a :class:`LuGreTruth` (the joint is simulated forward under the controller's torque
by :func:`fricid.models.lugre.simulate_joint`, with ``n_sub`` sub-steps per sample, 16 by
default so that the truth is integrated far more finely than an identification does), or any
static :class:`~fricid.sim.FrictionLaw` of :mod:`fricid.sim.laws` (the joint then follows the
reference exactly and the torque is the inverse dynamics, as in :func:`fricid.sim.simulate`;
torque-driven experiments, ``stick_slip`` and ``presliding``, need a dynamic truth: a static
law does not say what happens at zero velocity).

Sensors (:class:`~fricid.sim.Noise`): :data:`TRAJECTORY_NOISE` by default, the sweeps' noise
without current spikes and with a 24-bit encoder (a motor encoder seen through a gear: 0.37
micro-radians, fine enough to see pre-sliding). The log is the :class:`~fricid.samples.RawLog`
the readers produce: time, position, velocity, current (with ``torque_constant``),
temperature.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import ConfigError
from ..models import lugre
from ..samples import RawLog
from .joint import Joint, Noise, gravity_torque
from .laws import FrictionLaw

__all__ = [
    "KINDS",
    "TRAJECTORY_NOISE",
    "Experiment",
    "LuGreTruth",
    "chirp",
    "multisine",
    "presliding",
    "simulate_trajectory",
    "sine",
    "slow_multisine",
    "stick_slip",
]

#: Experiment kinds.
KINDS = ("sine", "chirp", "multisine", "slow_multisine", "stick_slip", "presliding")

#: Sensors of a trajectory experiment: no current spikes, a 24-bit position encoder.
TRAJECTORY_NOISE = Noise(spike_rate=0.0, position_lsb=2.0 * math.pi / 2**24)


@dataclass(frozen=True)
class LuGreTruth:
    """A LuGre joint as the truth: parameters in :data:`fricid.models.lugre.PARAM_NAMES`
    order (default: the module's typical geared joint), the simulation's sub-steps."""

    theta: np.ndarray = field(default_factory=lambda: np.array([1e4, 1.0, 0.2, 0.5, 0.8, 0.1, 1.0]))
    n_sub: int = 16

    def __post_init__(self) -> None:
        theta = np.asarray(self.theta, dtype=float)
        if theta.shape != (len(lugre.PARAMETERS),) or not np.isfinite(theta).all():
            raise ConfigError(f"LuGreTruth: theta must be {len(lugre.PARAMETERS)} finite numbers")
        object.__setattr__(self, "theta", theta)

    def params(self) -> dict[str, float]:
        """The parameters by name."""
        return dict(zip(lugre.PARAM_NAMES, map(float, self.theta), strict=True))


@dataclass(frozen=True)
class Experiment:
    """One trajectory experiment: a reference (position, velocity, acceleration) tracked
    under PD gains ``kp``, ``kd``, plus a feed-forward torque; ``kind`` one of :data:`KINDS`."""

    kind: str
    time: np.ndarray
    q_ref: np.ndarray
    v_ref: np.ndarray
    a_ref: np.ndarray
    torque: np.ndarray
    kp: float = 0.0
    kd: float = 0.0
    feedforward: bool = True
    temperature: float = 25.0

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ConfigError(f"unknown experiment '{self.kind}'; one of: {', '.join(KINDS)}")

    @property
    def sample_rate(self) -> float:
        return 1.0 / float(self.time[1] - self.time[0])


def _time(duration: float, rate: float) -> np.ndarray:
    if not (duration > 0 and rate > 0 and math.isfinite(duration * rate)):
        raise ConfigError("an experiment needs a positive duration [s] and sample rate [Hz]")
    return np.arange(round(duration * rate)) / rate


def _tracked(kind: str, t, q, v, a, kp: float, kd: float) -> Experiment:
    return Experiment(kind, t, q, v, a, np.zeros_like(t), kp, kd, True)


def sine(duration=10.0, rate=1000.0, amplitude=0.5, frequency=0.5, kp=200.0, kd=5.0) -> Experiment:
    """Track ``amplitude sin(2 pi f t)`` [rad]: two zero-velocity crossings per period."""
    t = _time(duration, rate)
    w = 2 * math.pi * frequency
    return _tracked(
        "sine",
        t,
        amplitude * np.sin(w * t),
        amplitude * w * np.cos(w * t),
        -amplitude * w**2 * np.sin(w * t),
        kp,
        kd,
    )


def chirp(
    duration=20.0, rate=1000.0, amplitude=0.3, f0=0.1, f1=2.0, kp=200.0, kd=5.0
) -> Experiment:
    """Track a linear chirp ``amplitude sin(phi(t))``, frequency from ``f0`` to ``f1`` [Hz]."""
    t = _time(duration, rate)
    c = (f1 - f0) / t[-1] if t[-1] > 0 else 0.0
    phi = 2 * math.pi * (f0 * t + 0.5 * c * t**2)
    w = 2 * math.pi * (f0 + c * t)
    dw = 2 * math.pi * c
    q = amplitude * np.sin(phi)
    v = amplitude * w * np.cos(phi)
    a = amplitude * (dw * np.cos(phi) - w**2 * np.sin(phi))
    return _tracked("chirp", t, q, v, a, kp, kd)


def multisine(
    duration=20.0,
    rate=1000.0,
    amplitude=0.3,
    frequencies=(0.2, 0.5, 1.1, 2.3),
    seed: int = 0,
    kp=200.0,
    kd=5.0,
) -> Experiment:
    """Track a sum of sines with random phases (``seed``), each of ``amplitude / count``."""
    t = _time(duration, rate)
    phases = np.random.default_rng(seed).uniform(0, 2 * math.pi, len(frequencies))
    q, v, a = (np.zeros_like(t) for _ in range(3))
    share = amplitude / len(frequencies)
    for f, p in zip(frequencies, phases, strict=True):
        w = 2 * math.pi * f
        q += share * np.sin(w * t + p)
        v += share * w * np.cos(w * t + p)
        a -= share * w**2 * np.sin(w * t + p)
    return _tracked("multisine", t, q, v, a, kp, kd)


def _plateaus(
    t: np.ndarray, speeds: tuple[float, ...], hold: float, ramp: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Velocity plateaus ``+s, -s`` for each speed ``s`` (``hold`` seconds each), joined by
    raised-cosine ramps of ``ramp`` seconds, from rest to rest; position by the trapezoid rule
    (every pair is symmetric, so the position returns to its start)."""
    levels = [0.0] + [x for s in speeds for x in (s, -s)] + [0.0]
    v, a = np.zeros_like(t), np.zeros_like(t)
    start = 0.0
    for v0, v1 in itertools.pairwise(levels):
        tau = t - start
        inside = (tau >= 0) & (tau < ramp)
        phase = math.pi * tau[inside] / ramp
        v[inside] = v0 + (v1 - v0) * 0.5 * (1 - np.cos(phase))
        a[inside] = (v1 - v0) * 0.5 * (math.pi / ramp) * np.sin(phase)
        steady = (tau >= ramp) & (tau < ramp + hold)
        v[steady] = v1
        start += ramp + (hold if v1 != 0.0 or v0 == 0.0 else 0.0)
    dt = np.diff(t)
    q = np.concatenate(([0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * dt)))
    return q, v, a


def slow_multisine(
    duration=60.0,
    rate=1000.0,
    amplitude=0.3,
    frequencies=(0.2, 0.5, 1.1, 2.3),
    seed: int = 0,
    speeds=(0.03, 0.05, 0.1, 0.2, 0.3),
    share=0.5,
    hold=None,
    ramp=0.25,
    fade=1.0,
    kp=200.0,
    kd=5.0,
) -> Experiment:
    """Slow constant-speed plateaus, then a :func:`multisine`: one continuous reference.

    The first ``share`` of ``duration`` holds each of ``speeds`` [rad/s] for ``hold`` seconds
    (default: that time shared evenly), forwards then backwards, joined by raised-cosine ramps
    of ``ramp`` seconds; the rest is the multi-sine of :func:`multisine`, faded in over
    ``fade`` seconds by a raised-cosine window. A multi-sine alone slides slowly only briefly,
    around its reversals, where a regression must leave samples out (the LuGre state is not
    at its steady value there), so it sees the Stribeck region (``|qd|`` near ``w_s``) on few
    samples; the plateaus give the steady state at those speeds for seconds at a time, as a
    sweep does (the paper's design, [BAS-RBFNN] section 4), while the multi-sine excites the
    dynamics (inertia, gravity, bristles). On the virtual joint it pins the static part
    down but biases sigma_0 (the notes of :mod:`fricid.identify.dynamic.trajectory`, measured by
    ``benchmarks/bench_trajectory.py --experiment slow_multisine``).
    """
    t = _time(duration, rate)
    half = share * t[-1] if t[-1] > 0 else 0.0
    pairs = 2 * len(speeds)
    if hold is None:
        hold = max((half - (pairs + 1) * ramp) / pairs, 0.0)
    slow = t < half
    q, v, a = (np.zeros_like(t) for _ in range(3))
    q[slow], v[slow], a[slow] = _plateaus(t[slow], tuple(speeds), float(hold), float(ramp))
    m = multisine(duration, rate, amplitude, frequencies, seed)
    tau = t[~slow] - t[~slow][0]
    k = np.minimum(tau / fade, 1.0) if fade > 0 else np.ones_like(tau)
    on = k < 1.0
    w = 0.5 * (1 - np.cos(math.pi * k))
    dw = np.where(on, 0.5 * math.pi / fade * np.sin(math.pi * k), 0.0)
    ddw = np.where(on, 0.5 * (math.pi / fade) ** 2 * np.cos(math.pi * k), 0.0)
    n = tau.size
    qm, vm, am = m.q_ref[:n], m.v_ref[:n], m.a_ref[:n]
    q0 = q[slow][-1] if slow.any() else 0.0
    q[~slow] = q0 + w * qm
    v[~slow] = dw * qm + w * vm
    a[~slow] = ddw * qm + 2 * dw * vm + w * am
    return _tracked("slow_multisine", t, q, v, a, kp, kd)


def stick_slip(duration=10.0, rate=1000.0, stiffness=20.0, speed=0.05) -> Experiment:
    """The motor as a spring of ``stiffness`` [N m/rad] towards a point moving at ``speed``
    [rad/s] (reversing every quarter of the run): stick, break away, slip, stick again."""
    t = _time(duration, rate)
    quarter = t[-1] / 4 if t[-1] > 0 else 1.0
    # a triangle: out and back twice, so the drive crosses zero velocity
    phase = np.mod(t, 2 * quarter)
    target = speed * np.where(phase < quarter, phase, 2 * quarter - phase)
    v = speed * np.where(phase < quarter, 1.0, -1.0)
    return Experiment(
        "stick_slip", t, target, v, np.zeros_like(t), np.zeros_like(t), stiffness, 0.0, False
    )


def presliding(duration=4.0, rate=1000.0, torque=0.3, frequency=0.5) -> Experiment:
    """A torque ``torque sin(2 pi f t)`` [N m], below break-away: pre-sliding only."""
    t = _time(duration, rate)
    tau = torque * np.sin(2 * math.pi * frequency * t)
    zeros = np.zeros_like(t)
    return Experiment("presliding", t, zeros, zeros, zeros, tau, 0.0, 0.0, False)


def simulate_trajectory(
    experiment: Experiment,
    truth: LuGreTruth | FrictionLaw,
    joint: Joint | None = None,
    *,
    noise: Noise = TRAJECTORY_NOISE,
    seed: int = 0,
) -> RawLog:
    """Run ``experiment`` on the virtual joint; the log as a reader would give it.

    Parameters
    ----------
    experiment : Experiment
        From :func:`sine`, :func:`chirp`, :func:`multisine`, :func:`stick_slip`,
        :func:`presliding`.
    truth : LuGreTruth or FrictionLaw
        The joint's friction (see the module notes).
    joint : Joint, optional
        Inertia, gravity and torque constant (its ``law`` is ignored); default a horizontal
        joint with J = 0.01 kg m^2 and K = 0.5 N m/A.
    noise : Noise
        Sensor noise (:data:`TRAJECTORY_NOISE`).
    seed : int
        Seed of the noise.

    Returns
    -------
    RawLog
        Current (``I = u / K`` plus noise, quantised), measured velocity, encoder position and
        temperature; ``meta`` holds the experiment, the truth (``truth``, ``inertia``,
        ``p_x``, ``p_y``) and the seed.
    """
    joint = joint or Joint(law=lambda v, load, temp: np.zeros_like(v))
    e = experiment
    t = np.asarray(e.time, dtype=float)
    n = t.size
    rng = np.random.default_rng(seed)
    ff = e.torque.copy()
    if e.feedforward:
        ff += joint.inertia * e.a_ref - gravity_torque(e.q_ref, joint.p_x, joint.p_y)
    if isinstance(truth, LuGreTruth):
        if e.feedforward:
            ff += lugre.steady_state(truth.theta, e.v_ref)
        sim = lugre.simulate_joint(
            truth.theta,
            joint.inertia,
            joint.p_x,
            joint.p_y,
            np.diff(t, prepend=t[0]),
            ff,
            q0=e.q_ref[0],
            v0=e.v_ref[0],
            z0=np.sign(e.v_ref[0])
            * lugre.stribeck_curve(truth.theta, e.v_ref[:1])[0]
            / truth.theta[0],
            reference=(e.q_ref, e.v_ref),
            gains=(e.kp, e.kd),
            n_sub=truth.n_sub,
        )
        q, v, u = sim["position"], sim["velocity"], sim["torque"]
        truth_meta = {"model": "lugre", **truth.params()}
    elif callable(truth):
        if not e.feedforward:
            raise ConfigError(
                f"a '{e.kind}' experiment is driven by torque: it needs a dynamic truth "
                "(LuGreTruth); a static law does not say what happens at zero velocity"
            )
        q, v = e.q_ref, e.v_ref
        u = ff + np.asarray(truth(v, gravity_torque(q, joint.p_x, joint.p_y), e.temperature))
        truth_meta = {"model": repr(truth)}
    else:
        raise ConfigError("truth must be a LuGreTruth or a friction law")
    if not np.isfinite(u).all() or not np.isfinite(q).all():
        raise ConfigError("the trajectory simulation diverged (non-finite state)")
    current = u / joint.torque_constant + rng.normal(0.0, noise.current_std, n)
    if noise.current_lsb > 0:
        current = np.round(current / noise.current_lsb) * noise.current_lsb
    v_meas = v + (noise.velocity_rel_std * np.abs(v) + noise.velocity_abs_std) * (
        rng.standard_normal(n)
    )
    q_meas = np.round(q / noise.position_lsb) * noise.position_lsb if noise.position_lsb else q
    temperature = e.temperature + rng.normal(0.0, noise.temperature_std, n)
    meta = {
        "experiment": e.kind,
        "truth": truth_meta,
        "inertia": joint.inertia,
        "p_x": joint.p_x,
        "p_y": joint.p_y,
        "seed": int(seed),
    }
    return RawLog(
        time=t,
        position=q_meas,
        velocity=v_meas,
        temperature=temperature,
        current=current,
        torque_constant=joint.torque_constant,
        joint="virtual",
        source=f"sim:{e.kind}",
        meta=meta,
    )


def with_temperature(experiment: Experiment, temperature: float) -> Experiment:
    """The same experiment at another temperature [degC]."""
    return replace(experiment, temperature=float(temperature))
