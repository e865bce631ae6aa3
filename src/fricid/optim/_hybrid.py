"""``bas+lm``: a beetle global phase polished by least squares (``lm``).

What a practitioner should use on a least-squares problem such as the Stribeck fit: a cheap
global phase finds the basin of the optimum, and the default least-squares method ``lm``
(:mod:`~fricid.optim._least_squares`: scipy's bounded trust-region reflective solver, a
Levenberg-Marquardt-type method, fast local convergence on a smooth least-squares problem)
finishes it in a few dozen evaluations.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from ..errors import ConfigError
from ._api import METHODS, Budget, Solver, positive_option, register
from ._least_squares import LeastSquaresLM
from ._threads import single_blas_thread

__all__ = ["BeetleLM"]

#: The methods the global phase may use.
GLOBAL = ("bas", "vsbas", "ibas", "rwsavsbas")


@register
class BeetleLM(Solver):
    """A BAS-family global phase (``global_method``, default ``vsbas``) with its own budget
    ``global_evals``, then ``lm`` (bounded trust region, :mod:`~fricid.optim._least_squares`)
    from the best point found, using what is left of ``max_evals`` (default 3000 in all).

    The global phase starts at ``x0`` or at a uniform point of the box (the run's first
    random draw, so ``lm`` alone with ``x0`` at that point starts where this does). All
    evaluations, the Jacobian's finite differences included, count against one budget; the
    result is the best point evaluated by either phase. The run has converged (status 0) when
    the ``lm`` polish did (see :mod:`~fricid.optim._least_squares`).

    Options
    -------
    global_method : one of bas, vsbas, ibas, rwsavsbas ("vsbas").
    global_evals : evaluations of the global phase (1500).
    global_options : options of the global phase (default: vsbas with ``n_iter = 500``).
    n_polish : lm starts: the global best, then uniform points (1).
    """

    name = "bas+lm"
    summary = "BAS-family global phase (default vsbas) polished by least squares (lm)"
    uses_residuals = True
    default_evals = 3000
    options: ClassVar[dict[str, Any]] = {
        "global_method": "vsbas",
        "global_evals": 1500,
        "global_options": None,
        "n_polish": 1,
    }

    def validate(self) -> None:
        o = self.opts
        if o["global_method"] not in GLOBAL:
            raise ConfigError(
                f"option 'global_method' of method 'bas+lm' must be one of {', '.join(GLOBAL)}; "
                f"got {o['global_method']!r}"
            )
        positive_option(o, "global_evals", self.name, integer=True)
        positive_option(o, "n_polish", self.name, integer=True)
        gopts = o["global_options"]
        if gopts is None:
            gopts = {"n_iter": 500} if o["global_method"] != "rwsavsbas" else {}
        if not isinstance(gopts, dict):
            raise ConfigError(
                f"option 'global_options' of method 'bas+lm' must be a dict; got {gopts!r}"
            )
        self._global = METHODS[o["global_method"]](dict(gopts), dim=self.dim, x0=self.x0)
        self._polish = LeastSquaresLM(
            {"n_starts": int(o["n_polish"])}, dim=self.dim, x0=None, residuals=self.residuals
        )

    @single_blas_thread
    def run(self) -> tuple[int, str]:
        obj = self.objective
        total = obj.max_evals
        obj.max_evals = min(total, int(self.opts["global_evals"]))
        try:
            self._global.bind(obj, self.rngs).run()
        except Budget:
            if obj.stopped_by_callback:
                raise
        finally:
            obj.max_evals = total
        self.nit = self._global.nit
        if not np.isfinite(obj.best_f[0]):
            return self.nit, "global phase found no finite value; no polish"
        if obj.remaining < 1:
            raise Budget
        polish = self._polish.bind(obj, self.rngs)
        polish.x0 = obj.to_x(obj.best_u[0])
        _, message = polish.run()
        self.converged = polish.converged
        self.nit += polish.nit
        return self.nit, f"global phase {self.opts['global_method']} then lm: {message}"
