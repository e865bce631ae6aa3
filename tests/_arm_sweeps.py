"""Constant-velocity sweeps of a whole arm, simulated from its rigid-body model: the truth the
arm extraction tests compare with.

Each joint is swept in both directions at each speed while the other joints are held at a
configuration that changes with the speed (a campaign measured in several poses); the torque
is the model's inverse dynamics plus the swept joint's friction (Coulomb and viscous, per
direction) plus Gaussian noise. Held joints carry no friction term (their samples are never
steady sweeps). Nothing here uses fricid's extraction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fricid.samples import RobotLog


@dataclass(frozen=True)
class Law:
    """Per-direction Coulomb and viscous friction: ``fc_pos + fv_pos v`` (v > 0),
    ``-fc_neg + fv_neg v`` (v < 0) [N m, N m s/rad]."""

    fc_pos: float
    fc_neg: float
    fv_pos: float
    fv_neg: float

    def __call__(self, v) -> np.ndarray:
        v = np.asarray(v, dtype=float)
        return np.where(
            v > 0,
            self.fc_pos + self.fv_pos * v,
            np.where(v < 0, -self.fc_neg + self.fv_neg * v, 0.0),
        )


def _move(start: float, stop: float, speed: float, accel: float, dt: float):
    """Position, velocity, acceleration of a trapezoidal move from ``start`` to ``stop``."""
    span = abs(stop - start)
    sign = np.sign(stop - start)
    t_acc = speed / accel
    t_cruise = max(span / speed - t_acc, 0.0)
    total = 2 * t_acc + t_cruise
    t = np.arange(0.0, total, dt)
    a = np.where(t < t_acc, accel, np.where(t < t_acc + t_cruise, 0.0, -accel))
    v = np.where(
        t < t_acc,
        accel * t,
        np.where(
            t < t_acc + t_cruise, speed, np.maximum(speed - accel * (t - t_acc - t_cruise), 0.0)
        ),
    )
    x = np.where(
        t < t_acc,
        0.5 * accel * t**2,
        np.where(
            t < t_acc + t_cruise,
            0.5 * speed * t_acc + speed * (t - t_acc),
            span - 0.5 * accel * np.maximum(total - t, 0.0) ** 2,
        ),
    )
    return start + sign * x, sign * v, sign * a


def arm_sweeps(
    model,
    spans: dict[str, tuple[float, float]],
    poses: dict[str, list[np.ndarray]],
    laws: dict[str, Law],
    *,
    speeds=(0.2, 0.4, 0.8),
    repeats: int = 2,
    rate: float = 100.0,
    accel: float = 4.0,
    noise: float = 0.01,
    velocity_noise: float = 1e-3,
    rest: float = 0.3,
    companion: float = 0.0,
    seed: int = 0,
) -> RobotLog:
    """Sweeps of the joints in ``spans`` (low, high [rad]); speed ``k`` of joint ``j`` is
    swept with the whole arm at ``poses[j][k % len(poses[j])]`` (its own entry replaced by
    the sweep); torque from ``model`` (the truth) plus the friction ``laws`` of every moving
    joint and noise [N m]. With ``companion`` [rad/s] the other joints of ``laws`` are not
    held but move at that constant speed through each move (the sign alternating with the
    swept joint's direction)."""
    rng = np.random.default_rng(seed)
    dt = 1.0 / rate
    chunks_q, chunks_dq, chunks_ddq, chunks_f = [], [], [], []
    for joint, (lo, hi) in spans.items():
        j = model.joints.index(joint)
        for k, speed in enumerate(speeds):
            pose = np.asarray(poses[joint][k % len(poses[joint])], dtype=float)
            for _ in range(repeats):
                for a, b in ((lo, hi), (hi, lo)):
                    x, v, acc = _move(a, b, speed, accel, dt)
                    still = int(rest * rate)
                    x = np.concatenate([np.full(still, a), x])
                    v = np.concatenate([np.zeros(still), v])
                    acc = np.concatenate([np.zeros(still), acc])
                    q = np.tile(pose, (x.size, 1))
                    dq = np.zeros_like(q)
                    others = [model.joints.index(o) for o in laws if o != joint]
                    if companion:
                        w = companion * np.sign(b - a)
                        q[:, others] += w * dt * np.arange(x.size)[:, None]
                        dq[:, others] = w
                        pose = q[-1].copy()
                    q[:, j] = x
                    dq[:, j] = v
                    ddq = np.zeros_like(q)
                    ddq[:, j] = acc
                    f = np.zeros_like(q)
                    for name, law in laws.items():
                        k = model.joints.index(name)
                        f[:, k] = law(dq[:, k])
                    chunks_q.append(q)
                    chunks_dq.append(dq)
                    chunks_ddq.append(ddq)
                    chunks_f.append(f)
    q, dq, ddq, f = (np.concatenate(c) for c in (chunks_q, chunks_dq, chunks_ddq, chunks_f))
    tau = model.inverse_dynamics(q, dq, ddq) + f + rng.normal(0.0, noise, q.shape)
    measured = dq + rng.normal(0.0, velocity_noise, dq.shape) * (dq != 0)
    return RobotLog(
        time=np.arange(q.shape[0]) * dt,
        joints=model.joints,
        position=q,
        velocity=measured,
        torque=tau,
        temperature=25.0,
        source="arm_sweeps",
    )


def perturbed(model, rng, low: float = 0.1, high: float = 0.2):
    """``model`` with every body's inertial parameters scaled by ``1 +- u``, ``u`` uniform in
    [low, high] (a URDF whose masses are off by 10-20 %; scaling keeps each body physical)."""
    pi = model.parameters().reshape(model.n, 10)
    factor = 1 + rng.choice([-1.0, 1.0], model.n) * rng.uniform(low, high, model.n)
    return model.with_parameters((pi * factor[:, None]).ravel())
