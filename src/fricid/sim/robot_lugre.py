"""LuGre friction on some joints of a simulated arm: the bristle states and their steps.

The model of :mod:`fricid.models.lugre` ([CW95] eq. 2-4, the Stribeck curve of the BAS-RBFNN
paper eq. 2), per LuGre joint::

    dz/dt = v - sigma_0 |v| / g(v) z,   F = sigma_0 z + sigma_1 dz/dt + sigma_2 v

Over a friction step of length ``tau`` of the arm's integrator (:mod:`fricid.sim.robot`) the
velocity is frozen and ``z`` is solved exactly, as :func:`fricid.models.lugre.simulate` does:
``z(tau) = z_ss + (z - z_ss) exp(-a tau)`` with ``a = sigma_0 |v| / g(v)`` and
``z_ss = sign(v) g(v) / sigma_0``, stable however stiff the bristles are. The step's mean
friction ``sigma_0 mean(z) + sigma_1 (z(tau) - z) / tau + sigma_2 v`` and its derivative in
``v`` (by a forward difference) enter the integrator's linearly implicit friction step, which
then holds the bristle spring (``sigma_0 tau`` per rad/s) and damping implicitly too; the
state advances with the step's new velocity.

The joint rings on its bristles, the least inertia ``m`` it meets (``1 / (M^-1)_jj``, the
other joints free) on the spring ``sigma_0``, at ``omega = sqrt(sigma_0 / m)`` (1,270 rad/s
on the Panda's joint 7 with ``sigma_0 = 1e4`` N m/rad), and the arm's split step resolves
that ringing only when ``omega h`` is small: :func:`bristle_step` gives the largest step,
:data:`BRISTLE_RESOLUTION` over ``omega``, and :func:`fricid.sim.robot.run_robot` takes no
larger. Measured (``benchmarks/bench_robot_sim.py``, table 3: the double pendulum's second
joint with ``lugre_like`` of the example law, sigma_0 = 1325 N m/rad, omega = 1314 rad/s,
PD-tracked, 5 s at 1 kHz), the mean friction of the samples at 0.02-0.04 rad/s against 0.105
N m at 6.25 us steps: 0.020 N m at the arm's default 0.5 ms (``omega h`` 0.66), 0.065 at
0.125 ms (0.16), 0.085 at 50 us (0.066), 0.108 at 25 us (0.033); at 0.005-0.02 rad/s 0.002,
0.036, 0.070 and 0.080 against 0.072. The Panda's 60 s with a LuGre wrist then takes 40 us
steps and 133 s of CPU (21 s at the 0.5 ms it took before). Stepping the friction alone
finer (the rigid body at 0.5 ms, twenty friction steps within each) did not cure it, so the
whole step is refined.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..models import lugre

__all__ = ["BRISTLE_RESOLUTION", "LuGreBristles", "bristle_step", "lugre_like"]

#: Velocity step [rad/s] of the central difference of the mean friction.
_DV = 1e-7

#: The largest ``omega h`` of the bristles' ringing the arm's step may take (module notes:
#: 0.033 held the friction at 0.02-0.15 rad/s within 3 % of a four times finer step, 0.066
#: was 19 % low at 0.02-0.04 rad/s).
BRISTLE_RESOLUTION = 0.025


def _theta(joint: str, value: Any) -> np.ndarray:
    if isinstance(value, Mapping):
        missing = [k for k in lugre.PARAM_NAMES if k not in value]
        if missing:
            raise ConfigError(f"LuGre friction of '{joint}' needs {', '.join(missing)}")
        value = [value[k] for k in lugre.PARAM_NAMES]
    theta = np.asarray(value, dtype=float).reshape(-1)
    if theta.shape != (7,) or not np.isfinite(theta).all() or lugre.passivity_margin(theta) < 0:
        raise ConfigError(
            f"LuGre friction of '{joint}': 7 finite parameters ({', '.join(lugre.PARAM_NAMES)}), "
            "sigma_0, tau_c, w_s > 0, and passive (sigma_1 <= 4 sigma_2 tau_c / (tau_s - tau_c))"
        )
    return theta


class LuGreBristles:
    """The LuGre joints of an arm and their bristle states (module notes).

    Parameters
    ----------
    joints : sequence of str
        All the arm's joints, in the model's order.
    laws : mapping
        Joint name -> LuGre parameters (a mapping of :data:`fricid.models.lugre.PARAM_NAMES`
        or 7 numbers in that order).
    """

    def __init__(self, joints: tuple[str, ...], laws: Mapping[str, Any]) -> None:
        unknown = [j for j in laws if j not in joints]
        if unknown:
            raise ConfigError(f"LuGre friction for joints not in the model: {unknown}")
        self.joints = tuple(j for j in joints if j in laws)
        self.index = np.array([joints.index(j) for j in self.joints], dtype=int)
        theta = np.array([_theta(j, laws[j]) for j in self.joints]).reshape(-1, 7)
        self.theta = theta
        self.s0, self.s1, self.s2, self.tau_c, self.tau_s, self.w_s, self.delta = (
            [float(x) for x in col] for col in theta.T
        )
        self.z = np.zeros(len(self.joints))

    def _curve(self, i: int, v: float) -> float:
        tau_c, tau_s = self.tau_c[i], self.tau_s[i]
        return tau_c + (tau_s - tau_c) * math.exp(-((abs(v) / self.w_s[i]) ** self.delta[i]))

    def _advance(self, i: int, v: float, tau: float) -> tuple[float, float]:
        """Joint ``i``'s ``z(tau)`` and the mean of ``z`` over the step at the frozen ``v``
        (plain floats: a LuGre joint or two, where numpy's per-call cost would dominate)."""
        s0, z = self.s0[i], self.z[i]
        g = self._curve(i, v)
        x = s0 * abs(v) / g * tau
        z_ss = math.copysign(g / s0, v) if v != 0 else 0.0
        share = -math.expm1(-x) / x if x > 1e-12 else 1.0 - 0.5 * x
        # mean of z: z_ss + (z - z_ss) (1 - e^-x) / x, i.e. z + v tau / 2 for small x
        return z_ss + (z - z_ss) * math.exp(-x), z_ss + (z - z_ss) * share

    def _mean_force(self, i: int, v: float, tau: float) -> float:
        z_end, z_mean = self._advance(i, v, tau)
        return self.s0[i] * z_mean + self.s1[i] * (z_end - self.z[i]) / tau + self.s2[i] * v

    def step_force(self, v: np.ndarray, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """The mean friction over a step of ``tau`` [s] at the LuGre joints' velocities ``v``,
        and its derivative in ``v`` (a forward difference)."""
        force, slope = np.empty(len(v)), np.empty(len(v))
        for i, vi in enumerate(map(float, v)):
            force[i] = self._mean_force(i, vi, tau)
            slope[i] = (self._mean_force(i, vi + _DV, tau) - force[i]) / _DV
        return force, slope

    def commit(self, v: np.ndarray, tau: float) -> None:
        """Advance the bristles over the step with the step's new velocities ``v``."""
        self.z = np.array([self._advance(i, float(vi), tau)[0] for i, vi in enumerate(v)])

    def force(self, v: np.ndarray) -> np.ndarray:
        """The friction now: ``sigma_0 z + sigma_1 dz/dt + sigma_2 v``."""
        out = np.empty(len(v))
        for i, vi in enumerate(map(float, v)):
            dz = vi - self.s0[i] * abs(vi) / self._curve(i, vi) * self.z[i]
            out[i] = self.s0[i] * self.z[i] + self.s1[i] * dz + self.s2[i] * vi
        return out

    def parameters(self) -> dict[str, dict[str, float]]:
        """Joint -> its LuGre parameters (fricid's ``lugre`` names)."""
        return {
            j: dict(zip(lugre.PARAM_NAMES, map(float, t), strict=True))
            for j, t in zip(self.joints, self.theta, strict=True)
        }


def bristle_step(bristles: LuGreBristles, least_inertia: np.ndarray) -> float:
    """The largest internal step [s] that resolves the bristles' ringing (module notes):
    :data:`BRISTLE_RESOLUTION` over the fastest ``sqrt(sigma_0 / m)``, ``least_inertia`` the
    least inertia [kg m^2] each of the arm's joints meets (all joints, the model's order)."""
    m = np.asarray(least_inertia, dtype=float)[bristles.index]
    omega = np.sqrt(np.asarray(bristles.s0) / np.maximum(m, 1e-12))
    return float(BRISTLE_RESOLUTION / omega.max())


def lugre_like(pos: Mapping[str, float], *, presliding: float = 1e-4) -> dict[str, float]:
    """A passive LuGre law with the steady state of a Stribeck law's positive direction.

    ``pos``: ``tau_c, tau_s, w_s, tau_v, delta`` (one direction of
    :meth:`fricid.sim.robot_friction.ArmFriction.parameters`, suffixes removed).
    ``sigma_0 = tau_s / presliding`` (the break-away torque reached after ``presliding``
    rad of bristle deflection), ``sigma_2 = tau_v`` and ``sigma_1`` half the passivity bound
    ``4 sigma_2 tau_c / (tau_s - tau_c)`` (capped at ``2 sqrt(sigma_0) 0.01`` N m s/rad).
    """
    tau_c, tau_s, w_s, tau_v, delta = (
        float(pos[k]) for k in ("tau_c", "tau_s", "w_s", "tau_v", "delta")
    )
    if not (presliding > 0 and tau_s > 0 and tau_c > 0):
        raise ConfigError("lugre_like needs tau_c, tau_s > 0 and presliding > 0")
    sigma_0 = tau_s / presliding
    bound = 4.0 * tau_v * tau_c / (tau_s - tau_c) if tau_s > tau_c else np.inf
    sigma_1 = float(min(0.5 * bound, 0.02 * np.sqrt(sigma_0)))
    return {
        "sigma_0": sigma_0,
        "sigma_1": sigma_1,
        "sigma_2": tau_v,
        "tau_c": tau_c,
        "tau_s": tau_s,
        "w_s": w_s,
        "delta": delta,
    }
