"""Bounded least squares with multi-start: ``lm`` (the default least-squares method) and
``trf``, both scipy's trust-region reflective solver (``scipy.optimize.least_squares(...,
method="trf")``) in the unit box, and ``lm_minpack``, MINPACK's Levenberg-Marquardt in
sin-transformed coordinates (kept for comparison only).

What ``lm`` runs
    ``lm`` is the name fricid has always used for "the default least-squares method"; since
    issue 11 (defect 6) it runs scipy's ``trf`` with the bounds handled natively in the unit
    box and a finite-difference Jacobian computed as **one batched call** of the residuals
    (forward differences with step :data:`FD_STEP` in the unit box, stepping inward on the
    upper face; ``d`` evaluations per Jacobian), with ``x_scale="jac"``. ``trf`` is the same
    solver with scipy's own (one residual vector per call) Jacobian and ``x_scale=1``.
    Trust-region reflective is a Levenberg-Marquardt-type method (a Gauss-Newton step inside
    a trust region, Branch, Coleman and Li 1999) that honours bounds.

Why not MINPACK with a sin transform (``lm_minpack``)
    MINPACK moves an unconstrained ``z`` with ``u = (sin z + 1) / 2``. At the middle of the box
    ``z`` is 0 up to rounding (about 2e-16), and MINPACK's forward-difference step
    ``sqrt(eps) |z|`` and first trust radius ``100 ||z||`` fall back to absolute values only at
    *exactly* zero: the Jacobian column vanishes, the first step is 1e-14, and the run reports
    "ftol satisfied" after a dozen evaluations at 1e4-1e5 times the optimum SSE. At a bound
    ``cos z = 0``, so the column vanishes there too, and near it progress crawls (on ``vlt``
    every start spent its whole share of the budget). Measured over 16 starts per problem
    (lower, upper and middle of the box, corners, random): the old ``lm`` reached the optimum
    from 8/16 (real lead screw), 14/16 (paper2 Stribeck) and 10/16 (paper1 vlt) starts;
    bounded ``trf`` from 14, 15 and 15, in a tenth of the evaluations on ``vlt``.

Starts: the first at ``x0`` (or the box centre), the others uniform in the box from ``seed``;
up to ``n_starts`` of them, each given an equal share of the remaining budget. Starts on a bound
are moved :data:`INSIDE` into the box (``trf`` needs strictly feasible points). With option
``restart="doubtful"`` (the default of ``lm``; issue 14) the other starts run only when the
first one is doubtful: it began on a face of the box (where trust-region reflective is
weakest: measured on the lead screw's ``stribeck_asym``, a start at a corner ends in a local
optimum with 10x the optimal SSE, yet within the measurement scatter), scipy did not report
convergence, a parameter ends on (within :data:`AT_BOUND` of) a bound, or its SSE exceeds
option ``restart_above`` (``fit`` sets it from the measurement scatter: the residual far above
the noise). Measured on the paper2
Stribeck problem, the first start reached the optimum 160 times in 160 (issue 14), so the
seven others were 8x the cost for nothing. ``restart="always"`` (``trf``, ``lm_minpack``)
runs them all. Restarted, ``lm`` stops once ``patience`` (3) starts in a row found nothing
better than the best so far (lowered its SSE by under :data:`PATIENCE_RTOL`): a family that
misses the measurement scatter by its shape, not by a local optimum, otherwise spent seven more
starts reaching the same point (measured: ``fricid.identify.select``'s screening of 18 families
on the 660 per-direction samples of paper1, ``benchmarks/bench_speed.py``).

Every residual vector evaluated (each row of a batched Jacobian included) counts as one
evaluation.

Convergence: a run has converged (status 0) when the start that found the best point ended
by scipy's own criterion (``ftol``, ``xtol`` or ``gtol``; scipy's ``status > 0``), not by its
share of the budget; a later start that runs out of the budget then ends the run without
changing that (the message says so). Otherwise the status is that of the budget.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from scipy.optimize import least_squares

from ..errors import ConfigError
from ._api import Budget, Solver, choice_option, positive_option, register
from ._threads import single_blas_thread

__all__ = ["FD_STEP", "INSIDE", "LeastSquaresLM", "LeastSquaresMINPACK", "LeastSquaresTRF"]

#: Forward-difference step of the batched Jacobian, in the unit box (never relative to a
#: coordinate that can be 0).
FD_STEP = 1e-7

#: How far a start on a face of the unit box is moved inside.
INSIDE = 1e-9

#: A first start whose result lies within this of a face of the unit box is doubtful.
AT_BOUND = 1e-6

#: A start "finds something better" when it lowers the best SSE by more than this fraction
#: (option ``patience``).
PATIENCE_RTOL = 1e-9


class _LeastSquares(Solver):
    uses_residuals = True
    default_evals = 20_000
    options: ClassVar[dict[str, Any]] = {
        "n_starts": 8,
        "ftol": 1e-12,
        "xtol": 1e-12,
        "gtol": 1e-12,
        "restart": "always",
        "restart_above": None,
        "patience": None,
    }
    scipy_method = "trf"
    #: scipy's ``x_scale``
    x_scale: ClassVar[Any] = 1.0
    #: whether the Jacobian is one batched call (else scipy's "2-point", one call per column)
    batched_jacobian = False

    def validate(self) -> None:
        positive_option(self.opts, "n_starts", self.name, integer=True)
        for tol in ("ftol", "xtol", "gtol"):
            positive_option(self.opts, tol, self.name)
        choice_option(self.opts, "restart", self.name, ("doubtful", "always"))
        if self.opts["restart_above"] is not None:
            positive_option(self.opts, "restart_above", self.name, allow_zero=True)
        if self.opts["patience"] is not None:
            positive_option(self.opts, "patience", self.name, integer=True)

    def doubtful(self, u0: np.ndarray, sol: Any) -> str:
        """Why the first start (from ``u0``) calls for the other starts ("" when it does not)."""
        if np.any(np.minimum(u0, 1.0 - u0) <= AT_BOUND):
            return "the first start began on a bound"
        if sol.status <= 0:
            return "the first start did not converge"
        u = self.objective.best_u[0]
        if np.any(np.minimum(u, 1.0 - u) <= AT_BOUND):
            return "the first start ended on a bound"
        above = self.opts["restart_above"]
        if above is not None and float(self.objective.best_f[0]) > float(above):
            return f"its SSE is above {float(above):.3g} (restart_above)"
        return ""

    # the variable scipy moves, and the unit-box point it stands for (bounded: the same)
    def _to_u(self, z: np.ndarray) -> np.ndarray:
        return z

    def _from_u(self, u: np.ndarray) -> np.ndarray:
        return np.clip(u, INSIDE, 1.0 - INSIDE)

    def _scipy_bounds(self):
        return (0.0, 1.0)

    def _starts(self) -> np.ndarray:
        obj = self.objective
        n = int(self.opts["n_starts"])
        first = obj.to_u(self.x0) if self.x0 is not None else np.full(obj.dim, 0.5)
        rest = self.rng.uniform(0.0, 1.0, size=(n - 1, obj.dim))
        return np.vstack([first, rest])

    def _residuals_at(self, U: np.ndarray) -> np.ndarray:
        """Residuals ``(k, n)`` of unit-box points ``U (k, d)``, counted and offered as best."""
        obj = self.objective
        k = U.shape[0]
        if obj.remaining < k:
            raise Budget
        R = np.asarray(self.residuals(obj.lower + U * obj.span), dtype=float).reshape(k, -1)
        obj.nfev += k
        sse = np.einsum("kn,kn->k", R, R)
        if not np.isfinite(sse).all():
            sse[~np.isfinite(sse)] = np.inf
        # the Objective's offer for one run, without its generality (hot: once per call)
        i = int(np.argmin(sse))
        if sse[i] < obj.best_f[0]:
            obj.best_f[0] = sse[i]
            obj.best_u[0] = U[i]
            obj.snapshot()
        return R

    def _residual_fun(self):
        self._last: tuple[np.ndarray, np.ndarray] | None = None

        def r(z: np.ndarray) -> np.ndarray:
            u = np.minimum(np.maximum(self._to_u(z), 0.0), 1.0)
            res = self._residuals_at(u[None, :])[0]
            self._last = (u, res)
            if not np.isfinite(res @ res):
                # scipy cannot step on non-finite residuals; a large finite one steers it away
                return np.full(res.shape, 1e50)
            return res

        return r

    def _jacobian_fun(self):
        """Forward differences in the unit box, all ``d`` columns in one batched call (the
        residual at ``u`` itself is the one scipy has just asked for, when it has)."""

        def jac(u: np.ndarray) -> np.ndarray:
            h = np.where(u + FD_STEP <= 1.0, FD_STEP, -FD_STEP)
            steps = u + np.diag(h)
            last = self._last
            if last is not None and last[0].shape == u.shape and (last[0] == u).all():
                r0, R = last[1], self._residuals_at(steps)
            else:
                both = self._residuals_at(np.vstack([u[None, :], steps]))
                r0, R = both[0], both[1:]
            J = ((R - r0) / h[:, None]).T
            return np.nan_to_num(J, nan=0.0, posinf=0.0, neginf=0.0)

        return jac

    @single_blas_thread
    def run(self) -> tuple[int, str]:
        obj = self.objective
        starts = self._starts()
        fun = self._residual_fun()
        jac = self._jacobian_fun() if self.batched_jacobian else "2-point"
        messages = []
        restarted = ""
        best_message = "none"
        self.converged = False
        patience, idle = self.opts["patience"], 0
        for i, u0 in enumerate(starts):
            if patience is not None and restarted and idle >= patience:
                return self.nit, (
                    f"{self.nit} start(s){restarted}; the last {idle} found nothing better "
                    f"(patience {patience}); best: {best_message}"
                )
            before = float(obj.best_f[0])
            share = max(obj.remaining // (len(starts) - i), 1)
            if obj.remaining < 1:
                break
            try:
                sol = least_squares(
                    fun,
                    self._from_u(u0),
                    jac=jac,
                    method=self.scipy_method,
                    bounds=self._scipy_bounds(),
                    ftol=self.opts["ftol"],
                    xtol=self.opts["xtol"],
                    gtol=self.opts["gtol"],
                    max_nfev=share,
                    x_scale=self.x_scale,
                )
                messages.append(sol.message)
                if float(obj.best_f[0]) < before:  # this start found the best point
                    self.converged = sol.status > 0
                    best_message = sol.message
                gain = before - float(obj.best_f[0])
                # the first start always counts as finding the best (it is the first)
                idle = 0 if i == 0 or gain > PATIENCE_RTOL * abs(before) else idle + 1
                if i == 0 and len(starts) > 1 and self.opts["restart"] == "doubtful":
                    why = self.doubtful(u0, sol)
                    if not why:
                        self.nit = 1
                        obj.notify(self.nit)
                        return 1, f"1 start, not doubtful (no restart): {sol.message}"
                    restarted = f" (restarted: {why})"
            except Budget:
                self.nit = i + 1
                if float(obj.best_f[0]) < before:  # the best is this unfinished start's
                    self.converged = False
                if obj.stopped_by_callback or not self.converged:
                    raise
                return self.nit, (
                    f"the best start converged; the budget of {obj.max_evals} was spent in "
                    f"start {i + 1} of {len(starts)}"
                )
            except ValueError as exc:  # scipy's own input checks (e.g. fewer residuals than d)
                raise ConfigError(f"method '{self.name}': {exc}") from None
            self.nit = i + 1
            obj.notify(self.nit)
        last = messages[-1] if messages else "none"
        return self.nit, f"{self.nit} start(s){restarted}; last: {last}"


@register
class LeastSquaresTRF(_LeastSquares):
    """Trust-region reflective least squares (scipy), bounded, multi-start, scipy's own
    finite-difference Jacobian."""

    name = "trf"
    summary = "trust-region reflective least squares (scipy), bounded, multi-start"


@register
class LeastSquaresLM(_LeastSquares):
    """The default least-squares method: scipy's bounded trust-region reflective solver (a
    Levenberg-Marquardt-type method) in the unit box, batched Jacobian, ``x_scale="jac"``,
    multi-start (see the module docstring for why it no longer runs MINPACK)."""

    name = "lm"
    summary = (
        "default least squares: bounded Levenberg-Marquardt-type trust region (scipy trf, "
        "batched Jacobian), multi-start"
    )
    x_scale = "jac"
    batched_jacobian = True
    options: ClassVar[dict[str, Any]] = {
        **_LeastSquares.options,
        "restart": "doubtful",
        "patience": 3,
    }


@register
class LeastSquaresMINPACK(_LeastSquares):
    """Levenberg-Marquardt (scipy/MINPACK) in sin-transformed coordinates, multi-start: what
    ``lm`` ran before issue 11; it stalls from the middle of the box and on its bounds (module
    docstring). Kept for comparison."""

    name = "lm_minpack"
    summary = "MINPACK Levenberg-Marquardt, bounds by sin transform (stalls at mid-box; legacy)"
    scipy_method = "lm"

    def _scipy_bounds(self):
        return (-np.inf, np.inf)

    def _to_u(self, z: np.ndarray) -> np.ndarray:
        return (np.sin(z) + 1.0) / 2.0

    def _from_u(self, u: np.ndarray) -> np.ndarray:
        return np.arcsin(np.clip(2.0 * u - 1.0, -1.0, 1.0))
