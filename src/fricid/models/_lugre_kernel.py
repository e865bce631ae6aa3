"""The compiled time loop of :func:`fricid.models.lugre.simulate` (numba, cached on disk).

A module of its own so that importing :mod:`fricid.models.lugre` does not import numba, and so
that the kernel is a module-level function numba can cache across processes.
"""

from __future__ import annotations

import math

from numba import njit

__all__ = ["run"]


@njit(cache=True)
def run(theta, v, dt, z0, F, Z):  # pragma: no cover - compiled
    """Exact zero-order-hold update of the bristle state for every row of ``theta``."""
    k = theta.shape[0]
    n = v.shape[0]
    for j in range(k):
        s0, s1, s2 = theta[j, 0], theta[j, 1], theta[j, 2]
        tau_c, tau_s, w_s, delta = theta[j, 3], theta[j, 4], theta[j, 5], theta[j, 6]
        ws = max(abs(w_s), 1e-12)
        z = z0[j]
        for i in range(n):
            vi = v[i]
            av = abs(vi)
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
