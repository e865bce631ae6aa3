"""The compiled time loops of :mod:`fricid.models.lugre` (numba, cached on disk).

A module of its own so that importing :mod:`fricid.models.lugre` does not import numba, and so
that the kernels are module-level functions numba can cache across processes.

Every kernel takes LuGre's parameters per direction, 10 columns (:data:`WIDE`): sigma_0,
sigma_1, then sigma_2, tau_c, tau_s for v >= 0, w_s, delta (shared), then sigma_2, tau_c,
tau_s for v < 0. Each use of the Stribeck curve g(v) and of sigma_2 takes the set of the
velocity's sign; the symmetric model repeats its levels (:func:`fricid.models.lugre.wide`),
which gives the same arithmetic, bit for bit, as a kernel with one set.
"""

from __future__ import annotations

import math

from .._jit import njit

__all__ = ["WIDE", "run", "run_joint", "run_mean"]

#: Columns of the kernels' parameters.
WIDE = 10


@njit(cache=True)
def run(theta, v, dt, z0, F, Z):  # pragma: no cover - compiled
    """Exact zero-order-hold update of the bristle state for every row of ``theta``."""
    k = theta.shape[0]
    n = v.shape[0]
    for j in range(k):
        s0, s1 = theta[j, 0], theta[j, 1]
        s2p, tcp, tsp = theta[j, 2], theta[j, 3], theta[j, 4]
        s2n, tcn, tsn = theta[j, 7], theta[j, 8], theta[j, 9]
        w_s, delta = theta[j, 5], theta[j, 6]
        ws = max(abs(w_s), 1e-12)
        z = z0[j]
        for i in range(n):
            vi = v[i]
            av = abs(vi)
            s2, tau_c, tau_s = (s2p, tcp, tsp) if vi >= 0.0 else (s2n, tcn, tsn)
            if av > 0.0 and s0 > 0.0:
                g = max(tau_c + (tau_s - tau_c) * math.exp(-((av / ws) ** delta)), 1e-12)
                rate = s0 * av / g
                z_ss = g / s0 if vi > 0.0 else -g / s0
                z = z_ss + (z - z_ss) * math.exp(-rate * dt[i])
                dz = vi - rate * z
            else:
                dz = vi
                z = z + vi * dt[i]
            Z[j, i] = z
            F[j, i] = s0 * z + s1 * dz + s2 * vi
    return 0


@njit(cache=True, nogil=True)
def run_mean(theta, v, h, up, z0, F):  # pragma: no cover - compiled
    """Friction averaged over each sample period, for every row of ``theta``.

    ``v`` holds ``up`` sub-step velocities per sample period (``(n - 1) up + 1`` entries, the
    first the velocity before the first sample), each held over a sub-step of ``h`` seconds;
    the bristle state follows the exact update of :func:`run`, and its mean over a sub-step
    is exact too (``z_ss + (z0 - z_ss) (1 - exp(-a h)) / (a h)``). ``F[j, i]`` (``i >= 1``)
    is the mean friction over the period ending at sample ``i``: ``sigma_0 mean(z) +
    sigma_1 (z_i - z_{i-1}) / (up h) + mean(sigma_2 v)`` (sigma_2 of each sub-step's
    direction); ``F[j, 0]`` the friction at the
    first sample in the steady state of ``v[0]``.
    """
    k = theta.shape[0]
    n = F.shape[1]
    period = up * h
    for j in range(k):
        s0, s1 = theta[j, 0], theta[j, 1]
        s2p, tcp, tsp = theta[j, 2], theta[j, 3], theta[j, 4]
        s2n, tcn, tsn = theta[j, 7], theta[j, 8], theta[j, 9]
        w_s, delta = theta[j, 5], theta[j, 6]
        ws = max(abs(w_s), 1e-12)
        z = z0[j]
        F[j, 0] = s0 * z + (s2p if v[0] >= 0.0 else s2n) * v[0]
        for i in range(1, n):
            z_start = z
            acc_z = 0.0
            acc_v = 0.0
            acc_back = 0.0  # the backward velocities' sum: sigma_2's second set
            for m in range(up):
                vi = v[(i - 1) * up + 1 + m]
                av = abs(vi)
                tau_c, tau_s = (tcp, tsp) if vi >= 0.0 else (tcn, tsn)
                if av > 0.0 and s0 > 0.0:
                    g = max(tau_c + (tau_s - tau_c) * math.exp(-((av / ws) ** delta)), 1e-12)
                    x = s0 * av / g * h
                    z_ss = g / s0 if vi > 0.0 else -g / s0
                    if x > 1e-9:
                        e = math.exp(-x)
                        acc_z += z_ss + (z - z_ss) * (1.0 - e) / x
                    else:
                        e = 1.0 - x
                        acc_z += z + 0.5 * (vi - x / h * z) * h
                    z = z_ss + (z - z_ss) * e
                else:
                    acc_z += z + 0.5 * vi * h
                    z = z + vi * h
                acc_v += vi
                if vi < 0.0:
                    acc_back += vi
            F[j, i] = (
                s0 * acc_z / up
                + s1 * (z - z_start) / period
                + s2p * acc_v / up
                + (s2n - s2p) * acc_back / up
            )
    return 0


