"""The whole-arm regression: stacking, weighted least squares, the Stribeck shapes by
variable projection, and covariances that respect correlated residuals.

Rows are one joint at one (decimated) instant, ``(t, j)``; columns are the base inertial
parameters (Gautier 1991; :func:`fricid.robot.base_parameters`) then each joint's friction
(:mod:`._arm_friction`), zero on the other joints' rows. A joint's rows slower than its
velocity threshold are left out: a joint at rest holds any torque within its static friction,
which no law of velocity says.

* Weighted least squares (Gautier and Poignet 2001): each joint's noise ``sigma_j`` is
  estimated from its ordinary least-squares residuals, ``sigma_j^2 = SSE_j / (m_j - p m_j /
  m)``, and its rows are divided by it.
* The Stribeck shapes ``(w_s, delta)`` of each joint and direction are found by variable
  projection (Golub and Pereyra 1973) one block at a time: with every other column fixed, the
  sum of squares with the excess column ``x`` is ``SSE_0 - (x' r_0)^2 / (x' (I - P_0) x)``,
  evaluated for a grid of shapes at once, then on finer grids around the best; the blocks are
  swept twice.
* Covariance (:func:`arm_covariance`): residuals of low-passed signals are correlated over
  about ``1 / f_c``, so 60 000 samples are far fewer independent ones. The correlation length
  ``L`` is the first lag at which the residuals' autocorrelation (averaged over the joints)
  falls below :data:`RHO_END`; the effective sample size per joint is ``m_j / (1 + 2 sum_{k
  <= L} rho_k)``; the covariance is the cluster-robust sandwich (Liang and Zeger 1986;
  :func:`fricid.identify.dynamic._data.cluster_covariance`) over contiguous blocks of
  :data:`BLOCK_OVER_L` ``L`` instants (all joints of an instant in one cluster, so the
  correlation between joints counts too), never below the plain estimate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._arm_friction import DELTA_BOX, W_S_BOX, JointFriction
from ._arm_signals import ArmSignals
from ._data import cluster_covariance

__all__ = ["Stack", "arm_covariance", "search_shapes", "stack", "wls"]

#: The autocorrelation below which residuals count as uncorrelated.
RHO_END = 0.05
#: Cluster length over the correlation length.
BLOCK_OVER_L = 10
#: Fewest clusters.
MIN_CLUSTERS = 30
#: The first grid of Stribeck shapes.
W_S_GRID = np.geomspace(2e-3, 0.6, 14)
DELTA_GRID = np.array([0.5, 0.75, 1.0, 1.5, 2.0, 3.0])


@dataclass
class Stack:
    """The stacked regression (module notes)."""

    A: np.ndarray  # (m, p) unweighted
    y: np.ndarray  # (m,)
    row_joint: np.ndarray  # (m,)
    row_time: np.ndarray  # (m,) index of the decimated instant
    offsets: list[int]  # first friction column of each joint
    n_base: int

    def weighted(self, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        w = 1.0 / sigma[self.row_joint]
        return self.A * w[:, None], self.y * w


def friction_block(sig: ArmSignals, jf: JointFriction, j: int) -> np.ndarray:
    """Joint ``j``'s friction columns at the log's rate, parallel-filtered and decimated."""
    return sig.parallel(jf.columns(sig.full_dq[:, j]))


def stack(
    Yb: np.ndarray, sig: ArmSignals, frictions: list[JointFriction], mask: np.ndarray
) -> Stack:
    """Stack ``Yb`` (N, n, r) and the friction columns on the rows ``mask`` (N, n) keeps."""
    N, n, r = Yb.shape
    widths = [len(jf.linear_names) for jf in frictions]
    offsets = list(r + np.concatenate([[0], np.cumsum(widths)[:-1]]).astype(int))
    A = np.zeros((N, n, r + sum(widths)))
    A[:, :, :r] = Yb
    for j, jf in enumerate(frictions):
        A[:, j, offsets[j] : offsets[j] + widths[j]] = friction_block(sig, jf, j)
    t_idx, j_idx = np.nonzero(mask)
    return Stack(A[t_idx, j_idx], sig.tau[t_idx, j_idx], j_idx, t_idx, offsets, r)


def lstsq(A: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Least squares with the columns scaled to unit norm (zero columns left at 0)."""
    norms = np.linalg.norm(A, axis=0)
    norms[norms == 0] = 1.0
    x, *_ = np.linalg.lstsq(A / norms, y, rcond=1e-10)
    return x / norms


def noise(st: Stack, theta: np.ndarray, n: int) -> np.ndarray:
    """Each joint's noise from the residuals (module notes); NaN for a joint without rows."""
    res = st.y - st.A @ theta
    m, p = st.A.shape
    out = np.full(n, np.nan)
    for j in range(n):
        rj = res[st.row_joint == j]
        if rj.size:
            out[j] = np.sqrt(rj @ rj / max(rj.size * (1 - p / m), 1.0))
    return out


