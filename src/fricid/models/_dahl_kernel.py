"""The compiled time loop of :func:`fricid.models.dahl.simulate` (numba, cached on disk)."""

from __future__ import annotations

import math

from .._jit import njit

__all__ = ["run"]


@njit(cache=True)
def run(theta, v, dt, f0, F, S):  # pragma: no cover - compiled
    """Exact zero-order-hold update of the Dahl force for every row of ``theta``.

    ``u = 1 - sign(v) F_d / tau_c`` obeys ``du/ds = -(sigma_0 / tau_c) u^alpha`` along the
    distance ``s`` travelled, solved in closed form over each sample.
    """
    k = theta.shape[0]
    n = v.shape[0]
    for j in range(k):
        s0, tau_c, alpha, s2 = theta[j, 0], theta[j, 1], theta[j, 2], theta[j, 3]
        if not (s0 > 0.0 and tau_c > 0.0 and alpha > 0.0):
            for i in range(n):
                F[j, i] = math.nan
                S[j, i] = math.nan
            continue
        fd = min(max(f0[j], -tau_c), tau_c)
        for i in range(n):
            vi = v[i]
            if vi != 0.0 and dt[i] > 0.0:
                sgn = 1.0 if vi > 0.0 else -1.0
                u = min(max(1.0 - sgn * fd / tau_c, 0.0), 2.0)
                rate = s0 / tau_c * abs(vi) * dt[i]
                if alpha == 1.0:
                    u = u * math.exp(-rate)
                elif u > 0.0:
                    if alpha < 1.0:
                        w = u ** (1.0 - alpha) - (1.0 - alpha) * rate
                        u = w ** (1.0 / (1.0 - alpha)) if w > 0.0 else 0.0
                    else:
                        u = (u ** (1.0 - alpha) + (alpha - 1.0) * rate) ** (-1.0 / (alpha - 1.0))
                fd = sgn * tau_c * (1.0 - u)
            S[j, i] = fd
            F[j, i] = fd + s2 * vi
    return 0
