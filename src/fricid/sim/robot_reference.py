"""References a simulated arm tracks: a periodic Fourier series and constant-velocity sweeps.

A reference is anything with ``evaluate(t) -> (q, dq, ddq)`` (arrays of shape ``(len(t), n)``
in rad, rad/s, rad/s^2; m for a prismatic joint) and a ``duration`` [s], or a plain callable
``reference(t) -> (q, dq, ddq)``; :func:`fricid.sim.robot.simulate_robot` takes either.

:class:`FourierTrajectory` (:mod:`fricid.robot.trajectories`, where excitation design makes
them) is the series of Swevers et al. (IEEE T-RA 13(5), 1997, eq. 25)::

    q_i(t) = q0_i + sum_k a_ik / (w_f k) sin(w_f k t) - b_ik / (w_f k) cos(w_f k t)

for ``k = 1..H``; excitation design chooses ``a, b``. :func:`sweep_reference` moves one joint
back and forth at constant velocities (the BAS-RBFNN paper's bidirectional sweeps, section 2)
with the other joints held, each move a trapezoid of velocity (constant acceleration ramps).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..robot.trajectories import FourierTrajectory

__all__ = ["FourierTrajectory", "SweepReference", "random_fourier", "sweep_reference"]


@dataclass(frozen=True, eq=False)
class SweepReference:
    """Constant-velocity moves of one joint, the others held (:func:`sweep_reference`).

    Attributes
    ----------
    joint : int
        The moving joint's column.
    hold : ndarray, shape (n,)
        Every joint's position while it does not move (the moving joint's start).
    starts, q_starts, cruise, accel, ramps, ends : ndarray
        Per move: start time [s], start position, signed cruise velocity [rad/s], acceleration
        magnitude [rad/s^2], ramp time [s], end time [s].
    plateaus : list of (float, float, float)
        ``(t_begin, t_end, velocity)`` of each constant-velocity stretch, for extraction.
    duration : float
        [s]
    drift : ndarray (n,) or None
        Amplitudes [rad] of the other joints' slow motion ``hold + drift sin(2 pi t / T)``.
    drift_period : float
        ``T`` [s].
    """

    joint: int
    hold: np.ndarray
    starts: np.ndarray
    q_starts: np.ndarray
    cruise: np.ndarray
    accel: np.ndarray
    ramps: np.ndarray
    ends: np.ndarray
    plateaus: list
    duration: float
    drift: np.ndarray | None = None
    drift_period: float = 60.0

    def evaluate(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q, dq, ddq)`` at the times ``t`` [s], each ``(len(t), n)``."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        k = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, self.starts.size - 1)
        tau = np.clip(t - self.starts[k], 0.0, self.ends[k] - self.starts[k])
        v, a, r = self.cruise[k], self.accel[k] * np.sign(self.cruise[k]), self.ramps[k]
        span = self.ends[k] - self.starts[k]
        up = np.minimum(tau, r)
        flat = np.clip(tau - r, 0.0, span - 2 * r)
        down = np.clip(tau - (span - r), 0.0, r)
        pos = self.q_starts[k] + 0.5 * a * up**2 + v * flat + v * down - 0.5 * a * down**2
        vel = np.where(tau < r, a * tau, np.where(tau > span - r, v - a * down, v))
        acc = np.where(tau < r, a, np.where(tau > span - r, -a, 0.0))
        inside = (t >= self.starts[k]) & (t < self.ends[k])
        acc = np.where(inside, acc, 0.0)
        q = np.tile(self.hold, (t.size, 1))
        dq, ddq = np.zeros_like(q), np.zeros_like(q)
        if self.drift is not None:
            w = 2.0 * np.pi / self.drift_period
            s, c = np.sin(w * t)[:, None], np.cos(w * t)[:, None]
            q, dq, ddq = q + self.drift * s, self.drift * w * c, -self.drift * w**2 * s
        q[:, self.joint], dq[:, self.joint], ddq[:, self.joint] = pos, vel, acc
        return q, dq, ddq

    __call__ = evaluate


def sweep_reference(
    hold,
    joint: int,
    velocities,
    lower: float,
    upper: float,
    *,
    acceleration: float = 2.0,
    dwell: float = 0.5,
    drift=None,
    drift_period: float = 60.0,
) -> SweepReference:
    """Bidirectional constant-velocity sweeps of joint ``joint`` between ``lower`` and ``upper``.

    For each speed ``v`` of ``velocities`` the joint moves from ``lower`` to ``upper`` at ``+v``
    and back at ``-v``, each move a velocity trapezoid with ramps of ``acceleration``
    [rad/s^2], a ``dwell`` [s] at rest before each move; the other joints stay at ``hold``.

    Parameters
    ----------
    hold : array_like, shape (n,)
        Positions of all joints [rad]; the moving joint starts at ``lower`` whatever it says.
    joint : int
        The moving joint's column.
    velocities : sequence of float
        Cruise speeds [rad/s], > 0; each must be reachable (``v^2 / a < upper - lower``).
    lower, upper : float
        The sweep's ends [rad].
    drift : array_like (n,), optional
        The other joints move slowly instead of being held: ``hold + drift sin(2 pi t /
        drift_period)`` [rad] (the moving joint's entry is ignored), so the sweeps see the
        coupled gravity of many configurations.

    Raises
    ------
    ConfigError
        Bad joint index, speeds, range, acceleration or dwell.
    """
    hold = np.asarray(hold, dtype=float).reshape(-1).copy()
    speeds = np.asarray(velocities, dtype=float).reshape(-1)
    if not 0 <= joint < hold.size:
        raise ConfigError(f"joint {joint} is not a column of {hold.size} joints")
    span = float(upper) - float(lower)
    if not (np.isfinite(span) and span > 0 and acceleration > 0 and dwell >= 0):
        raise ConfigError("sweeps need lower < upper, acceleration > 0 and dwell >= 0")
    if speeds.size == 0 or not (np.isfinite(speeds).all() and (speeds > 0).all()):
        got = ", ".join(f"{x:g}" for x in speeds)
        raise ConfigError(f"sweep velocities must be > 0 rad/s; got {got or 'none'}")
    if (speeds**2 / acceleration >= span).any():
        raise ConfigError(
            f"a speed of {speeds.max():g} rad/s is not reached over {span:g} rad with "
            f"{acceleration:g} rad/s^2 ramps"
        )
    hold[joint] = lower
    if drift is not None:
        drift = np.asarray(drift, dtype=float).reshape(-1).copy()
        if drift.shape != hold.shape or not np.isfinite(drift).all() or drift_period <= 0:
            raise ConfigError(f"drift needs {hold.size} finite amplitudes and a period > 0")
        drift[joint] = 0.0
    starts, q_starts, cruise, ends, plateaus = [], [], [], [], []
    t = 0.0
    for v in speeds:
        for sign, q_from in ((1.0, lower), (-1.0, upper)):
            t += dwell
            ramp = v / acceleration
            move = span / v + ramp  # trapezoid: span = v (T - ramp)
            starts.append(t)
            q_starts.append(q_from)
            cruise.append(sign * v)
            ends.append(t + move)
            plateaus.append((t + ramp, t + move - ramp, float(sign * v)))
            t += move
    starts_ = np.array(starts)
    return SweepReference(
        joint=int(joint),
        hold=hold,
        starts=starts_,
        q_starts=np.array(q_starts),
        cruise=np.array(cruise),
        accel=np.full(starts_.size, float(acceleration)),
        ramps=np.abs(np.array(cruise)) / acceleration,
        ends=np.array(ends),
        plateaus=plateaus,
        duration=float(t + dwell),
        drift=drift,
        drift_period=float(drift_period),
    )


def random_fourier(
    model: Any,
    *,
    harmonics: int = 5,
    base_frequency: float = 0.1,
    fraction: float = 0.5,
    seed: int | np.random.Generator | None = 0,
) -> FourierTrajectory:
    """A random Fourier reference inside a fraction of the arm's position and speed limits.

    Not a designed excitation (that optimises the coefficients): coefficients uniform in
    ``[-1, 1]``, each joint's then scaled so that over a period ``|q - q0|`` stays within
    ``fraction`` of half its range (``q0`` the middle; 1 rad where the URDF gives no range)
    and ``|dq|`` within ``fraction`` of its velocity limit (2 rad/s where none).

    Parameters
    ----------
    model : RigidBodyModel
        Its ``joints``, ``lower``, ``upper`` and ``velocity_limit``.
    harmonics : int
        ``H``.
    base_frequency : float
        [Hz]; the period is its inverse.
    fraction : float
        In (0, 1].
    seed : int, Generator or None
    """
    if not (isinstance(harmonics, int) and harmonics >= 1 and 0 < fraction <= 1):
        raise ConfigError("random_fourier needs harmonics >= 1 and 0 < fraction <= 1")
    if not (np.isfinite(base_frequency) and base_frequency > 0):
        raise ConfigError(f"the base frequency must be > 0 Hz; got {base_frequency!r}")
    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(model.lower, dtype=float), np.asarray(model.upper, dtype=float)
    bounded = np.isfinite(lo) & np.isfinite(hi)
    lo, hi = np.where(bounded, lo, -1.0), np.where(bounded, hi, 1.0)
    q0, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    vmax = np.asarray(model.velocity_limit, dtype=float)
    vmax = np.where(np.isfinite(vmax) & (vmax > 0), vmax, 2.0)
    n = len(model.joints)
    a, b = rng.uniform(-1.0, 1.0, (2, n, harmonics))
    w_f = 2.0 * np.pi * base_frequency
    unit = FourierTrajectory(model.joints, w_f, q0, a, b)
    q, dq, _ = unit.evaluate(np.linspace(0.0, unit.duration, 200 * harmonics + 1))
    scale = np.minimum(fraction * half / np.abs(q - q0).max(0), fraction * vmax / np.abs(dq).max(0))
    return FourierTrajectory(model.joints, w_f, q0, a * scale[:, None], b * scale[:, None])