@njit(cache=True)
def _linear_step(s0, s1, s2, a, inv_j, beta, z, v, h):  # pragma: no cover - compiled
    """Exact step of ``z' = v - a z``, ``v' = beta - (s0 z + s1 (v - a z) + s2 v) / J`` over
    ``h`` (``a`` and ``beta`` frozen): returns ``z, v`` at its end and the distance moved."""
    p = -a
    r = (s1 * a - s0) * inv_j
    s = -(s1 + s2) * inv_j
    det = p * s - r  # (a s2 + s0) / J > 0
    tr = p + s
    disc = 0.25 * (p - s) * (p - s) + r
    half = math.exp(0.5 * tr * h)
    if disc > 0.0:
        root = math.sqrt(disc)
        lam1 = 0.5 * tr - root  # the faster (more negative) eigenvalue
        lam2 = det / lam1  # the slower one, without cancellation
        e1 = math.exp(lam2 * h)
        e2 = math.exp(lam1 * h)
        c = 0.5 * (e1 + e2)
        if root * h > 1e-6:
            sh = (e1 - e2) / (lam2 - lam1)
        else:
            sh = half * h * (1.0 + (root * h) ** 2 / 6.0)
    else:
        w = math.sqrt(-disc)
        c = half * math.cos(w * h)
        sh = half * math.sin(w * h) / w if w * h > 1e-6 else half * h * (1.0 - (w * h) ** 2 / 6.0)
    z_eq = beta / det
    v_eq = a * z_eq
    dz = z - z_eq
    dv = v - v_eq
    # M = c I + sh (A - tr/2 I)
    m11 = c + sh * (p - 0.5 * tr)
    m22 = c + sh * (s - 0.5 * tr)
    m12 = sh
    m21 = sh * r
    nz = m11 * dz + m12 * dv
    nv = m21 * dz + m22 * dv
    # distance: v_eq h + [A^-1 (M - I) dx]_v, A^-1 = [[s, -1], [-r, p]] / det
    moved = v_eq * h + (-r * (nz - dz) + p * (nv - dv)) / det
    return z_eq + nz, v_eq + nv, moved


