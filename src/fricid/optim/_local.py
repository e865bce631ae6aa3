"""``lbfgsb``: a cheap bounded local method from a scalar objective alone, the default of
:func:`fricid.optim.minimize` when no residuals are given (as ``scipy.optimize.minimize``
defaults to a local quasi-Newton method).

scipy's L-BFGS-B (Byrd, Lu, Nocedal and Zhu 1995; ``scipy.optimize.minimize(...,
method="L-BFGS-B")``) in the unit box, from ``x0`` or the box centre. Its gradient is a
forward difference with step :data:`FD_STEP` in the unit box (inward on the upper face),
the point and its ``d`` neighbours in **one batched call** of the objective: ``d + 1``
evaluations per step, every one counted. Values scipy sees are finite (NaN and inf become
:data:`WORST`, and a difference involving one 0); a local method has no way out of a region
where the objective is not defined, so from such a start it stops at once (and
:func:`~fricid.optim.minimize` raises: no finite value).

Converged (status 0) when scipy reports success: the relative reduction of the objective
fell below ``ftol`` or the projected gradient below ``gtol`` (scipy's criteria and
defaults). A local method: it finds the minimum of the basin it starts in; the beetle family,
``de``, ``dual_annealing`` and ``cmaes`` search the whole box, and ``bas+lm`` polishes a
global phase.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from scipy.optimize import minimize as scipy_minimize

from ._api import Solver, positive_option, register

__all__ = ["FD_STEP", "LBFGSB", "WORST"]

#: Forward-difference step of the gradient, in the unit box (scipy's default ``eps``).
FD_STEP = 1e-8

#: What scipy sees instead of NaN/inf.
WORST = 1e150


@register
class LBFGSB(Solver):
    """Bounded quasi-Newton (scipy's L-BFGS-B) from ``x0`` or the box centre, with a batched
    finite-difference gradient (module notes).

    Options
    -------
    ftol : 2.22e-9 (scipy's).  gtol : 1e-5 (scipy's; in the unit box).  maxcor : 10.
    """

    name = "lbfgsb"
    summary = (
        "bounded quasi-Newton (scipy L-BFGS-B) from x0 or the box centre, batched "
        "finite-difference gradient; local, cheap (the default without residuals)"
    )
    default_evals = 10_000
    options: ClassVar[dict[str, Any]] = {
        "ftol": 2.220446049250313e-09,
        "gtol": 1e-05,
        "maxcor": 10,
    }

    def validate(self) -> None:
        positive_option(self.opts, "ftol", self.name, allow_zero=True)
        positive_option(self.opts, "gtol", self.name, allow_zero=True)
        positive_option(self.opts, "maxcor", self.name, integer=True)

    def run(self) -> tuple[int, str]:
        obj = self.objective
        d = obj.dim

        def fun_and_grad(u: np.ndarray) -> tuple[float, np.ndarray]:
            h = np.where(u + FD_STEP <= 1.0, FD_STEP, -FD_STEP)
            f = obj.call1(np.vstack([u[None, :], u + np.diag(h)]))
            f = np.minimum(f, WORST)
            g = (f[1:] - f[0]) / h
            return float(f[0]), np.nan_to_num(g, nan=0.0, posinf=0.0, neginf=0.0)

        def count(xk) -> None:  # scipy passes the iterate
            self.nit += 1
            obj.notify(self.nit)

        u0 = obj.to_u(self.x0) if self.x0 is not None else np.full(d, 0.5)
        res = scipy_minimize(
            fun_and_grad,
            u0,
            jac=True,
            method="L-BFGS-B",
            bounds=[(0.0, 1.0)] * d,
            callback=count,
            options={
                "ftol": float(self.opts["ftol"]),
                "gtol": float(self.opts["gtol"]),
                "maxcor": int(self.opts["maxcor"]),
                "maxfun": 10**9,
                "maxiter": 10**9,
            },
        )
        self.converged = bool(res.success)
        return self.nit, str(res.message)
