"""Where the Jacobian's interval is the profile's: the quadratic approximation checked at its ends.

The profile-likelihood interval of ``theta_j`` (:mod:`fricid.identify.static.profile`) ends
where ``SSE_j(t)``, the SSE minimised over the other parameters with ``theta_j = t``, reaches
the threshold ``SSE_min + rise`` with ``rise = s^2 t_{n-p}^2`` (Bates and Watts 1988, sec.
6.1). Where the model is linear in its parameters near the optimum, ``SSE_j`` is the quadratic
``SSE_min + (t - theta_j)^2 s^2 / C_jj`` (``C`` the Jacobian's covariance), its minimiser over
the other parameters lies on the straight *profile trace* ``theta + (t - theta_j) C_:j /
C_jj``, and the interval is the Jacobian's ``theta_j +/- t se_j`` (Wald) exactly.

How far the model is from that is what decides whether the profile must be computed, and it
is measured where it matters, at the Wald interval's two ends: the other parameters start on
the trace at ``t = theta_j +/- t se_j`` and take :data:`GN_STEPS` Gauss-Newton steps (the
conditional minimisation the profile would do, all ends in one batched evaluation of the
residuals per step); the SSE reached estimates ``SSE_j`` there. A side is *checked* when

* the trace stays inside the search box (a side near a bound needs the profile: it may be
  open, and the minimisation there is constrained),
* the parameter is not poorly determined (no correlation beyond :data:`MAX_CORREL` with
  another: the trace's direction is then ill-conditioned),
* the steps converge (the last lowers the SSE by less than :data:`STEP_TOL` of ``rise``), and
* the estimated ``SSE_j - SSE_min`` is within :data:`CHECK_TOL` of ``rise``: the quadratic
  approximation's error there (what Bates and Watts' relative curvature measures, up to a
  factor, in the directions that matter) is small.

A checked side's end is then moved to where the measured rise, continued quadratically,
reaches the threshold: ``theta_j +/- t se_j sqrt(rise / (SSE_j - SSE_min))`` (within
:data:`CHECK_TOL` of the Wald end, and nearer the profile's crossing). Every other side is
profiled by re-fits as before.
"""

from __future__ import annotations

import numpy as np

from ..problem import IdentificationProblem
from .profile import profile_threshold

__all__ = ["CHECK_TOL", "GN_STEPS", "MAX_CORREL", "STEP_TOL", "checked_ends"]

#: A side is checked when the estimated profile at its Wald end rises within this fraction of
#: the threshold's rise (10 % of the rise is about 5 % of the interval's half-width).
CHECK_TOL = 0.1

#: Gauss-Newton steps of the other parameters at each Wald end.
GN_STEPS = 2

#: The last step must lower the SSE by less than this fraction of the threshold's rise.
STEP_TOL = 0.02

#: A parameter correlated beyond this with another is profiled (poorly determined).
MAX_CORREL = 0.999


