"""Physically consistent inertial parameters: a body's ten standard parameters (Pinocchio's
order, :data:`~fricid.robot.model.PARAMETER_SYMBOLS`) are those of a real mass distribution iff
its pseudo-inertia matrix

    J = [[Sigma, h], [h^T, m]],  Sigma = tr(I)/2 * 1 - I,  h = m c

is positive semi-definite (Wensing, Kim and Slotine 2017). The log-Cholesky parametrisation
(Rucker and Wensing 2022) maps any ten real numbers ``theta`` to a positive-definite ``J = U
U^T``, ``U = e^alpha [[e^d1, s12, s13, t1], [0, e^d2, s23, t2], [0, 0, e^d3, t3], [0, 0, 0,
1]]``, so an identification over ``theta`` cannot leave physics.
"""

from __future__ import annotations

import numpy as np

from ..errors import ConfigError

__all__ = [
    "from_log_cholesky",
    "is_consistent",
    "pseudo_inertia",
    "to_log_cholesky",
]


def _body(pi: np.ndarray) -> np.ndarray:
    pi = np.asarray(pi, dtype=float)
    if pi.shape[-1] != 10:
        raise ConfigError(f"a body has 10 inertial parameters; got {pi.shape[-1]}")
    return pi


def pseudo_inertia(pi: np.ndarray) -> np.ndarray:
    """The 4 x 4 pseudo-inertia ``J`` of one body's parameters ``pi`` (module notes)."""
    m, hx, hy, hz, ixx, ixy, iyy, ixz, iyz, izz = _body(pi)
    inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    J = np.empty((4, 4))
    J[:3, :3] = 0.5 * np.trace(inertia) * np.eye(3) - inertia
    J[:3, 3] = J[3, :3] = (hx, hy, hz)
    J[3, 3] = m
    return J


def _parameters(J: np.ndarray) -> np.ndarray:
    sigma = J[:3, :3]
    inertia = np.trace(sigma) * np.eye(3) - sigma
    return np.array(
        [
            J[3, 3],
            *J[:3, 3],
            inertia[0, 0],
            inertia[0, 1],
            inertia[1, 1],
            inertia[0, 2],
            inertia[1, 2],
            inertia[2, 2],
        ]
    )


def is_consistent(pi: np.ndarray, *, rtol: float = 1e-9) -> np.ndarray:
    """Whether each body of ``pi`` (10 per body, last axis flattened) is physical: its
    pseudo-inertia has no eigenvalue below ``-rtol`` times its largest."""
    bodies = _body(np.asarray(pi, dtype=float).reshape(-1, 10))
    out = []
    for body in bodies:
        ev = np.linalg.eigvalsh(pseudo_inertia(body))
        out.append(bool(ev[0] >= -rtol * max(abs(ev[-1]), 1e-300)))
    return np.array(out)


def from_log_cholesky(theta: np.ndarray) -> np.ndarray:
    """Standard parameters from log-Cholesky ``theta`` = (alpha, d1, d2, d3, s12, s23, s13,
    t1, t2, t3) per body; ``theta`` of shape (10 k,) gives (10 k,)."""
    theta = np.asarray(theta, dtype=float).reshape(-1, 10)
    out = np.empty_like(theta)
    for k, (alpha, d1, d2, d3, s12, s23, s13, t1, t2, t3) in enumerate(theta):
        U = np.exp(alpha) * np.array(
            [
                [np.exp(d1), s12, s13, t1],
                [0.0, np.exp(d2), s23, t2],
                [0.0, 0.0, np.exp(d3), t3],
                [0.0, 0.0, 0.0, 1.0],
            ]
        )
        out[k] = _parameters(U @ U.T)
    return out.ravel()


def to_log_cholesky(pi: np.ndarray) -> np.ndarray:
    """The inverse of :func:`from_log_cholesky`, for bodies whose pseudo-inertia is positive
    definite (a :class:`ConfigError` names the first that is not)."""
    bodies = _body(np.asarray(pi, dtype=float).reshape(-1, 10))
    flip = np.eye(4)[::-1]
    out = np.empty_like(bodies)
    for k, body in enumerate(bodies):
        try:
            L = np.linalg.cholesky(flip @ pseudo_inertia(body) @ flip)
        except np.linalg.LinAlgError:
            raise ConfigError(
                f"body {k} is not physically consistent (its pseudo-inertia is not positive "
                "definite), so it has no log-Cholesky parameters"
            ) from None
        U = flip @ L @ flip  # upper triangular, J = U U^T
        alpha = np.log(U[3, 3])
        V = U / U[3, 3]
        out[k] = (
            alpha,
            np.log(V[0, 0]),
            np.log(V[1, 1]),
            np.log(V[2, 2]),
            V[0, 1],
            V[1, 2],
            V[0, 2],
            V[0, 3],
            V[1, 3],
            V[2, 3],
        )
    return out.ravel()
