"""Certify that a least-squares fit converged, by a short local polish from its result.

An optimiser's own status says why it stopped (``fricid.optim.OptimizeResult.status``), not
whether it stopped at the optimum: the beetle family stops after its schedule, any method when
its budget is spent. :func:`certify` runs the default least-squares method (``lm``: bounded
trust region, one start at the result) with :data:`POLISH_EVALS_PER_PARAM` ``* (p + 1)``
evaluations. The fit had converged when what the polish gained is below what the scatter of
the data can resolve:

``SSE_fit - SSE_polished <= max(POLISH_RTOL SSE_fit, RESOLVE_SE^2 s^2)``, with
``s^2 = SSE_polished / (n - p)`` the residual variance.

Near the optimum ``SSE(theta) - SSE_min = (theta - theta*)^T J^T J (theta - theta*)`` and the
parameters' covariance is ``s^2 (J^T J)^-1``, so ``(SSE_fit - SSE_min) / s^2`` is the squared
distance of the fit's parameters from the optimum in standard errors, along the worst
direction: a gain below ``RESOLVE_SE^2 s^2`` (:data:`RESOLVE_SE` = 0.1 standard errors) moves
no parameter, nor any combination of them, by more than a tenth of its standard error, far
below what the data resolve. (An SSE gain of 0.011 % on 60 samples is 0.007 ``s^2``:
converged.) Otherwise the fit had not converged, and the block says by how much (relative
SSE gain and standard errors); either way the result is a local optimum whatever the
optimiser's status (certified) or it is not. The fit keeps the optimiser's own point
either way (a paper's BAS run stays a BAS run); the polish only measures, but in
:func:`settle`, where a trajectory stage's least-squares search on its default budget carries
on from it. Any problem of the problem protocol (:class:`fricid.identify.problem.Problem`) is
certified alike: the analytic fits' and each stage of a trajectory identification.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ...optim import METHODS, OptimizeResult, minimize
from ..problem import Problem

__all__ = [
    "POLISH_EVALS_PER_PARAM",
    "POLISH_RTOL",
    "RESOLVE_SE",
    "advice",
    "certify",
    "certify_polish",
    "noise_ftol",
    "settle",
]

#: Rounds of :func:`settle`: a search carried on from the certificate's polish while that
#: polish still finds an SSE lower by more than the data resolve. Three left 3 of 108 LuGre
#: fits of ``benchmarks/bench_lugre.py``'s report seeds uncertified, crawling along a Stribeck
#: rise the log does not resolve (open-loop torque steps at 200 Hz, 2^17 counts/rev: 0.23
#: standard errors short after 1,755 evaluations); ten certify them, 1.6 s more on one of 11 s.
SETTLE_ROUNDS = 10

#: Relative SSE decrease by the polish at or below which the fit counts as converged (exact
#: data, where the residual variance is 0).
POLISH_RTOL = 1e-6

#: A polish that moves the parameters by less than this many standard errors (along the worst
#: direction: module notes) leaves the fit converged.
RESOLVE_SE = 0.1

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


def noise_ftol(problem: Problem, share: float = 1.0) -> float:
    """``lm``'s relative ``ftol`` at which a step's SSE gain is ``share`` times what the
    certificate resolves (``RESOLVE_SE^2 s^2``, ``s^2 = SSE / (n - p)``): ``share *
    RESOLVE_SE^2 / (n - p)``. A least-squares search stopped there is within the data's
    resolution of its optimum (near it, a Gauss-Newton step gains the squared distance in
    standard errors times ``s^2``): used where each evaluation is a simulation."""
    dof = max(_n_obs(problem) - problem.n_free, 1)
    return share * RESOLVE_SE**2 / dof


def certify(
    problem: Problem, result: OptimizeResult, *, noise_tolerance: bool = False
) -> dict[str, Any]:
    """The convergence block of a fit (stored in ``FittedModel.convergence``).

    Parameters
    ----------
    problem : Problem
        The problem that was minimised (loss ``sse``): an
        :class:`~fricid.identify.problem.IdentificationProblem`, or any other of the problem
        protocol (:class:`~fricid.identify.problem.Problem`: a trajectory route's stage).
    result : OptimizeResult
        The optimiser's result.
    noise_tolerance : bool, default False
        The polish stops once a step gains under a tenth of what the verdict resolves
        (:func:`noise_ftol`, ``share=0.1``) instead of at ``lm``'s own tolerances: for
        problems whose evaluations are simulations (a trajectory's output-error stage).

    Returns
    -------
    dict
        The verdict: ``converged`` (bool), ``polish_sse_ratio`` (polished SSE / fit SSE; 1
        when the polish found nothing lower), ``polish_nfev``, ``certified_by``
        (``"optimizer"``: its own test and the polish agree; ``"polish"``: the optimiser
        stopped otherwise, the polish finds nothing the data can resolve lower; ``""`` when
        not converged) and, when not converged, ``reason`` and ``advice``. The optimiser's own
        status, message, evaluations and budget are the model's optimiser record, not repeated
        here.
    """
    return certify_polish(problem, result, noise_tolerance=noise_tolerance)[0]


def certify_polish(
    problem: Problem, result: OptimizeResult, *, noise_tolerance: bool = False
) -> tuple[dict[str, Any], OptimizeResult | None]:
    """:func:`certify`'s block and the polish's own result (None when nothing was polished:
    no finite objective), for a search that carries on from the polish (:func:`settle`)."""
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
        return block, None
    p = problem.n_free
    polish = minimize(
        problem.evaluate,
        problem.bounds,
        method="lm",
        x0=np.clip(result.x, problem.bounds[:, 0], problem.bounds[:, 1]),
        options={"n_starts": 1, **({"ftol": noise_ftol(problem, 0.1)} if noise_tolerance else {})},
        max_evals=POLISH_EVALS_PER_PARAM * (p + 1),
        residuals=problem.residuals,
        seed=0,
    )
    best = min(float(polish.fun), sse)
    floor = 1e-24 * max(float(problem.y @ problem.y), 1e-300)  # exact data: SSE ~ rounding
    block["polish_sse_ratio"] = best / sse if sse > floor else 1.0
    block["polish_nfev"] = int(polish.nfev)
    dof = max(_n_obs(problem) - p, 1)
    variance = best / dof  # the residual variance, in the objective's units per sample
    moved = float(np.sqrt(max(sse - best, 0.0) / variance)) if variance > 0 else float("inf")
    if sse - best <= max(POLISH_RTOL * sse, RESOLVE_SE**2 * variance) + floor:
        block["converged"] = True
        block["certified_by"] = "optimizer" if result.success else "polish"
        return block, polish
    method = str(result.method)
    max_evals = int(result.get("max_evals", result.nfev))
    gain = 100.0 * (sse - best) / sse
    spent = (
        f"{result.nfev} of {max_evals} evaluations"
        if result.nfev <= max_evals  # else carried on past its budget by :func:`settle`
        else f"{result.nfev} evaluations (budget {max_evals}, carried on while a polish gained)"
    )
    block["reason"] = (
        f"method '{method}' ended after {spent} "
        f"(status {int(result.status)}: {result.message}) at SSE {sse:.6g}, but a local "
        f"least-squares polish from there reaches {best:.6g} ({gain:.3g} % lower: the "
        f"parameters move by {_se_text(moved)}, more than the {RESOLVE_SE:g} below which the data "
        "cannot tell the difference)"
    )
    block["advice"] = advice(method)
    return block, polish


def settle(
    problem: Problem,
    result: OptimizeResult,
    method: str,
    max_evals: int | None,
    rounds: int = SETTLE_ROUNDS,
) -> OptimizeResult:
    """``result`` carried on by the convergence certificate's polish while it finds an SSE
    lower by more than the data resolve (at most ``rounds`` polishes); only for a
    least-squares ``method`` on its default budget (``max_evals`` None): a budget or a method
    the user chose is theirs (a BAS run stays a BAS run, certified or not).

    A search whose every evaluation is a simulation (a trajectory's filtered and output-error
    stages) stops once a step gains under a tenth of what the certificate resolves
    (:data:`fricid.identify.dynamic._routes.SEARCH_SHARE`); in a long, flat valley it stops
    short (``benchmarks/bench_lugre.py``, seeds 0-2, 10 s: 21 of 108 LuGre fits uncertified,
    one examined 1.97 standard errors short), and the fit then withholds every interval. The
    polish is ``lm`` from the result on the same problem (:func:`certify_polish`); its point
    replaces the search's when lower, the evaluations of both counted. The returned result is
    certified again with the fit (:func:`fricid.identify.dynamic._outcome.converged`)."""
    key = method.strip().lower()
    if max_evals is not None or key not in METHODS or not METHODS[key].uses_residuals:
        return result
    for _ in range(rounds):
        block, polish = certify_polish(problem, result, noise_tolerance=True)
        if block["converged"] or polish is None or not polish.fun < result.fun:
            return result
        nfev = int(result.nfev) + int(polish.nfev)
        kept = {k: result[k] for k in ("method", "seed", "max_evals") if k in result}
        result = type(result)({**polish, **kept, "nfev": nfev})
        result["message"] = f"{polish.message} (carried on from the certificate's polish)"
    return result


def _n_obs(problem: Problem) -> int:
    """The number of residuals of ``problem``."""
    n = getattr(problem, "n_obs", None)
    return int(n) if n is not None else int(np.size(problem.y))


def _se_text(moved: float) -> str:
    """``"3.2 standard errors"``; the residual variance 0: ``"any amount (exact data)"``."""
    return f"{moved:.3g} standard errors" if np.isfinite(moved) else "any amount (exact data)"