def wls(st: Stack, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gautier's weighted least squares: (theta, sigma per joint)."""
    theta = lstsq(st.A, st.y)
    sigma = noise(st, theta, n)
    safe = np.where(np.isfinite(sigma) & (sigma > 0), sigma, 1.0)
    theta = lstsq(*st.weighted(safe))
    return theta, noise(st, theta, n)


def _gain(A: np.ndarray, y: np.ndarray, k: int, rows: np.ndarray, X: np.ndarray) -> np.ndarray:
    """The drop of the sum of squares when column ``k`` of ``A`` is each column of ``X``
    (non-zero on ``rows`` only; module notes)."""
    Am = np.delete(A, k, axis=1)
    norms = np.linalg.norm(Am, axis=0)
    norms[norms == 0] = 1.0
    As = Am / norms
    beta, *_ = np.linalg.lstsq(As, y, rcond=1e-10)
    r0 = y - As @ beta
    G = np.linalg.pinv(As.T @ As, rcond=1e-12)
    C = As[rows].T @ X
    num = (X.T @ r0[rows]) ** 2
    den = np.einsum("ik,ik->k", X, X) - np.einsum("ik,ij,jk->k", C, G, C)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den > 1e-12 * np.einsum("ik,ik->k", X, X), num / den, -np.inf)


def _candidates(
    sig: ArmSignals, jf: JointFriction, j: int, d: str, w: np.ndarray, e: np.ndarray
) -> np.ndarray:
    return sig.parallel(jf.excess_column(sig.full_dq[:, j], d, w, e))


def search_shapes(
    sig: ArmSignals,
    Yb: np.ndarray,
    frictions: list[JointFriction],
    mask: np.ndarray,
    sigma: np.ndarray,
    sweeps: int = 2,
) -> None:
    """Set each Stribeck joint's shapes by variable projection (module notes), in place."""
    n = len(frictions)
    for _ in range(sweeps):
        for j, jf in enumerate(frictions):
            if not jf.stribeck or not mask[:, j].any():
                continue
            for k, d in enumerate(jf.directions):
                st = stack(Yb, sig, frictions, mask)
                A, y = st.weighted(sigma)
                col = st.offsets[j] + 3 * k + 1
                rows = np.flatnonzero(st.row_joint == j)
                t_rows = st.row_time[rows]
                w_grid, e_grid = np.meshgrid(W_S_GRID, DELTA_GRID)
                w_grid, e_grid = w_grid.ravel(), e_grid.ravel()
                for zoom in (None, 1.6, 1.15):
                    if zoom is not None:
                        w0, e0 = jf.shapes[d]
                        w_grid, e_grid = np.meshgrid(
                            np.clip(w0 * zoom ** np.linspace(-2, 2, 7), *W_S_BOX),
                            np.clip(e0 * zoom ** np.linspace(-1, 1, 5), *DELTA_BOX),
                        )
                        w_grid, e_grid = w_grid.ravel(), e_grid.ravel()
                    X = _candidates(sig, jf, j, d, w_grid, e_grid)[t_rows] / sigma[j]
                    gain = _gain(A, y, col, rows, X)
                    if np.isfinite(gain).any():
                        best = int(np.argmax(gain))
                        jf.shapes[d] = (float(w_grid[best]), float(e_grid[best]))
    del n


def correlation_length(res: np.ndarray, row_joint: np.ndarray, row_time: np.ndarray, n: int):
    """(L, effective samples per joint) from the residuals' autocorrelation (module notes)."""
    T = int(row_time.max()) + 1 if row_time.size else 1
    series = np.zeros((T, n))
    series[row_time, row_joint] = res
    counts = np.bincount(row_joint, minlength=n)
    max_lag = max(2, T // 20)
    rho = np.zeros((max_lag + 1, n))
    for j in range(n):
        x = series[:, j]
        if counts[j] < 10 or not np.any(x):
            continue
        f = np.fft.rfft(x, 2 * T)
        ac = np.fft.irfft(f * np.conj(f))[: max_lag + 1]
        rho[:, j] = ac / ac[0]
    used = counts >= 10
    mean = rho[:, used].mean(axis=1) if used.any() else np.zeros(max_lag + 1)
    below = np.flatnonzero(mean < RHO_END)
    L = int(below[0]) if below.size else max_lag
    L = max(L, 1)
    inflation = 1 + 2 * np.clip(rho[1 : L + 1], 0, None).sum(axis=0)
    return L, counts / inflation


def arm_covariance(J: np.ndarray, res: np.ndarray, st: Stack, n: int):
    """(cov, stderr, clusters, L, effective samples) of the weighted problem (module notes)."""
    L, n_eff = correlation_length(res, st.row_joint, st.row_time, n)
    T = int(st.row_time.max()) + 1
    block = max(BLOCK_OVER_L * L, 1)
    if T // block < MIN_CLUSTERS:
        block = max(T // MIN_CLUSTERS, 1)
    cov, se, g = cluster_covariance(J, res, st.row_time // block)
    return cov, se, g, L, n_eff
