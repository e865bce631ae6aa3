"""The error the samples share: an arm's base gravity parameters, removed from every sample.

An arm's sweeps (:func:`fricid.extract.extract_arm`) identify the base gravity parameters
``beta`` together with the set-point frictions, and remove ``w(q) . beta`` from every joint's
torque. Each set-point's friction then moves by ``-wbar_k . d_beta`` with beta's error: one
error shared by all the samples, nearly the same offset at every speed of a direction. A
law's Coulomb level absorbs it, so the residuals of the least-squares fit (eq. 11 of the
RWSAVSBAS paper) never show it, and the intervals of :func:`.uncertainty.assess`, which take
the samples as independent, leave it out. Measured on the 2-DOF sweeps of
``benchmarks/bench_arm_sweeps.py`` (100 seeds): the Coulomb levels' 95 % intervals covered
88-91 % on the double pendulum's first joint and the Panda's second; with the true masses (no
``beta`` identified) the same fits covered 95 %. With the shared error added, over 300 seeds,
the Coulomb levels cover 95.7-98.0 % and every parameter 90.3-98.0 %
(``benchmarks/results/arm_sweeps.txt``).

:func:`shared_covariance` reads the shared error from the samples' ``meta["gravity"]`` (each
level's ``regressor`` row ``wbar_k`` and the parameters' ``covariance``), matching each sample
to its level by direction, speed and temperature; :func:`propagate` carries it through the
fit (``C = J^+ D Sigma D J^+T``, ``D`` the square roots of the weights), and
:func:`.uncertainty.assess` adds ``C`` to the parameters' covariance and widens each side of
their intervals by it in quadrature, after taking out of the residual variance what the
residuals do show of the shared error (where the levels' regressors differ between speeds,
part of it is not an offset), so that it is not counted twice.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ...samples import FrictionSamples

__all__ = ["MATCH_RTOL", "propagate", "shared_covariance"]

#: A sample belongs to the level of its direction nearest in speed when their speeds differ by
#: at most this fraction (and their temperatures by the extraction's ``temperature_atol``).
MATCH_RTOL = 0.05


def _number(x: Any) -> float:
    return float("nan") if x is None else float(x)


def _parameter_covariance(gravity: Mapping[str, Any], m: int) -> np.ndarray | None:
    """Beta's covariance, its diagonal raised to the recorded standard errors (the larger of
    ordinary and cluster-robust) with the correlations kept; an undetermined parameter
    (kept at the URDF's value, no error known) contributes nothing."""
    raw = gravity.get("covariance")
    params = gravity.get("parameters") or []
    if raw is None or len(raw) != m or len(params) != m:
        return None
    cov = np.array([[_number(x) for x in row] for row in raw], dtype=float)
    if cov.shape != (m, m):
        return None
    se = np.array([_number(p.get("se")) for p in params])
    ok = np.isfinite(se) & np.isfinite(np.diag(cov)) & (np.diag(cov) > 0)
    out = np.zeros((m, m))
    if not ok.any():
        return out
    d = np.sqrt(np.diag(cov)[ok])
    corr = cov[np.ix_(ok, ok)] / np.outer(d, d)
    if not np.isfinite(corr).all():
        return None
    out[np.ix_(ok, ok)] = corr * np.outer(se[ok], se[ok])
    return out


def _sensitivity(samples: FrictionSamples, levels: list, atol: float) -> np.ndarray | None:
    """``(n, m)``: each sample's ``d friction / d beta``, ``-wbar`` of its level (a combined
    row: the count-weighted mean of both directions' levels); zero for a sample that matches
    no level."""
    try:
        speed = np.array([abs(float(lv["velocity"])) for lv in levels])
        temp = np.array([float(lv["temperature"]) for lv in levels])
        sign = np.array([int(lv["direction"]) for lv in levels])
        count = np.array([float(lv.get("count") or 1.0) for lv in levels])
        wbar = np.array([[float(x) for x in lv["regressor"]] for lv in levels])
    except (KeyError, TypeError, ValueError):
        return None
    if wbar.ndim != 2 or not np.isfinite(wbar).all():
        return None
    out = np.zeros((len(samples), wbar.shape[1]))
    for i, (v, t, d) in enumerate(
        zip(samples.velocity, samples.temperature, samples.direction, strict=True)
    ):
        rel = np.abs(speed - abs(v)) / max(abs(v), 1e-12)
        near = (rel <= MATCH_RTOL) & ~(np.abs(temp - t) > atol)
        picks = [
            int(np.flatnonzero(near & (sign == s))[np.argmin(rel[near & (sign == s)])])
            for s in ((1, -1) if d == 0 else (int(d),))
            if (near & (sign == s)).any()
        ]
        if picks:
            out[i] = -np.average(wbar[picks], axis=0, weights=count[picks])
    return out


def shared_covariance(samples: FrictionSamples) -> np.ndarray | None:
    """``(n, n)``: the covariance of the samples' friction through the shared gravity
    parameters (``G Sigma_beta G^T``), or None when the samples carry none (not from an arm
    whose gravity was identified, or the record is incomplete)."""
    gravity = (samples.meta or {}).get("gravity")
    if not isinstance(gravity, Mapping) or not gravity.get("identified"):
        return None
    levels = gravity.get("levels")
    if not isinstance(levels, list) or not levels:
        return None
    extract = (samples.meta or {}).get("extract") or {}
    atol = float(extract.get("temperature_atol") or 1.0)
    g = _sensitivity(samples, levels, atol)
    if g is None:
        return None
    cov = _parameter_covariance(gravity, g.shape[1])
    if cov is None or not g.any():
        return None
    return g @ cov @ g.T


def propagate(
    J: np.ndarray, sqrt_w: np.ndarray | None, shared: np.ndarray
) -> tuple[np.ndarray, float]:
    """What the shared error ``shared (n, n)`` of the targets does to a least-squares fit
    (``J`` the weighted residuals' Jacobian, ``D = diag(sqrt_w)``; a robust loss's
    down-weighting is not followed): the estimate's covariance ``J^+ M J^+T`` with
    ``M = D shared D``, and the part of the residuals' expected sum of squares it makes,
    ``tr((I - H) M)`` with ``H = J J^+`` (what the residuals do show of it)."""
    pinv = np.linalg.pinv(J)
    m = shared if sqrt_w is None else shared * np.outer(sqrt_w, sqrt_w)
    seen = float(np.trace(m) - np.trace(J @ (pinv @ m)))
    return pinv @ m @ pinv.T, max(seen, 0.0)
