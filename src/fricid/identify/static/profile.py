"""Profile-likelihood confidence intervals, inside the search box.

For a least-squares fit with ``n`` samples, ``p`` free parameters and minimum ``SSE_min``, the
profile of parameter ``theta_j`` is ``SSE_j(t) = min SSE`` over the other parameters with
``theta_j = t`` held fixed. Its ``1 - alpha`` interval is (Venzon and Moolgavkar 1988; Bates
and Watts 1988, sec. 6.1, the F form for an unknown noise variance)::

    { t : SSE_j(t) <= SSE_min (1 + F(1 - alpha; 1, n - p) / (n - p)) }

Unlike the Jacobian's ``value +/- t se`` (Wald) interval it follows the model's nonlinearity
(``w_s`` and ``delta`` enter the Stribeck model, RWSAVSBAS paper eq. 7, through
``exp(-(v / w_s)^delta)``) and it never leaves the feasible range: each side is searched only
up to the parameter's bound. A side on which the threshold is not crossed before the bound is
*open* (the data do not bound the parameter there: "w_s <= 20.8 rad/s, the bound"); both
sides open means the data do not identify the parameter at all.

How each side is found: from the estimate toward the bound, on a grid of :data:`GRID`
fractions of the way (geometric when the box spans more than two decades of a positive
parameter), the other free parameters are re-fitted by scipy's bounded ``trf`` (warm-started
from the previous grid point, Jacobian by forward differences in one batched call of
:meth:`~fricid.identify.problem.IdentificationProblem.residuals`); the first grid point above
the threshold is bracketed and the crossing refined by :data:`N_BISECT` bisections. A re-fit
that finds an SSE below ``SSE_min`` means the fit was not at the optimum; that is recorded
(:attr:`ProfileInterval.lower_sse`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats
from scipy.optimize import least_squares

from ...optim import single_blas_thread
from ..problem import IdentificationProblem

__all__ = ["GRID", "N_BISECT", "ProfileInterval", "profile_intervals", "profile_threshold"]

#: Fractions of the way from the estimate to the bound at which the profile is evaluated.
GRID = (0.02, 0.06, 0.15, 0.3, 0.5, 0.75, 1.0)

#: Bisections of the bracket around the threshold crossing.
N_BISECT = 5

#: Evaluations allowed to each re-fit of the other parameters.
REFIT_EVALS = 400

_FD = 1e-7


@dataclass
class ProfileInterval:
    """A profile-likelihood interval of one parameter.

    Attributes
    ----------
    low, high : float
        The interval's ends, inside the search box.
    low_open, high_open : bool
        True when the profile stays under the threshold up to that bound (the end is the
        bound itself: the data do not bound the parameter on that side).
    lower_sse : float
        The lowest SSE any re-fit found (below the fit's SSE: the fit was not at the optimum).
    nfev : int
        Residual evaluations spent on this parameter.
    """

    low: float
    high: float
    low_open: bool
    high_open: bool
    lower_sse: float
    nfev: int


def profile_threshold(sse_min: float, n_obs: int, n_free: int, level: float = 0.95) -> float:
    """``SSE_min (1 + F(level; 1, n - p) / (n - p))``: the profile's cut-off."""
    dof = max(n_obs - n_free, 1)
    return float(sse_min * (1.0 + stats.f.ppf(level, 1, dof) / dof))


class _Refit:
    """Re-fit every free parameter but ``j`` with ``theta_j`` held at a value."""

    def __init__(self, problem: IdentificationProblem, j: int) -> None:
        self.problem = problem
        self.j = j
        self.others = [k for k in range(problem.n_free) if k != j]
        b = problem.bounds[self.others]
        self.lo, self.span = b[:, 0], b[:, 1] - b[:, 0]
        self.nfev = 0

    def _theta(self, U: np.ndarray, value: float, x: np.ndarray) -> np.ndarray:
        T = np.repeat(x[None, :], U.shape[0], axis=0)
        T[:, self.others] = self.lo + np.clip(U, 0.0, 1.0) * self.span
        T[:, self.j] = value
        return T

    def __call__(self, value: float, x: np.ndarray) -> tuple[np.ndarray, float]:
        """The best ``(x, SSE)`` with ``x[j] = value``, starting from ``x``."""
        x = x.copy()
        x[self.j] = value
        if not self.others:
            r = self.problem.residuals(x[None, :])[0]
            self.nfev += 1
            return x, float(r @ r)

        def fun(u: np.ndarray) -> np.ndarray:
            self.nfev += 1
            r = self.problem.residuals(self._theta(u[None, :], value, x))[0]
            # scipy cannot step on non-finite residuals; a large finite one steers it away
            return r if np.isfinite(r).all() else np.full(r.shape, 1e50)

        def jac(u: np.ndarray) -> np.ndarray:
            h = np.where(u + _FD <= 1.0, _FD, -_FD)
            R = self.problem.residuals(self._theta(np.vstack([u, u + np.diag(h)]), value, x))
            self.nfev += R.shape[0]
            return np.nan_to_num(((R[1:] - R[0]) / h[:, None]).T)

        u0 = np.clip((x[self.others] - self.lo) / self.span, 1e-9, 1.0 - 1e-9)
        sol = least_squares(
            fun,
            u0,
            jac=jac,
            bounds=(0.0, 1.0),
            method="trf",
            x_scale="jac",
            ftol=1e-10,
            xtol=1e-10,
            gtol=1e-10,
            max_nfev=REFIT_EVALS,
        )
        out = self._theta(sol.x[None, :], value, x)[0]
        r = sol.fun
        return out, float(r @ r)


def _grid(est: float, bound: float, lo: float, hi: float) -> np.ndarray:
    frac = np.asarray(GRID)
    if lo > 0 and hi / lo > 100 and est > 0:
        return est * (bound / est) ** frac  # geometric: w_s and the like span decades
    return est + frac * (bound - est)


def _side(refit: _Refit, x_hat: np.ndarray, bound: float, thr: float, best: list[float]):
    """The end of the interval toward ``bound``: ``(end, open)``."""
    j = refit.j
    est = float(x_hat[j])
    lo, hi = refit.problem.bounds[j]
    if abs(bound - est) <= 1e-9 * (hi - lo):
        return bound, True
    inside_v, inside_x, inside_f = est, x_hat, best[1]
    for v in _grid(est, bound, lo, hi):
        x, f = refit(float(v), inside_x)
        best[0] = min(best[0], f)
        if f > thr:
            out_v, out_f = float(v), f
            break
        inside_v, inside_x, inside_f = float(v), x, f
    else:
        return bound, True
    for _ in range(N_BISECT):
        mid = 0.5 * (inside_v + out_v)
        x, f = refit(mid, inside_x)
        best[0] = min(best[0], f)
        if f > thr:
            out_v, out_f = mid, f
        else:
            inside_v, inside_x, inside_f = mid, x, f
    t = (thr - inside_f) / (out_f - inside_f) if out_f > inside_f else 0.0
    return inside_v + float(np.clip(t, 0.0, 1.0)) * (out_v - inside_v), False


@single_blas_thread
def profile_intervals(
    problem: IdentificationProblem,
    x_hat: np.ndarray,
    *,
    level: float = 0.95,
    which: list[int] | None = None,
    sides: np.ndarray | None = None,
) -> dict[str, ProfileInterval]:
    """Profile-likelihood intervals of the free parameters of a least-squares fit.

    Parameters
    ----------
    problem : IdentificationProblem
        The fitted problem (its residuals are re-evaluated; loss ``sse``).
    x_hat : ndarray (p,)
        The optimum, free parameters only.
    level : float, default 0.95
        Confidence level.
    which : list of int, optional
        Indices of the free parameters to profile (default: all).
    sides : ndarray of bool (p, 2), optional
        The lower and upper sides to profile (default: both sides of ``which``); a side left
        out has a NaN end, not open.

    Returns
    -------
    dict of str to ProfileInterval
        Keyed by free-parameter name (the parameters with a side profiled); every end lies
        inside the search box.
    """
    x_hat = np.asarray(x_hat, dtype=float)
    r0 = problem.residuals(x_hat[None, :])[0]
    sse = float(r0 @ r0)
    thr = profile_threshold(sse, problem.n_obs, problem.n_free, level)
    out = {}
    todo = np.ones((problem.n_free, 2), dtype=bool) if sides is None else np.asarray(sides)
    for j in range(problem.n_free) if which is None else which:
        if not todo[j].any():
            continue
        refit = _Refit(problem, j)
        best = [sse, sse]
        lo, hi = problem.bounds[j]
        low, low_open = _side(refit, x_hat, float(lo), thr, best) if todo[j, 0] else (np.nan, False)
        high, high_open = (
            _side(refit, x_hat, float(hi), thr, best) if todo[j, 1] else (np.nan, False)
        )
        out[problem.free_names[j]] = ProfileInterval(
            low=float(min(low, x_hat[j])) if todo[j, 0] else np.nan,
            high=float(max(high, x_hat[j])) if todo[j, 1] else np.nan,
            low_open=low_open,
            high_open=high_open,
            lower_sse=float(best[0]),
            nfev=refit.nfev,
        )
    return out
