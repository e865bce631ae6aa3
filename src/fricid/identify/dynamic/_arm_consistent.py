"""Physically consistent standard parameters behind the identified base parameters.

Least squares gives the base parameters ``beta`` with their information matrix ``H = cov^-1``.
Many standard parameter vectors ``pi`` map onto them (``beta = P pi``,
:meth:`fricid.robot.BaseParameters.project`); some are physical (every body's
pseudo-inertia positive definite; Wensing, Kim and Slotine 2017), perhaps none. We solve

    min_theta  (P pi(theta) - beta)' H (P pi(theta) - beta) + eps^2 |(pi(theta) - pi_0) / s|^2

over the log-Cholesky parameters ``theta`` of every body (Rucker and Wensing 2022;
:func:`fricid.robot.from_log_cholesky`), which cannot leave physics. ``pi_0`` are the URDF's
parameters and ``s`` their scales: the weak prior (``eps`` = :data:`PRIOR_WEIGHT`) fixes the
directions the data do not see and barely moves the others. The first term at the optimum is
the Mahalanobis distance ``d^2`` of the consistent base parameters from the least-squares
ones: at most :data:`CONSISTENT_D2` means the least-squares estimate is already physical
(within its noise), and it is kept; above, the consistent one replaces it and the result
says so.
"""

from __future__ import annotations

import numpy as np
import scipy.optimize

from ...robot import BaseParameters, from_log_cholesky, is_consistent, to_log_cholesky

__all__ = ["CONSISTENT_D2", "consistent_parameters"]

#: Weight of the prior towards the URDF's parameters.
PRIOR_WEIGHT = 1e-2
#: Largest Mahalanobis distance at which the least-squares estimate counts as physical.
CONSISTENT_D2 = 1.0
#: Scale floors of the prior: mass [kg], first moment [kg m], inertia [kg m^2].
_FLOORS = np.array([0.1, 0.01, 0.01, 0.01, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3])


def _start(pi0: np.ndarray) -> np.ndarray:
    """Log-Cholesky start from the URDF, each body made physical first if it is not."""
    bodies = pi0.reshape(-1, 10).copy()
    for k, body in enumerate(bodies):
        if not is_consistent(body)[0]:
            m = max(body[0], 0.1)
            bodies[k] = [m, 0, 0, 0, 1e-3 * m, 0, 1e-3 * m, 0, 0, 1e-3 * m]
    try:
        return to_log_cholesky(bodies.ravel())
    except Exception:  # a body on the boundary: a small mass-like body instead
        return np.zeros(bodies.size)


def consistent_parameters(
    beta: np.ndarray, cov: np.ndarray, bp: BaseParameters, pi0: np.ndarray
) -> dict:
    """The consistent standard parameters nearest the data (module notes).

    Returns
    -------
    dict
        ``pi`` (standard, physical), ``beta`` (their base parameters), ``d2`` (Mahalanobis
        distance from the least-squares ``beta``), ``ls_consistent`` (``d2 <=``
        :data:`CONSISTENT_D2`), ``converged``.
    """
    good = np.isfinite(np.diag(cov))
    H = np.zeros_like(cov)
    sub = cov[np.ix_(good, good)]
    H[np.ix_(good, good)] = np.linalg.pinv(sub, rcond=1e-12, hermitian=True)
    w, V = np.linalg.eigh((H + H.T) / 2)
    L = (V * np.sqrt(np.clip(w, 0, None))).T  # L' L = H
    scale = np.maximum(np.abs(pi0), np.tile(_FLOORS, pi0.size // 10))

    def residual(theta: np.ndarray) -> np.ndarray:
        pi = from_log_cholesky(theta)
        return np.concatenate([L @ (bp.project(pi) - beta), PRIOR_WEIGHT * (pi - pi0) / scale])

    sol = scipy.optimize.least_squares(residual, _start(pi0), method="trf", x_scale="jac")
    pi = from_log_cholesky(sol.x)
    bc = bp.project(pi)
    d = bc - beta
    d2 = float(d @ H @ d)
    return {
        "pi": pi,
        "beta": bc,
        "d2": d2,
        "ls_consistent": d2 <= CONSISTENT_D2,
        "converged": bool(sol.success),
    }
