"""A whole arm simulated as the truth to test identification against: its own integrator of
the rigid-body dynamics, each joint's friction, a drive's tracking controller and its sensors.

The plant is ``M(q) ddq + C(q, dq) dq + g(q) = u - F(dq)``, the rigid-body dynamics of a
:class:`~fricid.robot.RigidBodyModel` (by :meth:`~fricid.robot.RigidBodyModel.forward_dynamics`,
Pinocchio's ABA) with the motor torque ``u`` and each joint's friction ``F``
(:class:`~fricid.sim.robot_friction.ArmFriction`; LuGre on chosen joints,
:mod:`fricid.sim.robot_lugre`). Integration, per internal step ``h`` (the sample period split
into equal steps of at most ``integrator_step``, default 0.5 ms, less with LuGre joints: see
:func:`fricid.sim.robot_lugre.bristle_step`), is split (Strang splitting,
second order; ``benchmarks/bench_robot_sim.py`` measures it):

1. friction over ``tau = h / 2`` by a linearly implicit theta-method, ``(M + tau Theta D) dv =
   -tau F(v)`` with ``D = diag(dF_j / dv_j)`` and ``theta_j = 1/2 + z_j / (2 (1 + |z_j|))``,
   ``z_j = tau D_j (M^-1)_jj``: where a joint slides (``z_j`` small) this is the linearised
   trapezoidal rule, second order; on the steep smoothed sign at zero velocity (slope
   ``tau_s / v_eps``, ``z_j`` large) it is Rosenbrock-Euler, L-stable, so the sign neither
   limits the step nor makes the joint chatter. (Rosenbrock-Euler throughout held a sliding
   joint's friction low by ``h D_j / 2 m_j``, 0.85 % on the Panda's wrist at 0.125 ms; ROS2
   changed how long the wrist sticks, unlike smaller steps.) Where a Stribeck fall makes
   ``z_j < 0``, ``1 + theta_j z_j`` stays in (1/2, 1); LuGre joints keep ``theta = 1``;
2. the rest, classical Runge-Kutta (RK4) over ``h`` with ``u`` held: 4 ABA calls;
3. friction over ``h / 2`` again (merged with the next step's first half inside a period).

Without friction this is RK4 itself (the double pendulum's energy drifts by ~1e-7 of its
kinetic energy over 2 s at 0.5 ms steps).

The drive, at the log's ``rate``: the controller reads the quantised position (an encoder of
``encoder_counts`` per revolution: ``q_m = 2 pi / counts round(q counts / 2 pi)``) and the
velocity by backward differences of it, low-pass filtered (first order, ``velocity_filter``
Hz), and holds its command ``u`` for one period (zero-order hold). A prismatic joint's
position is quantised in the same steps, read as metres. Controllers:

- ``"pd"``: ``u = Kp (q_r - q_m) + Kd (dq_r - dq_m)`` (+ the model's inverse dynamics of the
  reference with ``feedforward=True``), gains by default for a ``bandwidth`` [Hz] and damping
  ratio 1 on the inertia each joint meets at ``q_0``, lowered on a joint whose inertia along
  the reference falls so far that the sampled loop would ring (:mod:`fricid.sim.robot_drive`);
- ``"torque"``: computed torque, ``u = ID(q_m, dq_m, ddq_r + w^2 e + 2 w de)``, ``w = 2 pi
  bandwidth``;
- ``"none"``: ``u = 0`` (the arm falls freely; tests of the integrator).

The log (a :class:`~fricid.samples.RobotLog`) holds the quantised position, the raw backward-
difference velocity (as drives log it) and the torque ``u + e``, ``e ~ N(0, torque_noise^2)``;
:class:`RobotTruth` holds the true states, accelerations, friction, command and parameters.
Another simulator of the same arm can take the integrator's place (``plant=``):
``benchmarks/_robot_truth.py`` runs MuJoCo on the exported MJCF under the same drive.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ConfigError, DataQualityWarning, user_stacklevel
from ..robot import RigidBodyModel
from ..robot._pin import pinocchio
from ..samples import RobotLog
from .robot_drive import (
    CONTROLLERS,
    default_gains,
    least_inertia,
    make_drive,
    per_joint,
    quantise,
)
from .robot_friction import ArmFriction
from .robot_lugre import LuGreBristles, bristle_step

__all__ = [
    "CONTROLLERS",
    "RobotRun",
    "RobotTruth",
    "default_gains",
    "quantise",
    "run_robot",
    "shared_model",
    "simulate_robot",
]


def shared_model(kinds: dict[str, str]) -> str:
    """The friction model every joint of ``kinds`` (joint -> model) has, or ``"per joint"``
    (the log's ``friction_models`` then says which)."""
    models = set(kinds.values())
    return models.pop() if len(models) == 1 else "per joint"


#: A sign change of the true velocity between consecutive samples, both beyond this speed
#: [rad/s], in more than this share of the samples is chatter (:func:`_warn_chatter`).
CHATTER_SPEED, CHATTER_SHARE = 0.01, 0.05

#: Default internal step [s]: 60 s of the Panda at 1 kHz take about 10 s of CPU time.
DEFAULT_STEP = 5e-4


@dataclass(frozen=True, eq=False)
class RobotTruth:
    """What the log came from, sample by sample (rows as the log's).

    Attributes
    ----------
    joints : tuple of str
    time : ndarray (N,)
    position, velocity : ndarray (N, n)
        The true states at the sample instants [rad, rad/s].
    acceleration : ndarray (N, n)
        The true velocity's central difference over the neighbouring samples [rad/s^2] (one-
        sided at the ends). ``M^-1 (u - C dq - g - F(dq))`` at the sample, what this held
        before, is not the motion where a joint sticks: the smoothed sign at the sampled
        velocity is not the friction holding it (a PD-tracked double pendulum: RMS 240 and 411
        rad/s^2 against 4 and 9 of its velocity's differences).
    torque : ndarray (N, n)
        The motor command ``u`` held from each sample to the next, noiseless [N m].
    friction_torque : ndarray (N, n)
        ``F(dq)`` at the true velocity [N m].
    reference : tuple of three ndarray (N, n)
        The tracked ``q_r, dq_r, ddq_r``.
    friction : ArmFriction
        The static law; ``friction_parameters[joint]`` gives each joint's law in the names of
        fricid's model ``friction_models[joint]`` (``stribeck_asym``, or ``lugre`` for the
        LuGre joints, whose ``friction_torque`` comes from their bristle states).
    parameters : ndarray (10 n,)
        The true standard inertial parameters (``model.parameters()``).
    step : float
        The internal integrator step [s].
    """

    joints: tuple[str, ...]
    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    torque: np.ndarray
    friction_torque: np.ndarray
    reference: tuple[np.ndarray, np.ndarray, np.ndarray]
    friction: ArmFriction
    parameters: np.ndarray
    step: float
    friction_parameters: dict = field(default_factory=dict)
    friction_models: dict = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class RobotRun:
    """A simulated log and its truth (:func:`run_robot`)."""

    log: RobotLog
    truth: RobotTruth


def _evaluate(reference: Any, t: np.ndarray, n: int) -> tuple[np.ndarray, ...]:
    fn = getattr(reference, "evaluate", reference)
    if not callable(fn):
        raise ConfigError("the reference must be callable as reference(t) -> (q, dq, ddq)")
    out = tuple(np.asarray(x, dtype=float) for x in fn(t))
    if len(out) != 3 or any(x.shape != (t.size, n) for x in out):
        raise ConfigError(f"the reference must give (q, dq, ddq) of shape ({t.size}, {n})")
    if not all(np.isfinite(x).all() for x in out):
        raise ConfigError("the reference gives non-finite values")
    return out


def _substeps(rate: float, step: float) -> int:
    if not (math.isfinite(rate) and rate > 0 and math.isfinite(step) and step > 0):
        raise ConfigError(f"rate and integrator_step must be > 0; got {rate!r}, {step!r}")
    return max(1, math.ceil(1.0 / (rate * step) - 1e-9))


def _pin_calls(model: RigidBodyModel) -> tuple[Any, Any]:
    """One sample's ``forward_dynamics`` ``(q, dq, tau) -> ddq`` and ``M(q)^-1``, fast.

    Pinocchio's ABA and ``computeMinverse`` on the model's own Pinocchio model and data: the
    public :meth:`~fricid.robot.RigidBodyModel.forward_dynamics` checks and reshapes its
    arguments on every call, which costs about twice the ABA itself, and the integrator calls
    it four times per step (``tests/sim/test_robot_sim.py`` checks that the two agree).
    """
    pin = pinocchio()
    pm, pd = model._model, model._data

    def aba(q: np.ndarray, v: np.ndarray, u: np.ndarray) -> np.ndarray:
        return pin.aba(pm, pd, q, v, u)

    def minv(q: np.ndarray) -> np.ndarray:
        return pin.computeMinverse(pm, pd, q)

    return aba, minv


class _Plant:
    """The split integrator (module notes) of one arm with friction."""

    def __init__(
        self,
        model: RigidBodyModel,
        friction: ArmFriction | None,
        h: float,
        substeps: int,
        bristles: LuGreBristles | None = None,
    ) -> None:
        self.friction, self.h, self.substeps, self.bristles = friction, h, substeps, bristles
        self.eye = np.eye(model.n)
        self.static = np.ones(model.n)  # 0 on the LuGre joints
        if bristles is not None:
            self.static[bristles.index] = 0.0
        self._accel, self._minv = _pin_calls(model)
        from scipy.linalg.lapack import dgesv

        self._dgesv = dgesv

    def _static(self, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if self.friction is None:
            return np.zeros_like(v), np.zeros_like(v)
        force, slope = self.friction.row_slope(v)
        return force * self.static, slope * self.static

    def _friction_step(self, q: np.ndarray, v: np.ndarray, h: float) -> np.ndarray:
        """``v'`` of ``M (v' - v) = -h F(v + theta (v' - v))``, linearised about ``v``: the
        linearly implicit theta-method (module notes), ``theta = 1`` on LuGre joints."""
        if self.friction is None and self.bristles is None:
            return v
        minv = self._minv(q)
        force, slope = self._static(v)
        z = h * slope * np.diagonal(minv)  # each joint's stiffness over the step
        theta = 0.5 + 0.5 * z / (1.0 + np.abs(z))
        lugre = self.bristles
        if lugre is not None:
            force[lugre.index], slope[lugre.index] = lugre.step_force(v[lugre.index], h)
            theta[lugre.index] = 1.0
        # LAPACK's dgesv: numpy's solve costs four times as much on 7 x 7
        _, _, dv, info = self._dgesv(self.eye + h * minv * (theta * slope), -h * (minv @ force))
        if info != 0:
            raise ConfigError("the implicit friction step is singular (a far too large step)")
        v = v + dv
        if lugre is not None:
            lugre.commit(v[lugre.index], h)
        return v

    def _rk4(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        h = self.h
        k1v = self._accel(q, v, u)
        v2 = v + 0.5 * h * k1v
        k2v = self._accel(q + 0.5 * h * v, v2, u)
        v3 = v + 0.5 * h * k2v
        k3v = self._accel(q + 0.5 * h * v2, v3, u)
        v4 = v + h * k3v
        k4v = self._accel(q + h * v3, v4, u)
        q = q + h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4)
        return q, v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)

    def advance(self, q, v, u) -> tuple[np.ndarray, np.ndarray]:
        """The state one sample period later under the held command ``u`` (Strang splitting:
        half a friction step, then RK4 steps with full friction steps between them, then half
        a friction step)."""
        v = self._friction_step(q, v, 0.5 * self.h)
        for i in range(self.substeps):
            q, v = self._rk4(q, v, u)
            last = i + 1 == self.substeps
            v = self._friction_step(q, v, 0.5 * self.h if last else self.h)
        return q, v


def run_robot(
    model: RigidBodyModel,
    reference: Any,
    friction: ArmFriction | None,
    *,
    rate: float = 1000.0,
    duration: float | None = None,
    controller: str = "pd",
    gains: tuple[Any, Any] | None = None,
    feedforward: bool = False,
    bandwidth: float = 5.0,
    velocity_filter: float = 100.0,
    encoder_counts: int = 2**17,
    torque_noise: Any = 0.05,
    seed: int | np.random.Generator | None = None,
    integrator_step: float = DEFAULT_STEP,
    initial: tuple[Any, Any] | None = None,
    plant: Any = None,
    lugre: Mapping[str, Any] | None = None,
) -> RobotRun:
    """Simulate ``model`` tracking ``reference`` with ``friction`` (module notes).

    Parameters
    ----------
    model : RigidBodyModel
        The arm (its parameters are the truth).
    reference : object
        ``reference.evaluate(t)`` or ``reference(t)`` -> ``(q, dq, ddq)``, each ``(len(t), n)``
        (:mod:`fricid.sim.robot_reference`).
    friction : ArmFriction or None
        Each joint's friction (None: frictionless).
    rate : float
        Samples and controller updates per second [Hz].
    duration : float, optional
        [s]; default ``reference.duration``. The log has ``round(duration rate)`` samples.
    controller : {"pd", "torque", "none"}
    gains : (Kp, Kd), optional
        PD gains [N m/rad, N m s/rad], scalars or one per joint (default :func:`default_gains`).
    feedforward : bool
        Add the model's inverse dynamics of the reference to the PD command.
    bandwidth : float
        [Hz] of the default gains and of the computed-torque loop.
    velocity_filter : float
        Cut-off [Hz] of the controller's velocity low-pass (the log keeps the raw one).
    encoder_counts : int
        Counts per revolution.
    torque_noise : float or array_like
        Standard deviation [N m] of the logged torque's Gaussian noise, one or per joint.
    seed : int, Generator or None
        The noise's generator (the dynamics are deterministic).
    integrator_step : float
        Largest internal step [s]; the sample period is split into equal steps. LuGre joints
        lower it until their bristles' ringing is resolved
        (:func:`fricid.sim.robot_lugre.bristle_step`; ``truth.step`` holds the step taken).
    initial : (q, dq), optional
        The initial state (default the reference's at ``t = 0``).
    plant : object, optional
        Another simulator of the same arm: ``plant.advance(q, dq, u) -> (q, dq)`` one sample
        period on (``plant.step`` [s] its internal step); default this module's integrator.
        ``friction`` is then only the truth record's law (it should be what ``plant``
        simulates).
    lugre : mapping, optional
        Joint name -> LuGre parameters (:data:`fricid.models.lugre.PARAM_NAMES`, a mapping or
        7 numbers): these joints get LuGre friction (:mod:`fricid.sim.robot_lugre`, bristles
        at rest at the start) instead of ``friction``'s law.

    Returns
    -------
    RobotRun
        ``.log`` (a :class:`RobotLog`) and ``.truth`` (a :class:`RobotTruth`).
    """
    n = model.n
    if friction is not None and friction.n != n:
        raise ConfigError(f"the friction law has {friction.n} joints, the model {n}")
    if duration is None:
        duration = getattr(reference, "duration", None)
        if duration is None:
            raise ConfigError("give a duration: the reference has none")
    substeps = _substeps(rate, integrator_step)
    count = round(float(duration) * rate)
    if count < 2:
        raise ConfigError(f"duration {duration!r} s at {rate!r} Hz gives fewer than 2 samples")
    noise = per_joint(torque_noise, n, "torque_noise")
    rng = np.random.default_rng(seed)
    time = np.arange(count) / rate
    ref = _evaluate(reference, time, n)
    q, v = (ref[0][0].copy(), ref[1][0].copy()) if initial is None else initial
    q, v = np.asarray(q, dtype=float).copy(), np.asarray(v, dtype=float).copy()
    if q.shape != (n,) or v.shape != (n,) or not (np.isfinite(q).all() and np.isfinite(v).all()):
        raise ConfigError(f"the initial state must be {n} finite positions and velocities")
    ff = np.zeros((count, n))
    if feedforward and controller == "pd":
        ff = model.inverse_dynamics(*ref)
    drive = make_drive(
        model, controller, gains, q, v, rate, encoder_counts, bandwidth, velocity_filter, ref[0]
    )
    if plant is None:
        bristles = LuGreBristles(model.joints, lugre) if lugre else None
        if bristles is not None:  # resolve the bristles' ringing (fricid.sim.robot_lugre)
            step = bristle_step(bristles, least_inertia(model, ref[0][:: max(count // 25, 1)]))
            substeps = max(substeps, _substeps(rate, step))
        plant = _Plant(model, friction, 1.0 / (rate * substeps), substeps, bristles)
    elif lugre:
        raise ConfigError("LuGre joints are simulated by fricid's own plant only")
    out = {k: np.empty((count, n)) for k in ("q", "v", "qm", "vm", "u")}
    # friction that depends on a state (LuGre bristles) is recorded as it goes
    bristles = _plant_lugre(plant)
    lugre_f = np.zeros((count, 0 if bristles is None else bristles.index.size))
    for k in range(count):
        qm, vm = drive.read(q)
        u = drive.command(qm, (ref[0][k], ref[1][k], ref[2][k]), ff[k])
        for key, value in zip(out, (q, v, qm, vm, u), strict=True):
            out[key][k] = value
        if bristles is not None:
            lugre_f[k] = bristles.force(v[bristles.index])
        if not (np.isfinite(q).all() and np.isfinite(v).all()):
            raise ConfigError(f"the simulation diverged at t = {time[k]:.4g} s")
        if k + 1 < count:
            q, v = plant.advance(q, v, u)
    step = float(getattr(plant, "h", getattr(plant, "step", float("nan"))))
    _warn_chatter(out["v"], model.joints, step)
    out["f"] = np.zeros_like(out["v"]) if friction is None else friction(out["v"])
    if bristles is not None:
        out["f"][:, bristles.index] = lugre_f
    lugre_params = {} if bristles is None else bristles.parameters()
    return _assemble(
        model, friction, lugre_params, out, time, ref, noise, rng, step, rate, encoder_counts
    )


def _warn_chatter(v: np.ndarray, joints: tuple[str, ...], step: float) -> None:
    """Warn of joints whose true velocity changes sign between consecutive samples, both
    beyond :data:`CHATTER_SPEED`, in more than :data:`CHATTER_SHARE` of the samples: a joint
    that sticks does not, an integrator step too coarse for a light joint's friction does
    (the double pendulum at 0.5 ms: 36 % and 19 % of the samples of its two joints, 0.9 % and
    4 % at 62.5 us; the Panda at 0.5 ms: none)."""
    if len(v) < 3:
        return
    big = np.abs(v) > CHATTER_SPEED
    flips = ((v[1:] * v[:-1] < 0) & big[1:] & big[:-1]).mean(axis=0)
    bad = [
        f"{j} ({100 * x:.0f} % of the samples)"
        for j, x in zip(joints, flips, strict=True)
        if x > CHATTER_SHARE
    ]
    if bad:
        warnings.warn(
            f"the simulated velocity of {', '.join(bad)} flips sign from one sample to the "
            f"next (both faster than {CHATTER_SPEED:g} rad/s): the joints chatter at the "
            f"internal step of {step:.3g} s, too coarse for their friction and inertia, so the "
            "motion there is the integrator's, not the friction law's; try a step several "
            "times smaller (integrator_step=, or --integrator-step of fricid robot simulate; "
            "the double pendulum stopped chattering at a sixteenth of 5e-4 s)",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )


def _plant_lugre(plant: Any) -> LuGreBristles | None:
    """The LuGre joints of a plant, if it has any."""
    return getattr(plant, "bristles", None)


def _assemble(model, friction, lugre, out, time, ref, noise, rng, h, rate, counts) -> RobotRun:
    n = model.n
    f_true = out["f"]
    acc = np.gradient(out["v"], axis=0) * rate if len(time) > 1 else np.zeros_like(out["v"])
    torque = out["u"] + rng.standard_normal(out["u"].shape) * noise
    params = (
        {} if friction is None else {j: friction.parameters(i) for i, j in enumerate(model.joints)}
    )
    params.update(lugre)
    kinds = {j: "lugre" if j in lugre else "stribeck_asym" for j in params}
    truth = RobotTruth(
        joints=model.joints,
        time=time,
        position=out["q"],
        velocity=out["v"],
        acceleration=acc,
        torque=out["u"],
        friction_torque=f_true,
        reference=ref,
        friction=friction,
        parameters=model.parameters(),
        step=h,
        friction_parameters=params,
        friction_models=kinds,
    )
    meta = {
        "simulated": "fricid.sim.robot",
        "encoder_counts": int(counts),
        "rate_hz": float(rate),
        "torque_noise": [float(x) for x in noise[:n]],
        "integrator_step": float(h),
        "friction_model": shared_model(kinds),
        "friction": params,
        "friction_models": kinds,
    }
    log = RobotLog(
        time=time,
        joints=model.joints,
        position=out["qm"],
        velocity=out["vm"],
        torque=torque,
        source="simulated",
        meta=meta,
    )
    return RobotRun(log, truth)


def simulate_robot(model: RigidBodyModel, reference: Any, friction: ArmFriction | None, **options):
    """The log of :func:`run_robot` alone (same arguments): a :class:`RobotLog`."""
    return run_robot(model, reference, friction, **options).log
