"""CMA-ES baseline from the ``cma`` package, driven by ask/tell.

References
----------
N. Hansen, "The CMA Evolution Strategy: A Tutorial", arXiv:1604.00772; the ``cma`` package
(pycma) by N. Hansen et al.
"""

from __future__ import annotations

import warnings
from typing import Any, ClassVar

import numpy as np

from ._api import Solver, choice_option, positive_option, register
from ._scipy_global import WORST

__all__ = ["CMAES"]

#: cma's termination criteria that mean convergence (the others are limits).
_CONVERGED_STOPS = {"tolfun", "tolx", "tolfunhist"}


@register
class CMAES(Solver):
    """CMA-ES (``cma.CMAEvolutionStrategy``) in the unit box, one objective call per generation.

    Seeding without global state: cma normally seeds ``numpy.random`` (``np.random.seed``); we
    give it the option ``randn`` drawing from the run's own Generator and ``seed=nan``, so the
    global random state is never touched and the same seed gives the same run. Box handling is
    cma's ``BoundTransform`` onto [0, 1] (candidates never leave the box). When cma's own
    termination criteria fire before the budget is spent, it restarts from a new uniform
    point (``restarts=True``), so budgets compare fairly with the other methods. cma's
    warnings are silenced; NaN/inf values reach it as ``1e150``. With restarts it runs to the
    budget (status 1); without, it has converged (status 0) when cma stopped on ``tolfun``,
    ``tolx`` or ``tolfunhist``.

    Options
    -------
    sigma0 : initial step in unit-box units (0.3).  popsize : None (cma's 4 + 3 ln d).
    restarts : True.
    """

    name = "cmaes"
    summary = "CMA-ES (the cma package), ask/tell, seeded without global state, restarts"
    default_evals = 10_000
    options: ClassVar[dict[str, Any]] = {"sigma0": 0.3, "popsize": None, "restarts": True}

    def validate(self) -> None:
        positive_option(self.opts, "sigma0", self.name)
        if self.opts["popsize"] is not None:
            positive_option(self.opts, "popsize", self.name, integer=True)
        choice_option(self.opts, "restarts", self.name, (True, False))

    def run(self) -> tuple[int, str]:
        import cma

        obj = self.objective
        rng = self.rng

        def randn(*shape: int) -> np.ndarray:
            return rng.standard_normal(shape)

        cma_opts = {
            "bounds": [0.0, 1.0],
            "seed": np.nan,
            "randn": randn,
            "verbose": -9,
            "verb_disp": 0,
            "verb_log": 0,
            "maxfevals": np.inf,
        }
        if self.opts["popsize"] is not None:
            cma_opts["popsize"] = int(self.opts["popsize"])
        x0 = obj.to_u(self.x0) if self.x0 is not None else rng.random(obj.dim)
        stops: list[str] = []
        while True:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                es = cma.CMAEvolutionStrategy(x0, float(self.opts["sigma0"]), cma_opts)
                while not es.stop():
                    X = np.asarray(es.ask(), dtype=float)
                    f = obj.call1(X)
                    es.tell(list(X), list(np.minimum(f, WORST)))
                    self.nit += 1
                    obj.notify(self.nit)
            stops.append(", ".join(es.stop()))
            if not self.opts["restarts"]:
                self.converged = bool(_CONVERGED_STOPS & set(es.stop()))
                break
            x0 = rng.random(obj.dim)
        return self.nit, f"cma stopped: {stops[-1]}"
