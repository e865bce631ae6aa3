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
the Coulomb levels cover 95.7-98.0 % and every parameter 92.7-98.0 %
(``benchmarks/results/arm_sweeps.txt``).

:func:`shared_covariance` reads the shared error from the samples' ``meta["gravity"]`` (each
level's ``regressor`` row ``wbar_k`` and the parameters' ``covariance``), matching each sample
to its level by direction, speed and temperature; :func:`propagate` carries it through the
fit (``C = J^+ D Sigma D J^+T``, ``D`` the square roots of the weights), and
:func:`.uncertainty.assess` adds ``C`` to the parameters' covariance and widens each side of
their intervals by it in quadrature, after taking out of the residual variance what the
residuals do show of the shared error (where the levels' regressors differ between speeds,
part of it is not an offset), so that it is not counted twice. Where the residuals show
nothing beyond the shared error (a law that fits its samples exactly), the samples' own
variances as the arm's fit measured them (:func:`own_variance`) stand in; not elsewhere: as a
floor they overstated the scatter (97-100 % coverage on the same benchmark, 100 seeds).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ...samples import FrictionSamples

__all__ = ["MATCH_RTOL", "own_variance", "propagate", "shared_covariance"]

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


def _matches(samples: FrictionSamples, levels: list, atol: float) -> list[list[int]] | None:
    """Each sample's level(s): the one whose friction and count it holds (the arm
    extraction's rows, :func:`fricid.extract.arm.extract_arm`), else the nearest in speed of
    its direction (a combined row: one of each direction), within :data:`MATCH_RTOL` and
    ``atol`` degC; ``[]`` for none."""
    try:
        speed = np.array([abs(float(lv["velocity"])) for lv in levels])
        temp = np.array([float(lv["temperature"]) for lv in levels])
        sign = np.array([int(lv["direction"]) for lv in levels])
    except (KeyError, TypeError, ValueError):
        return None
    try:
        key = {
            (float(lv["friction"]), int(lv["count"])): i
            for i, lv in enumerate(levels)
            if lv.get("friction") is not None and lv.get("count") is not None
        }
    except (TypeError, ValueError):
        key = {}
    counts = [None] * len(samples) if samples.count is None else samples.count
    out = []
    for v, t, d, f, n in zip(
        samples.velocity,
        samples.temperature,
        samples.direction,
        samples.friction,
        counts,
        strict=True,
    ):
        if d != 0 and n is not None and (float(f), int(n)) in key:
            out.append([key[float(f), int(n)]])  # the row the arm extraction wrote for it
            continue
        rel = np.abs(speed - abs(v)) / max(abs(v), 1e-12)
        near = (rel <= MATCH_RTOL) & ~(np.abs(temp - t) > atol)
        out.append(
            [
                int(np.flatnonzero(near & (sign == s))[np.argmin(rel[near & (sign == s)])])
                for s in ((1, -1) if d == 0 else (int(d),))
                if (near & (sign == s)).any()
            ]
        )
    return out


def _record(samples: FrictionSamples):
    """The samples' gravity record, its levels and each sample's matches, or None."""
    gravity = (samples.meta or {}).get("gravity")
    if not isinstance(gravity, Mapping) or not gravity.get("identified"):
        return None
    levels = gravity.get("levels")
    if not isinstance(levels, list) or not levels:
        return None
    extract = (samples.meta or {}).get("extract") or {}
    picks = _matches(samples, levels, float(extract.get("temperature_atol") or 1.0))
    return None if picks is None else (gravity, levels, picks)


def _average(values: np.ndarray, levels: list, picks: list[list[int]]) -> np.ndarray:
    """Per sample, the count-weighted mean of ``values`` (one row per level) over its
    matches; zero for a sample with none."""
    count = np.array([float(lv.get("count") or 1.0) for lv in levels])
    out = np.zeros((len(picks), *values.shape[1:]))
    for i, p in enumerate(picks):
        if p:
            out[i] = np.average(values[p], axis=0, weights=count[p])
    return out


def shared_covariance(samples: FrictionSamples) -> np.ndarray | None:
    """``(n, n)``: the covariance of the samples' friction through the shared gravity
    parameters (``G Sigma_beta G^T``, each row of ``G`` the ``-wbar`` of the sample's level),
    or None when the samples carry none (not from an arm whose gravity was identified, or the
    record is incomplete)."""
    found = _record(samples)
    if found is None:
        return None
    gravity, levels, picks = found
    try:
        wbar = np.array([[float(x) for x in lv["regressor"]] for lv in levels])
    except (KeyError, TypeError, ValueError):
        return None
    if wbar.ndim != 2 or not np.isfinite(wbar).all():
        return None
    g = -_average(wbar, levels, picks)
    cov = _parameter_covariance(gravity, g.shape[1])
    if cov is None or not g.any():
        return None
    return g @ cov @ g.T


def own_variance(samples: FrictionSamples, shared: np.ndarray) -> np.ndarray | None:
    """``(n,)``: each sample's own variance as the arm's fit measured it (its level's
    ``friction_se`` squared less its shared part, never below zero; zero for a sample without
    a level), or None without a record: the floor of the variance a law fitted to few samples
    estimates from its residuals."""
    found = _record(samples)
    if found is None:
        return None
    _, levels, picks = found
    try:
        se = np.array([float(lv.get("friction_se") or 0.0) for lv in levels])
    except (TypeError, ValueError):
        return None
    var = _average(np.where(np.isfinite(se), se, 0.0) ** 2, levels, picks)
    return np.clip(var - np.diag(shared), 0.0, None)


def propagate(
    J: np.ndarray, sqrt_w: np.ndarray | None, shared: np.ndarray, own: np.ndarray | None = None
) -> tuple[np.ndarray, float, np.ndarray]:
    """What the shared error ``shared (n, n)`` of the targets does to a least-squares fit
    (``J`` the weighted residuals' Jacobian, ``D = diag(sqrt_w)``; a robust loss's
    down-weighting is not followed): the estimate's covariance ``J^+ M J^+T`` with
    ``M = D shared D``; the part of the residuals' expected sum of squares it makes,
    ``tr((I - H) M)`` with ``H = J J^+`` (what the residuals do show of it); and the
    variances ``diag(J^+ D diag(own) D J^+T)`` the samples' own known variances ``own (n,)``
    give (zeros without them)."""
    pinv = np.linalg.pinv(J)
    if sqrt_w is not None:
        pinv = pinv * sqrt_w[None, :]
    m = shared
    seen = float(np.trace(m @ _residual_maker(J, sqrt_w)))
    known = np.zeros(J.shape[1]) if own is None else np.einsum("pi,i,pi->p", pinv, own, pinv)
    return pinv @ m @ pinv.T, max(seen, 0.0), known


def _residual_maker(J: np.ndarray, sqrt_w: np.ndarray | None) -> np.ndarray:
    """``D (I - H) D`` with ``H = J J^+``: ``tr(shared D (I - H) D)`` is what a shared error
    adds to the weighted residuals' expected sum of squares."""
    h = np.eye(J.shape[0]) - J @ np.linalg.pinv(J)
    return h if sqrt_w is None else h * np.outer(sqrt_w, sqrt_w)
