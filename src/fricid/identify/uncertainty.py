"""Parameter uncertainty from the Jacobian at the optimum, as scipy's ``curve_fit`` computes it.

The covariance is ``s^2 (J^T J)^+`` with ``s^2 = SSE / (n - p)`` and the pseudo-inverse taken
through the singular value decomposition of ``J`` itself (never ``J^T J``, which would square
its condition number), dropping singular values below ``eps * max(J.shape) * s[0]`` (scipy's
``curve_fit``). ``J``'s columns are scaled to unit length first (as MINPACK scales its
variables), so that the cut-off measures collinearity, not the parameters' units; the
covariance is scaled back (for a full-rank ``J`` this is exactly ``s^2 (J^T J)^-1``).

A parameter is *not determined* (standard error NaN) when its direction is not within the
span of the singular vectors whose singular values exceed :data:`DETERMINED_RCOND` times the
largest: a finite-difference Jacobian is accurate to about 1e-9 relative, so a direction the
data cannot see shows a singular value of that size rather than one below scipy's cut-off.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["covariance_svd", "jacobian", "jacobian_uncertainty"]

#: A parameter counts as determined when at least ``1 - DETERMINED_TOL`` of its unit vector's
#: squared length lies in the span of the right singular vectors (of the column-scaled
#: Jacobian) with singular values above ``DETERMINED_RCOND * s[0]``.
DETERMINED_TOL = 1e-6
DETERMINED_RCOND = 1e-6


def jacobian(
    residual: Callable[[np.ndarray], np.ndarray], theta: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Central-difference Jacobian ``(n, p)`` of a batch residual ``(k, p) -> (k, n)`` at
    ``theta (p,)``, in one batch call; also returns the residual at ``theta``."""
    p = theta.size
    h = 1e-6 * np.maximum(np.abs(theta), 1e-3)
    steps = np.vstack([theta + np.diag(h), theta - np.diag(h)])
    r = residual(np.vstack([theta[None, :], steps]))
    r0, rp, rm = r[0], r[1 : p + 1], r[p + 1 :]
    return ((rp - rm) / (2 * h[:, None])).T, r0


def covariance_svd(J: np.ndarray, s2: float) -> tuple[np.ndarray, np.ndarray]:
    """``s2 (J^T J)^+`` by the SVD of ``J`` (scipy ``curve_fit``'s cut-off), and a mask of the
    parameters it determines.

    Parameters
    ----------
    J : ndarray (n, p)
        Jacobian of the residuals.
    s2 : float
        Residual variance.

    Returns
    -------
    cov : ndarray (p, p)
        Covariance; rows and columns of undetermined parameters are NaN.
    determined : ndarray of bool (p,)
    """
    p = J.shape[1]
    if not np.isfinite(J).all():
        return np.full((p, p), np.nan), np.zeros(p, dtype=bool)
    norms = np.linalg.norm(J, axis=0)
    norms[norms == 0] = 1.0  # a parameter without effect: a zero column, singular value 0
    _, s, VT = np.linalg.svd(J / norms, full_matrices=False)
    if s.size == 0 or s[0] == 0:
        return np.full((p, p), np.nan), np.zeros(p, dtype=bool)
    keep = s > np.finfo(float).eps * max(J.shape) * s[0]
    cov = s2 * ((VT[keep].T / s[keep] ** 2) @ VT[keep]) / np.outer(norms, norms)
    seen = VT[s > DETERMINED_RCOND * s[0]]
    determined = np.sum(seen**2, axis=0) >= 1.0 - DETERMINED_TOL
    cov[~determined, :] = np.nan
    cov[:, ~determined] = np.nan
    return cov, determined


def jacobian_uncertainty(
    residual: Callable[[np.ndarray], np.ndarray], theta: np.ndarray, n_obs: int
) -> tuple[np.ndarray, np.ndarray | None]:
    """Standard errors and covariance of ``theta`` from a central-difference Jacobian.

    Parameters
    ----------
    residual : callable
        Batch residuals ``(k, p) -> (k, n)``.
    theta : ndarray (p,)
        The optimum.
    n_obs : int
        Number of observations n.

    Returns
    -------
    stderr : ndarray (p,)
        NaN for a parameter the data do not determine (see :func:`covariance_svd`).
    cov : ndarray (p, p) or None
        None when there are no spare observations (``n <= p``) or nothing is determined.
    """
    p = theta.size
    nan = np.full(p, np.nan)
    dof = n_obs - p
    if p == 0 or dof <= 0:
        return nan, None
    J, r0 = jacobian(residual, theta)
    cov, determined = covariance_svd(J, float(r0 @ r0) / dof)
    if not determined.any():
        return nan, None
    return np.where(determined, np.sqrt(np.clip(np.diag(cov), 0.0, None)), np.nan), cov