@njit(cache=True, nogil=True)
def run_joint(
    theta, phys, tau, qref, vref, gains, dt, n_sub, reset, q_meas, v_meas, a_meas, x0, Q, V, Z, F, U
):  # pragma: no cover - compiled
    """A joint with LuGre friction, ``J qdd = u + p_x cos q - p_y sin q - F``, for every row
    (the levels and sigma_2 of each direction taken by the sign of the velocity they act at).

    ``u = tau + kp (qref - q) + kd (vref - v)`` is computed at each sample from the state
    there and held until the next (zero-order hold); each sample period is cut into ``n_sub``
    sub-steps, over each of which the bristle rate ``a = sigma_0 |v| / g(v)`` and the gravity
    torque are frozen at the predicted mid-point and the linear (z, v) system is solved
    exactly. Where ``reset`` is 1,
    position and velocity restart from the measured ones and the bristle state from the force
    balance ``sigma_0 z + sigma_1 (v - sigma_0 |v| z / g) = tau + tau_g(q) - J a - sigma_2 v``
    (measured acceleration ``a``; the steady deflection where ``sigma_1 |v| / g > 0.9`` makes
    that ill-posed), bounded by the steady deflection ``g(v) / sigma_0``: the equilibrium at
    rest, the steady state when sliding steadily. Where ``reset`` is 2, the sample is
    simulated as usual, then position and velocity restart from the measured ones while the
    bristle state carries on (the next segment of a multiple-shooting window).
    """
    k = theta.shape[0]
    n = tau.shape[0]
    kp, kd = gains[0], gains[1]
    for j in range(k):
        s0, s1 = theta[j, 0], theta[j, 1]
        s2p, tcp, tsp = theta[j, 2], theta[j, 3], theta[j, 4]
        s2n, tcn, tsn = theta[j, 7], theta[j, 8], theta[j, 9]
        w_s, delta = theta[j, 5], theta[j, 6]
        inertia, p_x, p_y = phys[j, 0], phys[j, 1], phys[j, 2]
        if not (s0 > 0.0 and inertia > 0.0 and min(tcp, tcn) > 0.0 and w_s > 0.0):
            for i in range(n):
                Q[j, i] = math.nan
                V[j, i] = math.nan
                Z[j, i] = math.nan
                F[j, i] = math.nan
                U[j, i] = math.nan
            continue
        inv_j = 1.0 / inertia
        q, v, z = x0[j, 0], x0[j, 1], x0[j, 2]
        u = 0.0
        for i in range(n):
            if reset[i] == 1:
                q = q_meas[i]
                v = v_meas[i]
                av = abs(v)
                s2, tau_c, tau_s = (s2p, tcp, tsp) if v >= 0.0 else (s2n, tcn, tsn)
                g = max(tau_c + (tau_s - tau_c) * math.exp(-((av / w_s) ** delta)), 1e-12)
                grav = p_x * math.cos(q) - p_y * math.sin(q)
                # F = s0 z + s1 (v - s0 |v| / g z) + s2 v solved for z (the damping term
                # included); where that is ill-posed (s1 |v| / g near or above 1) the
                # steady deflection
                lever = 1.0 - s1 * av / g
                if lever > 0.1:
                    z = (tau[i] + grav - inertia * a_meas[i] - (s1 + s2) * v) / (s0 * lever)
                else:
                    z = math.copysign(g / s0, v)
                # at rest, the break-away deflection of each direction bounds its side
                g_back = g if v != 0.0 else max(tcn + (tsn - tcn) * 1.0, 1e-12)
                z = min(max(z, -g_back / s0), g / s0)
            elif i > 0:
                h = dt[i] / n_sub
                for _ in range(n_sub):
                    # predictor with the rate at the start, corrector with the rate and the
                    # gravity torque at the predicted mid-point (exponential mid-point rule)
                    av = abs(v)
                    beta = (u + p_x * math.cos(q) - p_y * math.sin(q)) * inv_j
                    # at rest, the direction the applied torque starts it in
                    ahead = v > 0.0 or (v == 0.0 and beta >= 0.0)
                    s2, tau_c, tau_s = (s2p, tcp, tsp) if ahead else (s2n, tcn, tsn)
                    g = max(tau_c + (tau_s - tau_c) * math.exp(-((av / w_s) ** delta)), 1e-12)
                    a = s0 * av / g
                    _, vp, moved = _linear_step(s0, s1, s2, a, inv_j, beta, z, v, h)
                    vm = 0.5 * (v + vp)
                    av = abs(vm)
                    s2, tau_c, tau_s = (s2p, tcp, tsp) if vm >= 0.0 else (s2n, tcn, tsn)
                    g = max(tau_c + (tau_s - tau_c) * math.exp(-((av / w_s) ** delta)), 1e-12)
                    a = s0 * av / g
                    qm = q + 0.5 * moved
                    beta = (u + p_x * math.cos(qm) - p_y * math.sin(qm)) * inv_j
                    z, v, moved = _linear_step(s0, s1, s2, a, inv_j, beta, z, v, h)
                    q += moved
                if reset[i] == 2:  # the motion restarts from the measured, z carries on
                    q = q_meas[i]
                    v = v_meas[i]
            av = abs(v)
            s2, tau_c, tau_s = (s2p, tcp, tsp) if v >= 0.0 else (s2n, tcn, tsn)
            g = max(tau_c + (tau_s - tau_c) * math.exp(-((av / w_s) ** delta)), 1e-12)
            Q[j, i] = q
            V[j, i] = v
            Z[j, i] = z
            F[j, i] = s0 * z + s1 * (v - s0 * av / g * z) + s2 * v
            u = tau[i] + kp * (qref[i] - q) + kd * (vref[i] - v)
            U[j, i] = u
    return 0
