"""Compiled time loops of the LuGre joint (numba, cached on disk): see
:mod:`fricid.control.plant` for the step and :mod:`fricid.control.dynamic` for the study.

A module of its own so that importing :mod:`fricid.control` does not import numba. The
observer's update is the model's own compiled kernel (:func:`fricid.models._lugre_kernel.run`,
what :func:`fricid.models.lugre.simulate` runs), called one sample at a time.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit
from ..models._lugre_kernel import run as lugre_run

__all__ = ["drive_lugre", "lugre_plant_step", "track_lugre"]


@njit(cache=True)
def lugre_plant_step(th, z, v, u, inertia, dt):  # pragma: no cover - compiled
    """One linearly implicit step (:mod:`fricid.control.plant`): ``(z', v', friction)``."""
    s0, s1, s2 = th[0], th[1], th[2]
    tau_c, tau_s, w_s, delta = th[3], th[4], th[5], th[6]
    g = tau_c + (tau_s - tau_c) * math.exp(-((abs(v) / max(w_s, 1e-12)) ** delta))
    a = s0 * abs(v) / max(g, 1e-12)
    c = 1.0 / (1.0 + a * dt)
    k = (s0 - s1 * a) * c  # friction = k z + (k dt + s1 + s2) v'
    v_new = (inertia * v / dt + u - k * z) / (inertia / dt + k * dt + s1 + s2)
    return c * (z + dt * v_new), v_new, k * z + (k * dt + s1 + s2) * v_new


@njit(cache=True)
def drive_lugre(th, torque, dt, inertia, Q, V, F):  # pragma: no cover - compiled
    """Open loop from rest: state before each torque sample into ``Q``, ``V``; friction ``F``."""
    q = 0.0
    v = 0.0
    z = 0.0
    for i in range(torque.shape[0]):
        Q[i] = q
        V[i] = v
        z, v, F[i] = lugre_plant_step(th, z, v, torque[i], inertia, dt)
        q += v * dt
    return 0


@njit(cache=True)
def track_lugre(
    truth, model, q_r, v_r, a_r, static_ff, kp, kd, inertia, dt, z0, z0_hat, noise, Q, V, U, FR, FF
):  # pragma: no cover - compiled
    """The three runs of :func:`fricid.control.dynamic.lugre_compensation_study` (row 0 PD
    only, 1 static feed-forward, 2 LuGre observer on row 2's measured velocity).

    ``model`` is (1, 10), the kernel's per-direction columns
    (:func:`fricid.models.lugre.wide`); ``noise`` (n,) is added to the measured velocity
    (the D term and the observer's input); ``Q``, ``V``, ``U``, ``FR``, ``FF`` (3, n)
    receive position, true velocity, command, true friction and feed-forward at each step's
    start.
    """
    k, n = Q.shape
    q = np.zeros(k)
    v = np.full(k, v_r[0])
    z = np.full(k, z0)
    v_obs = np.empty(1)
    dt_obs = np.full(1, dt)
    z_hat = np.full(1, z0_hat)
    f_obs = np.empty((1, 1))
    z_obs = np.empty((1, 1))
    ff = np.zeros(k)
    for i in range(n):
        v_obs[0] = v[2] + noise[i]
        lugre_run(model, v_obs, dt_obs, z_hat, f_obs, z_obs)  # the model's own update
        z_hat[0] = z_obs[0, 0]
        ff[1] = static_ff[i]
        ff[2] = f_obs[0, 0]
        for j in range(k):
            v_meas = v[j] + noise[i]
            u = inertia * a_r[i] + kp * (q_r[i] - q[j]) + kd * (v_r[i] - v_meas) + ff[j]
            Q[j, i] = q[j]
            V[j, i] = v[j]
            U[j, i] = u
            FF[j, i] = ff[j]
            z[j], v[j], FR[j, i] = lugre_plant_step(truth, z[j], v[j], u, inertia, dt)
            q[j] += v[j] * dt
    return 0
