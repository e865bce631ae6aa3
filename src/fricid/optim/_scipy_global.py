"""Global baselines from scipy: differential evolution (``de``) and dual annealing.

Both run in the unit box with the objective wrapped so that every point scipy evaluates is
counted (one point, one evaluation) and the budget is exact: the wrapper raises at the first
point over ``max_evals``, whatever scipy's own limits say. Values scipy sees are finite (NaN
and inf become ``1e150``, so its statistics stay finite); the result keeps the true values.
scipy draws its random numbers from the run's own ``numpy.random.Generator`` (``rng=``).

References
----------
R. Storn, K. Price, "Differential Evolution", J. Global Optimization 11, 1997;
Y. Xiang et al., "Generalized simulated annealing", Physica A 233, 1997; and
``scipy.optimize.differential_evolution`` / ``dual_annealing``.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from scipy.optimize import differential_evolution, dual_annealing

from ..errors import ConfigError
from ._api import Solver, choice_option, positive_option, register

__all__ = ["DifferentialEvolution", "DualAnnealing"]

#: What scipy sees instead of NaN/inf.
WORST = 1e150


class _Passthrough(Exception):
    """Carries our ConfigError through scipy, which re-wraps ValueErrors raised by ``func``."""

    def __init__(self, error: ConfigError) -> None:
        super().__init__(str(error))
        self.error = error


def _guard(call):
    try:
        return call()
    except ConfigError as exc:
        raise _Passthrough(exc) from None


@register
class DifferentialEvolution(Solver):
    """scipy's differential evolution, vectorised (one objective call per generation).

    ``vectorized=True`` makes scipy pass the population as ``(d, S)``; we transpose it into
    our ``(S, d)`` batch. ``updating="deferred"`` (required by vectorised evaluation),
    ``polish=False`` (polish with ``bas+lm`` or ``lm`` instead) and by default ``tol=0``,
    ``atol=0``: it runs until the budget is spent (status 1). With ``tol`` or ``atol`` above 0
    scipy's own criterion (population spread ``std(f) <= atol + tol |mean(f)|``; scipy's
    default ``tol`` is 0.01) may stop it first: then it has converged (status 0).

    Options
    -------
    popsize : population = popsize * d (15).  mutation : (0.5, 1).  recombination : 0.7.
    strategy : "best1bin".  init : "latinhypercube".  tol, atol : 0, 0.
    """

    name = "de"
    summary = "differential evolution (scipy), vectorised, runs to the budget"
    default_evals = 10_000
    options: ClassVar[dict[str, Any]] = {
        "popsize": 15,
        "mutation": (0.5, 1.0),
        "recombination": 0.7,
        "strategy": "best1bin",
        "init": "latinhypercube",
        "tol": 0.0,
        "atol": 0.0,
    }

    def validate(self) -> None:
        positive_option(self.opts, "popsize", self.name, integer=True)
        positive_option(self.opts, "tol", self.name, allow_zero=True)
        positive_option(self.opts, "atol", self.name, allow_zero=True)
        positive_option(self.opts, "recombination", self.name)
        choice_option(self.opts, "init", self.name, ("latinhypercube", "sobol", "halton", "random"))

    def run(self) -> tuple[int, str]:
        obj = self.objective
        d = obj.dim

        def f(U: np.ndarray) -> np.ndarray:
            v = _guard(lambda: obj.call1(np.asarray(U, dtype=float).T))
            return np.minimum(v, WORST)

        def count(intermediate_result) -> None:  # scipy passes this name
            self.nit += 1
            obj.notify(self.nit)

        try:
            res = self._de(f, count, d)
        except _Passthrough as exc:
            raise exc.error from None
        self.converged = bool(res.success)
        return self.nit, str(res.message)

    def _de(self, f, count, d):
        obj = self.objective
        pop = int(self.opts["popsize"]) * d
        maxiter = max(1, -(-obj.max_evals // pop))
        return differential_evolution(
            f,
            [(0.0, 1.0)] * d,
            strategy=self.opts["strategy"],
            maxiter=maxiter,
            popsize=int(self.opts["popsize"]),
            tol=float(self.opts["tol"]),
            atol=float(self.opts["atol"]),
            mutation=self.opts["mutation"],
            recombination=float(self.opts["recombination"]),
            rng=self.rng,
            callback=count,
            polish=False,
            init=self.opts["init"],
            updating="deferred",
            vectorized=True,
            x0=None if self.x0 is None else obj.to_u(self.x0),
        )


@register
class DualAnnealing(Solver):
    """scipy's dual annealing (generalised simulated annealing with local search).

    scipy evaluates one point per call; its local search (L-BFGS-B with finite-difference
    gradients) is counted too. ``maxfun`` is set to the budget (scipy treats it as a soft
    limit; our wrapper makes it exact). Dual annealing has no convergence criterion (scipy's
    ``success`` only says its iteration limit, here 1e9, was reached): it runs to the budget
    and never reports "converged".

    Options
    -------
    initial_temp : 5230.  restart_temp_ratio : 2e-5.  visit : 2.62.  accept : -5.
    no_local_search : False.
    """

    name = "dual_annealing"
    summary = "dual annealing (scipy): generalised simulated annealing + local search"
    default_evals = 10_000
    options: ClassVar[dict[str, Any]] = {
        "initial_temp": 5230.0,
        "restart_temp_ratio": 2e-5,
        "visit": 2.62,
        "accept": -5.0,
        "no_local_search": False,
    }

    def validate(self) -> None:
        positive_option(self.opts, "initial_temp", self.name)
        positive_option(self.opts, "restart_temp_ratio", self.name, open_unit=True)
        choice_option(self.opts, "no_local_search", self.name, (True, False))

    def run(self) -> tuple[int, str]:
        obj = self.objective
        d = obj.dim

        def f(u: np.ndarray) -> float:
            v = _guard(lambda: obj.call1(np.asarray(u, dtype=float)[None, :])[0])
            return float(min(v, WORST))

        def count(_x, _f, _context) -> None:
            self.nit += 1
            obj.notify(self.nit)

        try:
            res = self._da(f, count, d)
        except _Passthrough as exc:
            raise exc.error from None
        return self.nit, " ".join(str(m) for m in np.atleast_1d(res.message))

    def _da(self, f, count, d):
        obj = self.objective
        return dual_annealing(
            f,
            [(0.0, 1.0)] * d,
            maxiter=10**9,
            initial_temp=float(self.opts["initial_temp"]),
            restart_temp_ratio=float(self.opts["restart_temp_ratio"]),
            visit=float(self.opts["visit"]),
            accept=float(self.opts["accept"]),
            maxfun=obj.max_evals,
            rng=self.rng,
            no_local_search=self.opts["no_local_search"],
            callback=count,
            x0=None if self.x0 is None else obj.to_u(self.x0),
        )
