"""Certify that a least-squares fit converged, by a short local polish from its result.

An optimiser's own status says why it stopped (``fricid.optim.OptimizeResult.status``), not
whether it stopped at the optimum: the beetle family stops after its schedule, any method when
its budget is spent. :func:`certify` runs the default least-squares method (``lm``: bounded
trust region, one start at the result) with :data:`POLISH_EVALS_PER_PARAM` ``* (p + 1)``
evaluations. If that lowers the SSE by more than :data:`POLISH_RTOL` relative, the fit had not
converged, and the ratio says by how much; otherwise the result is a local optimum, whatever
the optimiser's status (certified). The fit keeps the optimiser's own point either way (a
paper's BAS run stays a BAS run); the polish only measures. Any problem of the problem
protocol (:class:`fricid.identify.problem.Problem`) is certified alike: the analytic fits'
and each stage of a trajectory identification.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...optim import OptimizeResult, minimize
from ..problem import Problem

__all__ = ["POLISH_EVALS_PER_PARAM", "POLISH_RTOL", "advice", "certify"]

#: Relative SSE decrease by the polish above which the fit counts as not converged.
POLISH_RTOL = 1e-6

#: The polish's budget is this many evaluations per free parameter, plus one set.
POLISH_EVALS_PER_PARAM = 50

#: Methods that search globally without a convergence test of their own.
_GLOBAL = ("bas", "vsbas", "ibas", "rwsavsbas", "ga", "de", "dual_annealing", "cmaes")


def advice(method: str) -> str:
    """What to do about an unconverged fit with ``method``."""
    if method in _GLOBAL:
        return (
            f"use --method bas+lm (a global phase polished by least squares) or --method lm, "
            f"or raise --max-evals for '{method}'"
        )
    return "raise --max-evals, or start elsewhere (--seed, x0)"


def certify(problem: Problem, result: OptimizeResult) -> dict[str, Any]:
    """The convergence block of a fit (stored in ``FittedModel.convergence``).

    Parameters
    ----------
    problem : Problem
        The problem that was minimised (loss ``sse``): an
        :class:`~fricid.identify.problem.IdentificationProblem`, or any other of the problem
        protocol (:class:`~fricid.identify.problem.Problem`: a trajectory route's stage).
    result : OptimizeResult
        The optimiser's result.

    Returns
    -------
    dict
        The verdict: ``converged`` (bool), ``polish_sse_ratio`` (polished SSE / fit SSE; 1
        when the polish found nothing lower), ``polish_nfev``, ``certified_by``
        (``"optimizer"``: its own test and the polish agree; ``"polish"``: the optimiser
        stopped otherwise, the polish finds nothing lower; ``""`` when not converged) and,
        when not converged, ``reason`` and ``advice``. The optimiser's own status, message,
        evaluations and budget are the model's optimiser record, not repeated here.
    """
    sse = float(result.fun)
    block: dict[str, Any] = {
        "converged": False,
        "polish_sse_ratio": float("nan"),
        "polish_nfev": 0,
        "certified_by": "",
    }
    if not np.isfinite(sse):
        block["reason"] = "no finite value of the objective was found"
        block["advice"] = "check the data and the bounds"
        return block
    p = problem.n_free
    polish = minimize(
        problem.evaluate,
        problem.bounds,
        method="lm",
        x0=np.clip(result.x, problem.bounds[:, 0], problem.bounds[:, 1]),
        options={"n_starts": 1},
        max_evals=POLISH_EVALS_PER_PARAM * (p + 1),
        residuals=problem.residuals,
        seed=0,
    )
    best = min(float(polish.fun), sse)
    floor = 1e-24 * max(float(problem.y @ problem.y), 1e-300)  # exact data: SSE ~ rounding
    block["polish_sse_ratio"] = best / sse if sse > floor else 1.0
    block["polish_nfev"] = int(polish.nfev)
    if sse - best <= POLISH_RTOL * sse + floor:
        block["converged"] = True
        block["certified_by"] = "optimizer" if result.success else "polish"
        return block
    method = str(result.method)
    max_evals = int(result.get("max_evals", result.nfev))
    block["reason"] = (
        f"method '{method}' ended after {result.nfev} of {max_evals} evaluations "
        f"(status {int(result.status)}: {result.message}) at SSE {sse:.4g}, but a local "
        f"least-squares polish from there reaches {best:.4g} ({sse / best:.3g}x lower)"
    )
    block["advice"] = advice(method)
    return block
