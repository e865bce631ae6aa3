"""Separating friction from gravity (BAS-RBFNN paper eq. 7, 9-11).

At constant velocity the motor torque is ``tau_m = tau_f - tau_g`` (eq. 8). Moving the same
position in both directions, ``tau_f(v) - tau_g = tau+`` and ``tau_f(-v) - tau_g = tau-``
(eq. 9); with a symmetric friction, eq. 11 gives ``tau_f = (tau+ - tau-) / 2`` and
``tau_g = -(tau+ + tau-) / 2``, and eq. 7, ``tau_g = p_x cos(theta) - p_y sin(theta)``, is
fitted to the latter by linear least squares.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DataError

__all__ = ["GravityFit", "fit_gravity", "gravity_se", "separate"]


def separate(tau_plus, tau_minus) -> tuple[np.ndarray, np.ndarray]:
    """Friction and gravity torques from the two directions' motor torques, eq. 11.

    Returns ``(tau_f, tau_g)`` with ``tau_f = (tau+ - tau-) / 2`` (the positive-direction
    friction) and ``tau_g = -(tau+ + tau-) / 2``.
    """
    tp = np.asarray(tau_plus, dtype=float)
    tm = np.asarray(tau_minus, dtype=float)
    return 0.5 * (tp - tm), -0.5 * (tp + tm)


def gravity_se(fit, cos, sin) -> np.ndarray:
    """N m, the standard error of the fitted gravity torque (eq. 7) averaged over samples
    whose mean ``cos`` and ``sin`` of the position are given, from the coefficients'
    standard errors (``fit.p_x_se``, ``fit.p_y_se``; their correlation left out). A row of
    friction with the fitted gravity removed carries it beside its own noise: it is common to
    every speed at that position, which no friction law of the speed can follow."""
    cos, sin = np.asarray(cos, dtype=float), np.asarray(sin, dtype=float)
    return np.sqrt((cos * float(fit.p_x_se)) ** 2 + (sin * float(fit.p_y_se)) ** 2)


@dataclass(frozen=True)
class GravityFit:
    """Least-squares fit of eq. 7 to gravity torques.

    Attributes
    ----------
    p_x, p_y : N m, the coefficients of ``tau_g = p_x cos(theta) - p_y sin(theta)``.
    p_x_se, p_y_se : N m, their standard errors (from the residual scatter).
    residual_rms : N m, RMS of the fit residuals.
    n : number of points fitted.
    """

    p_x: float
    p_y: float
    p_x_se: float
    p_y_se: float
    residual_rms: float
    n: int

    def torque(self, theta) -> np.ndarray:
        """The fitted gravity torque [N m] at ``theta`` [rad] (eq. 7); it is the load (eq. 12)."""
        theta = np.asarray(theta, dtype=float)
        return self.p_x * np.cos(theta) - self.p_y * np.sin(theta)


def fit_gravity(theta, tau_g, *, source: str | None = None, cos=None, sin=None) -> GravityFit:
    """Fit eq. 7 to gravity torques ``tau_g`` [N m] at positions ``theta`` [rad].

    ``cos`` and ``sin``, when given, are the means of ``cos`` and ``sin`` of the positions
    each torque was averaged over (a position bin's samples): eq. 7 is linear in them, so the
    fit is then exact however wide the bins, where ``cos(mean theta)`` is off by about
    ``h^2 / 6`` relative for a bin of half-width ``h``.

    Needs at least two distinct positions (not half a turn apart, and spread over more than
    about 0.1 deg so the two coefficients are separable); raises :class:`DataError` otherwise.
    """
    theta = np.asarray(theta, dtype=float).ravel()
    y = np.asarray(tau_g, dtype=float).ravel()
    c = np.cos(theta) if cos is None else np.asarray(cos, dtype=float).ravel()
    s = np.sin(theta) if sin is None else np.asarray(sin, dtype=float).ravel()
    A = np.column_stack([c, -s])
    coef, _, rank, sv = np.linalg.lstsq(A, y, rcond=None)
    if rank < 2 or sv[-1] < 1e-3 * sv[0]:
        raise DataError(
            "the gravity fit (eq. 7) needs samples at two or more distinct positions; "
            "give position bins (positions=...) or, for a horizontal joint, gravity='none'",
            file=source,
        )
    resid = y - A @ coef
    n = y.size
    dof = n - 2
    if dof > 0:
        s2 = float(resid @ resid) / dof
        cov = s2 * np.linalg.inv(A.T @ A)
        se = np.sqrt(np.diag(cov))
    else:
        se = np.full(2, np.nan)
    return GravityFit(
        p_x=float(coef[0]),
        p_y=float(coef[1]),
        p_x_se=float(se[0]),
        p_y_se=float(se[1]),
        residual_rms=float(np.sqrt(np.mean(resid**2))),
        n=int(n),
    )
