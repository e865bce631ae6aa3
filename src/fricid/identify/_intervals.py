"""What an analytic fit stores for its prediction intervals: the covariance of its free
parameters and the residual variance (:mod:`fricid.fitted._interval`, the delta method).

``C = s^2 (J^T J)^+`` with ``J`` the Jacobian of the predictions in the free parameters at
the optimum and ``s^2 = SSE / (n - p)`` of the unweighted residuals (Seber & Wild 1989,
eq. 5.7). The pseudo-inverse (SVD, cut at ``eps max(n, p)`` of the largest singular value of
the column-scaled ``J``, as scipy's ``curve_fit``) leaves out the directions the data do not
determine: a prediction inside the data hardly moves along them, so the interval there stays
finite where a parameter's own standard error is not. A robust or weighted fit is treated as
least squares here: its residual variance, outliers included, sets the noise term.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..fitted._interval import gradient
from ..models import get_model

__all__ = ["delta_record"]


def delta_record(
    model_name: str, theta: np.ndarray, free: Sequence[str], X: np.ndarray, y: np.ndarray
) -> dict[str, Any] | None:
    """The model file's ``prediction_interval`` of an analytic fit (module notes), or None
    when there are no spare observations (``n <= p``) or the Jacobian is not finite."""
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
    if p:
        norms = np.linalg.norm(J, axis=0)
        norms[norms == 0] = 1.0
        _, s, VT = np.linalg.svd(J / norms, full_matrices=False)
        keep = s > np.finfo(float).eps * max(n, p) * s[0] if s[0] > 0 else s > np.inf
        cov = s2 * ((VT[keep].T / s[keep] ** 2) @ VT[keep]) / np.outer(norms, norms)
    return {
        "method": "delta",
        "free": free,
        "covariance": (0.5 * (cov + cov.T)).tolist(),
        "noise_std": float(np.sqrt(s2)),
        "dof": n - p,
    }