def _gauss_newton(
    problem: IdentificationProblem, T: np.ndarray, held: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One Gauss-Newton step of every parameter but ``held[k]`` at each row ``T[k]``, all rows
    in two batched residual calls; the step is cut at the box.

    Returns ``(T_new, sse_before, sse_after)``; the SSEs are NaN where residuals are not
    finite, and ``T_new`` is ``T`` there."""
    m, p = T.shape
    h = 1e-7 * np.maximum(np.abs(T), 1e-3)
    steps = T[:, None, :] + h[:, :, None] * np.eye(p)[None]
    R = problem.residuals(np.vstack([T, steps.reshape(m * p, p)]))
    r = R[:m]
    J = (R[m:].reshape(m, p, -1) - r[:, None, :]) / h[:, :, None]  # (m, p, n)
    J[np.arange(m), held, :] = 0.0
    J = np.transpose(J, (0, 2, 1))  # (m, n, p)
    norms = np.linalg.norm(J, axis=1)
    norms[norms == 0] = 1.0
    finite = np.isfinite(J).all(axis=(1, 2)) & np.isfinite(r).all(axis=1)
    J = np.where(finite[:, None, None], J, 0.0)
    delta = (
        -np.einsum(
            "mpn,mn->mp", np.linalg.pinv(J / norms[:, None, :]), np.where(finite[:, None], r, 0.0)
        )
        / norms
    )
    delta[np.arange(m), held] = 0.0
    new = np.clip(T + delta, problem.bounds[:, 0], problem.bounds[:, 1])
    r_new = problem.residuals(new)
    before = np.where(finite, np.sum(np.where(finite[:, None], r, 0.0) ** 2, axis=1), np.nan)
    ok = finite & np.isfinite(r_new).all(axis=1)
    after = np.where(ok, np.sum(np.where(ok[:, None], r_new, 0.0) ** 2, axis=1), np.nan)
    return np.where(ok[:, None], new, T), before, after


def checked_ends(
    problem: IdentificationProblem,
    x_hat: np.ndarray,
    cov: np.ndarray,
    sse: float,
    level: float = 0.95,
) -> tuple[np.ndarray, np.ndarray, float]:
    """The interval ends the quadratic approximation gives where it is checked (module
    docstring), and which sides are.

    Parameters
    ----------
    problem : IdentificationProblem
        The fitted problem (loss ``sse``).
    x_hat : ndarray (p,)
        The optimum (free parameters).
    cov : ndarray (p, p)
        The Jacobian's covariance at ``x_hat`` (finite: every parameter determined).
    sse : float
        ``SSE_min``.
    level : float, default 0.95

    Returns
    -------
    ends : ndarray (p, 2)
        Lower and upper end of each parameter's interval on its checked sides, else NaN.
    checked : ndarray of bool (p, 2)
    lowest : float
        The lowest SSE any step reached (below ``sse``: the fit was not at the optimum).
    """
    p = x_hat.size
    lo, hi = problem.bounds[:, 0], problem.bounds[:, 1]
    rise = profile_threshold(sse, problem.n_obs, p, level) - sse
    var = np.diag(cov)
    half = np.sqrt(rise * var / (sse / (problem.n_obs - p))) if sse > 0 else np.zeros(p)
    with np.errstate(invalid="ignore", divide="ignore"):  # var 0: a fit without noise
        trace = cov / var[None, :]  # column j: the trace's direction per unit of theta_j
    sign = np.array([-1.0, 1.0])
    T = x_hat[None, None, :] + sign[None, :, None] * (half[:, None] * trace.T)[:, None, :]
    T = T.reshape(2 * p, p)  # rows: (j, low), (j, high)
    held = np.repeat(np.arange(p), 2)
    inside = np.all((lo <= T) & (hi >= T), axis=1)
    d = np.sqrt(var)
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = np.abs(cov / np.outer(d, d)) - np.eye(p)
    determined = np.repeat(np.nanmax(corr, axis=1, initial=0.0) < MAX_CORREL, 2)
    # an interval under 1e-9 of the box (a fit without noise) is left to the profile
    ok = inside & determined & (np.repeat(half, 2) > 1e-9 * (hi - lo)[held])
    est = np.full(2 * p, np.nan)
    lowest = float(sse)
    if ok.any():
        Tk = np.clip(T[ok], lo, hi)
        last = np.zeros(Tk.shape[0])
        for _ in range(GN_STEPS):
            Tk, before, after = _gauss_newton(problem, Tk, held[ok])
            last = before - after
        est[ok] = after
        lowest = min(lowest, float(np.nanmin(after, initial=np.inf)))
        good = np.isfinite(after) & (last < STEP_TOL * rise)
        good &= np.all((Tk > lo) & (Tk < hi) | (np.arange(p)[None, :] == held[ok][:, None]), axis=1)
        ok[np.flatnonzero(ok)[~good]] = False
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = (est - sse) / rise
    ok &= np.abs(ratio - 1.0) <= CHECK_TOL
    dist = np.where(ok, np.repeat(half, 2) / np.sqrt(np.where(ok, ratio, 1.0)), np.nan)
    ends = (np.repeat(x_hat, 2) + np.tile(sign, p) * dist).reshape(p, 2)
    return ends, ok.reshape(p, 2), lowest
