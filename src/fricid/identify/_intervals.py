"""What an analytic fit stores for its prediction intervals: the covariance of its free
parameters, the residual variance, and the multiplier calibrated on its leave-one-out
residuals (:mod:`fricid.fitted._interval`, the delta method).

``C = s^2 (J^T J)^+`` with ``J`` the Jacobian of the predictions in the free parameters at
the optimum and ``s^2 = SSE / (n - p)`` of the unweighted residuals (Seber & Wild 1989,
eq. 5.7). The pseudo-inverse (SVD, cut at ``eps max(n, p)`` of the largest singular value of
the column-scaled ``J``, as scipy's ``curve_fit``) leaves out the directions the data do not
determine: a prediction inside the data hardly moves along them, so the interval there stays
finite where a parameter's own standard error is not.

The multiplier (``scale``): ``F(x) -+ k sqrt(g^T C g + s^2)`` with ``k = t(n - p)`` is exact
when the family holds and the noise is Gaussian. Where it does not, ``s^2`` holds what is not
Gaussian noise: a few gross outliers inflate ``s`` for every prediction (two samples 10-20
noise std off gave intervals covering 99.8-100 % of clean samples), and a bounded spread,
such as an offset that varies from run to run, has no tails for ``t s`` to reach into. ``k``
is therefore the normalised (studentised) jackknife quantile of the samples' own prediction
errors (Lei et al. 2018, section 5.2; Barber et al. 2021): the leave-one-out residual
``r_i / (1 - h_ii)`` over its standard deviation ``s / sqrt(1 - h_ii)`` under the same
formula, ``z_i = |r_i| / (s sqrt(1 - h_ii))``, ``h_ii`` the leverages of ``J``. ``k`` is the
order statistic of rank ``(n + 1) level``, interpolated between its neighbours (Hyndman &
Fan 1996, type 6): the ``j``-th smallest of ``n`` exchangeable scores covers ``j / (n + 1)``
of a new one in expectation, so this rank covers ``level`` on average (the conformal
``ceil`` of the rank guarantees at least ``level`` and sits on the largest one or two of 20-40
scores). Gross outliers (``|r_i| / sqrt(1 - h_ii)`` beyond :data:`GROSS` robust standard
deviations, ``1.4826 median``) are left out of the scores, looked for among
:data:`GROSS_MIN` scores or more: the interval is for measurements, not for faults. With too
few scores for the rank (under 19 at 95 %) ``k`` is the Student-t quantile with ``n - p``
degrees of freedom: the largest of a dozen scores, most of them pulled towards zero by a fit
of 3-5 parameters, is no quantile.

The noise term is never below the measured scatter of a sample (``noise_floor``: given
with the samples, or from repeated runs; not the estimate from second differences): the
residuals of 10-30 samples fitted by 2-5 parameters may come out well below the noise by
chance, or because ``auto`` picked the family whose residuals did (``s`` at half the noise
gave 80 % on a tuning case of six speed levels). The noise of a new sample is the scatter;
``s`` above it holds misfit as well, and stays. ``C`` is scaled with it. Where the scatter
sets the noise term and the multiplier is the Student-t fall-back, the multiplier is the
normal quantile: the noise is then known from the raw measurements behind every sample,
not estimated from ``n - p`` residuals.

Where the family misses the law by several times the noise, no multiplier makes an interval
centred on it cover 95 %: at each speed the new sample is the fixed bias plus noise, covered
with probability near 0 or near 1, and the share of speeds covered follows the shape of the
misfit. Such a fit is one the trust verdict refuses; a model that follows the law (the hybrid
model's residual network) is the cure, not a wider or narrower interval.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..fitted._interval import gradient
from ..models import get_model

__all__ = ["GROSS", "GROSS_MIN", "INTERVAL_LEVELS", "delta_record", "jackknife_scale"]

#: Levels at which the calibrated multiplier is stored.
INTERVAL_LEVELS = (0.9, 0.95)

#: A residual beyond this many robust standard deviations is a gross error, not a score.
GROSS = 6.0

#: Gross errors are looked for among this many scores or more (fewer: the median of a
#: handful of residuals, most of them pulled to zero by the fit, is no scale).
GROSS_MIN = 20


def _t_ppf(q: float, dof: int) -> float:
    from scipy import stats

    return float(stats.t.ppf(q, dof))


def jackknife_scale(
    r: np.ndarray, h: np.ndarray, s: float, dof: int, levels=INTERVAL_LEVELS
) -> dict[str, Any] | None:
    """The calibrated multipliers of the delta-method interval (module notes) from the
    residuals ``r``, the leverages ``h`` and the residual standard deviation ``s``; None
    when there is nothing to calibrate on (``s == 0`` or fewer than 3 usable scores)."""
    ok = h < 1 - 1e-9
    if s <= 0 or ok.sum() < 3:
        return None
    e = np.abs(r[ok]) / np.sqrt(1 - h[ok])
    robust = 1.4826 * float(np.median(e))
    gross = np.zeros(e.size, bool)
    if robust > 0 and e.size >= GROSS_MIN:
        gross = e > GROSS * robust
    z = np.sort(e[~gross] / s)
    m = z.size
    if m < 3:
        return None
    scale, student = [], []
    for level in levels:
        ranked = (m + 1) * float(level) <= m
        student.append(not ranked)
        if ranked:
            scale.append(float(np.quantile(z, float(level), method="weibull")))
        else:
            scale.append(_t_ppf(0.5 + level / 2, max(dof, 1)))
    return {
        "levels": list(levels),
        "scale": scale,
        "student_t": student,
        "scores": int(m),
        "gross": int(gross.sum()),
        "method": "normalised jackknife (leave-one-out residuals by leverage)",
    }


def delta_record(
    model_name: str,
    theta: np.ndarray,
    free: Sequence[str],
    X: np.ndarray,
    y: np.ndarray,
    noise_floor: float | None = None,
) -> dict[str, Any] | None:
    """The model file's ``prediction_interval`` of an analytic fit (module notes), or None
    when there are no spare observations (``n <= p``) or the Jacobian is not finite.

    ``noise_floor`` [N m]: the measured scatter of a sample (given, or from repeated runs),
    stored as ``noise_floor`` (module notes)."""
    free = list(free)
    n, p = len(y), len(free)
    if n <= p:
        return None
    r = y - get_model(model_name).predict(theta, X)
    J = gradient(model_name, theta, free, X).T  # (n, p)
    if not (np.isfinite(J).all() and np.isfinite(r).all()):
        return None
    s2 = float(r @ r) / (n - p)
    cov = np.zeros((p, p))
    h = np.zeros(n)
    if p:
        norms = np.linalg.norm(J, axis=0)
        norms[norms == 0] = 1.0
        U, s, VT = np.linalg.svd(J / norms, full_matrices=False)
        keep = s > np.finfo(float).eps * max(n, p) * s[0] if s[0] > 0 else s > np.inf
        cov = s2 * ((VT[keep].T / s[keep] ** 2) @ VT[keep]) / np.outer(norms, norms)
        h = np.sum(U[:, keep] ** 2, axis=1)
    out = {
        "method": "delta",
        "free": free,
        "covariance": (0.5 * (cov + cov.T)).tolist(),
        "noise_std": float(np.sqrt(s2)),
        "dof": n - p,
    }
    scale = jackknife_scale(r, h, float(np.sqrt(s2)), n - p)
    if scale is not None:
        out["scale"] = scale
    if noise_floor is not None and np.isfinite(noise_floor) and noise_floor > 0:
        out["noise_floor"] = float(noise_floor)
    return out
