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

from ....robot import BaseParameters, is_consistent, to_log_cholesky

__all__ = ["CONSISTENT_D2", "consistent_parameters"]

#: Weight of the prior towards the URDF's parameters.
PRIOR_WEIGHT = 1e-2
#: Largest Mahalanobis distance at which the least-squares estimate counts as physical.
CONSISTENT_D2 = 1.0
#: Scale floors of the prior: mass [kg], first moment [kg m], inertia [kg m^2].
#: Most evaluations of the constrained problem.
MAX_NFEV = 300
_FLOORS = np.array([0.1, 0.01, 0.01, 0.01, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3])


def _pi(theta: np.ndarray) -> np.ndarray:
    """:func:`fricid.robot.from_log_cholesky` for a batch (k, 10 B), complex allowed (so that
    the complex step gives its exact Jacobian), shape (k, 10 B)."""
    th = theta.reshape(theta.shape[0], -1, 10)
    alpha, d1, d2, d3, s12, s23, s13, t1, t2, t3 = np.moveaxis(th, -1, 0)
    zero = np.zeros_like(alpha)
    U = (
        np.stack(
            [
                np.stack([np.exp(d1), s12, s13, t1], -1),
                np.stack([zero, np.exp(d2), s23, t2], -1),
                np.stack([zero, zero, np.exp(d3), t3], -1),
                np.stack([zero, zero, zero, zero + 1.0], -1),
            ],
            -2,
        )
        * np.exp(alpha)[..., None, None]
    )
    J = U @ np.swapaxes(U, -1, -2)
    sigma = J[..., :3, :3]
    tr = sigma[..., 0, 0] + sigma[..., 1, 1] + sigma[..., 2, 2]
    inertia = tr[..., None, None] * np.eye(3) - sigma
    out = np.stack(
        [
            J[..., 3, 3],
            J[..., 0, 3],
            J[..., 1, 3],
            J[..., 2, 3],
            inertia[..., 0, 0],
            inertia[..., 0, 1],
            inertia[..., 1, 1],
            inertia[..., 0, 2],
            inertia[..., 1, 2],
            inertia[..., 2, 2],
        ],
        -1,
    )
    return out.reshape(theta.shape[0], -1)


def _pi_jacobian(theta: np.ndarray) -> np.ndarray:
    """d pi / d theta by the complex step, (10 B, 10 B)."""
    h = 1e-30
    p = theta.size
    batch = theta[None, :] + 1j * h * np.eye(p)
    return (_pi(batch).imag / h).T


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


def _projection(bp: BaseParameters, p: int) -> np.ndarray:
    """The matrix ``P`` of ``beta = P pi``, (r, p)."""
    return np.column_stack([bp.project(e) for e in np.eye(p)])


def consistent_parameters(
    beta: np.ndarray, cov: np.ndarray, bp: BaseParameters, pi0: np.ndarray
) -> dict:
    """The consistent standard parameters nearest the data (module notes).

    The least-squares ``beta`` is first mapped to the standard parameters nearest the URDF's
    (in the prior's scales) that give it exactly, ``pi = pi_0 + S (P S)^+ (beta - P pi_0)``;
    when those are physical, nothing is solved (``d2 = 0``).

    Returns
    -------
    dict
        ``pi`` (standard, physical), ``beta`` (their base parameters), ``d2`` (Mahalanobis
        distance from the least-squares ``beta``), ``ls_consistent`` (``d2 <=``
        :data:`CONSISTENT_D2`), ``converged``.
    """
    p = pi0.size
    P = _projection(bp, p)
    scale = np.maximum(np.abs(pi0), np.tile(_FLOORS, p // 10))
    good = np.isfinite(np.diag(cov))
    target = np.where(good, beta, P @ pi0)  # undetermined directions: the URDF's
    S = np.diag(scale)
    near = pi0 + S @ np.linalg.pinv(P @ S, rcond=1e-10) @ (target - P @ pi0)
    if is_consistent(near).all():
        return {"pi": near, "beta": P @ near, "d2": 0.0, "ls_consistent": True, "converged": True}
    H = np.zeros_like(cov)
    H[np.ix_(good, good)] = np.linalg.pinv(cov[np.ix_(good, good)], rcond=1e-12, hermitian=True)
    w, V = np.linalg.eigh((H + H.T) / 2)
    L = (V * np.sqrt(np.clip(w, 0, None))).T  # L' L = H

    def residual(theta: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            pi = _pi(theta[None, :])[0]
        if not np.isfinite(pi).all():
            return np.full(target.size + p, 1e100)
        return np.concatenate([L @ (P @ pi - target), PRIOR_WEIGHT * (pi - pi0) / scale])

    def jacobian(theta: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            D = np.nan_to_num(_pi_jacobian(theta))
        return np.vstack([L @ P @ D, PRIOR_WEIGHT * D / scale[:, None]])

    with np.errstate(over="ignore"):  # a trial step far out: an infinite cost, rejected
        sol = scipy.optimize.least_squares(
            residual, _start(pi0), jac=jacobian, method="trf", x_scale="jac", max_nfev=MAX_NFEV
        )
    pi = _pi(sol.x[None, :])[0]
    bc = P @ pi
    d = bc - target
    d2 = float(d @ H @ d)
    return {
        "pi": pi,
        "beta": bc,
        "d2": d2,
        "ls_consistent": d2 <= CONSISTENT_D2,
        "converged": bool(sol.success),
    }
