"""The whole-arm estimate's covariance from the correlation its own filters give the noise.

The torque's noise is white at the log's rate in the model of the fit (Gaussian, independent
between joints); the rows the fit uses are that noise through the low-pass, the anti-alias
filter and the decimation (:meth:`._signals.ArmSignals.parallel`), so their correlation is
known exactly: white noise through a linear filter of impulse response ``h`` has the
autocorrelation ``R(m) = sum_i h_i h_(i+m)`` at a lag of ``m`` samples. The covariance of the
weighted least-squares estimate is then the sandwich ``G (sum_j s_j^2 A_j' S_j A_j) G`` with
``G = (A' A)^-1``, ``A_j`` joint ``j``'s rows, ``S_j`` their correlation ``R(|t_a - t_b|) /
R(0)`` and ``s_j^2`` their variance from the residuals.

Why not the residuals' own autocorrelation alone (:func:`._solve.hac_covariance`): the
filtered noise stays correlated over several periods of the cut-off, and Bartlett weights
over a few lags, estimated from one log, leave much of that out. Measured on the open-loop
truth (``tests/identify/dynamic/_arm_truth.py``, Panda, tuning seed 50, 20 s, the Stribeck
shapes fixed at the truth, 8 draws of the noise): the estimates' spread over their standard
errors was 1.28 (base parameters) and 1.13 (friction) with the autocorrelation sandwich, the
95 % intervals covering 89 % and 93 %; with the filter's correlation 0.98 and 0.92, covering
94 % and 95 %. Residuals correlated beyond what the filter explains (a closed loop feeding
noise back, a model that misses) still widen the intervals: :func:`._solve.arm_covariance`
keeps the wider of the two.
"""

from __future__ import annotations

import numpy as np

from ...static.uncertainty import covariance_svd
from ._signals import ArmSignals, _filt

__all__ = ["filter_correlation", "filter_covariance", "impulse_response"]

#: The impulse response is taken over this many periods of the cut-off on each side.
SUPPORT_PERIODS = 20.0


def impulse_response(sig: ArmSignals) -> np.ndarray:
    """The torque's filters' response (2 half + 1,) at the log's rate to a unit sample at
    ``half`` (:data:`SUPPORT_PERIODS` periods of the cut-off each side): what a sample of the
    log adds to the filtered samples about it, before decimation."""
    half = int(np.ceil(SUPPORT_PERIODS * sig.rate / sig.cutoff))
    impulse = np.zeros((2 * half + 1, 1))
    impulse[half] = 1.0
    return _filt(sig.anti_alias, _filt(sig.low_pass, impulse))[:, 0]


def filter_correlation(sig: ArmSignals) -> np.ndarray:
    """``rho[k]``: the correlation of white noise through the torque's filters between two
    rows ``k`` decimated instants apart (module notes); zero beyond the returned length."""
    h = impulse_response(sig)
    R = np.correlate(h, h, mode="full")[h.size - 1 :]
    rho = R[:: sig.decimation] / R[0]
    below = np.flatnonzero(np.abs(rho) < 1e-6)
    return rho[: below[0]] if below.size else rho


def filter_covariance(
    J: np.ndarray,
    res: np.ndarray,
    row_joint: np.ndarray,
    row_time: np.ndarray,
    n: int,
    rho: np.ndarray,
    lost: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """(cov, stderr) of the weighted problem ``J`` with residuals ``res`` (module notes); NaN
    where the data do not determine a parameter. ``lost``: each joint's degrees of freedom
    taken by columns projected out of its rows (:mod:`._sticks`)."""
    m, p = J.shape
    bread, determined = covariance_svd(J, 1.0)
    bread = np.nan_to_num(bread)
    T = int(row_time.max()) + 1 if m else 1
    meat = np.zeros((p, p))
    for j in range(n):
        rows = row_joint == j
        m_j = int(rows.sum())
        if m_j == 0:
            continue
        cols = np.flatnonzero(np.any(J[rows] != 0, axis=0))
        X = np.zeros((T, cols.size))
        X[row_time[rows]] = J[np.ix_(rows, cols)]
        block = X.T @ X
        for k in range(1, min(rho.size, T)):
            gamma = X[k:].T @ X[:-k]
            block += rho[k] * (gamma + gamma.T)
        dof = m_j - p * m_j / m - (0 if lost is None else lost[j])
        s2 = float(res[rows] @ res[rows]) / max(dof, 1.0)
        meat[np.ix_(cols, cols)] += s2 * block
    cov = bread @ meat @ bread
    cov[~determined, :] = np.nan
    cov[:, ~determined] = np.nan
    se = np.sqrt(np.clip(np.diag(cov), 0, None))
    se[~determined] = np.nan
    return cov, se
