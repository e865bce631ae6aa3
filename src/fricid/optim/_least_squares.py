"""Least-squares baselines: Levenberg-Marquardt (``lm``) and trust-region reflective (``trf``),
both from ``scipy.optimize.least_squares``, with multi-start.

Every residual vector scipy asks for (finite-difference Jacobian columns included) counts as
one evaluation. ``trf`` honours the bounds natively (in the unit box). ``lm`` has no bounds in
scipy, so it runs in an unconstrained variable ``z`` with ``u = (sin z + 1) / 2`` (the MINUIT
transformation lmfit uses), which keeps every candidate inside the box.

Starts: the first at ``x0`` (or the box centre), the others uniform in the box from ``seed``;
``n_starts`` of them, each given an equal share of the remaining budget.

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
from ._api import Budget, Solver, positive_option, register

__all__ = ["LeastSquaresLM", "LeastSquaresTRF"]


class _LeastSquares(Solver):
    uses_residuals = True
    default_evals = 20_000
    options: ClassVar[dict[str, Any]] = {"n_starts": 8, "ftol": 1e-12, "xtol": 1e-12, "gtol": 1e-12}
    scipy_method = ""

    def validate(self) -> None:
        positive_option(self.opts, "n_starts", self.name, integer=True)
        for tol in ("ftol", "xtol", "gtol"):
            positive_option(self.opts, tol, self.name)

    # the variable scipy moves, and the unit-box point it stands for
    def _to_u(self, z: np.ndarray) -> np.ndarray:
        return z

    def _from_u(self, u: np.ndarray) -> np.ndarray:
        return u

    def _starts(self) -> np.ndarray:
        obj = self.objective
        n = int(self.opts["n_starts"])
        first = obj.to_u(self.x0) if self.x0 is not None else np.full(obj.dim, 0.5)
        rest = self.rng.uniform(0.0, 1.0, size=(n - 1, obj.dim))
        return np.vstack([first, rest])

    def _residual_fun(self):
        obj = self.objective
        residuals = self.residuals

        def r(z: np.ndarray) -> np.ndarray:
            if obj.remaining < 1:
                raise Budget
            u = np.clip(self._to_u(z), 0.0, 1.0)
            res = np.asarray(residuals(obj.to_x(u)[None, :]), dtype=float)
            res = res.reshape(-1)
            obj.nfev += 1
            sse = float(res @ res)
            if not np.isfinite(sse):
                # scipy cannot step on non-finite residuals; a large finite one steers it away
                return np.full(res.shape, 1e50)
            obj.record(u, sse)
            return res

        return r

    def run(self) -> tuple[int, str]:
        obj = self.objective
        starts = self._starts()
        fun = self._residual_fun()
        messages = []
        self.converged = False
        for i, u0 in enumerate(starts):
            before = float(obj.best_f[0])
            share = max(obj.remaining // (len(starts) - i), 1)
            if obj.remaining < 1:
                break
            try:
                sol = least_squares(
                    fun,
                    self._from_u(u0),
                    method=self.scipy_method,
                    bounds=self._scipy_bounds(),
                    ftol=self.opts["ftol"],
                    xtol=self.opts["xtol"],
                    gtol=self.opts["gtol"],
                    max_nfev=share,
                    x_scale=1.0,
                )
                messages.append(sol.message)
                if float(sol.fun @ sol.fun) <= float(obj.best_f[0]):  # its end is the best
                    self.converged = sol.status > 0
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
        return self.nit, f"{self.nit} start(s); last: {messages[-1] if messages else 'none'}"

    def _scipy_bounds(self):
        return (-np.inf, np.inf)


@register
class LeastSquaresTRF(_LeastSquares):
    """Trust-region reflective least squares (scipy), bounded, multi-start."""

    name = "trf"
    summary = "trust-region reflective least squares (scipy), bounded, multi-start"
    scipy_method = "trf"

    def _scipy_bounds(self):
        return (0.0, 1.0)

    def _from_u(self, u: np.ndarray) -> np.ndarray:
        # trf wants strictly feasible starts
        return np.clip(u, 1e-9, 1.0 - 1e-9)


@register
class LeastSquaresLM(_LeastSquares):
    """Levenberg-Marquardt (scipy/MINPACK) in sin-transformed coordinates, multi-start."""

    name = "lm"
    summary = "Levenberg-Marquardt (scipy/MINPACK), bounds by sin transform, multi-start"
    scipy_method = "lm"

    def _to_u(self, z: np.ndarray) -> np.ndarray:
        return (np.sin(z) + 1.0) / 2.0

    def _from_u(self, u: np.ndarray) -> np.ndarray:
        return np.arcsin(np.clip(2.0 * u - 1.0, -1.0, 1.0))
