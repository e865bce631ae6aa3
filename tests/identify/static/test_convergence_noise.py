"""Convergence judged against the noise: a polish gain the scatter cannot resolve is converged,
one that moves the parameters by standard errors is not, and the message gives the figures."""

from __future__ import annotations

import numpy as np
import pytest

from fricid.identify import IdentificationProblem
from fricid.identify.static.convergence import RESOLVE_SE, certify, noise_ftol
from fricid.models import get_model
from fricid.optim import OptimizeResult, minimize
from fricid.samples import FrictionSamples


@pytest.fixture(scope="module")
def problem():
    rng = np.random.default_rng(0)
    speed = np.geomspace(0.05, 2.0, 30)
    v = np.r_[-speed, speed]
    y = np.sign(v) * (0.8 + 0.3 * np.abs(v)) + rng.normal(0.0, 0.05, v.size)
    s = FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=y)
    return IdentificationProblem(get_model("coulomb_viscous"), s)


def _at(problem, rel_gain: float) -> OptimizeResult:
    """A result on the line through the optimum whose SSE is ``rel_gain`` above it."""
    best = minimize(problem.evaluate, problem.bounds, method="lm", residuals=problem.residuals)
    x0, sse0 = np.asarray(best.x, float), float(best.fun)
    step = np.array([0.0, 1.0])  # along the viscous coefficient
    lo, hi = 0.0, 1.0
    for _ in range(80):  # bisection on the SSE gain
        mid = 0.5 * (lo + hi)
        gain = float(problem.evaluate((x0 + mid * step)[None, :])[0]) / sse0 - 1.0
        lo, hi = (mid, hi) if gain < rel_gain else (lo, mid)
    x = x0 + lo * step
    return OptimizeResult(
        x=x,
        fun=float(problem.evaluate(x[None, :])[0]),
        nfev=500,
        nit=10,
        status=1,
        message="budget spent",
        success=False,
        method="bas",
        max_evals=500,
    )


def test_a_gain_below_what_the_scatter_resolves_is_converged(problem):
    conv = certify(problem, _at(problem, 1.1e-4))  # 0.011 % of the SSE
    assert conv["converged"] and conv["certified_by"] == "polish"
    assert 0.9998 < conv["polish_sse_ratio"] < 0.99995


def test_a_gain_of_standard_errors_is_not_converged_and_says_so(problem):
    dof = problem.n_obs - problem.n_free
    conv = certify(problem, _at(problem, 4.0 / dof))  # about 2 standard errors
    assert not conv["converged"]
    reason = conv["reason"]
    assert "x lower" not in reason and "% lower" in reason
    moved = float(reason.split("move by ")[1].split(" standard errors")[0])
    assert 1.5 < moved < 2.5 and moved > RESOLVE_SE


@pytest.mark.parametrize(("distance", "converged"), [(0.05, True), (0.3, False), (2.0, False)])
def test_a_polish_stopped_at_the_resolution_gives_the_same_verdict(problem, distance, converged):
    """``noise_tolerance``: the polish stops once a step gains under a tenth of what the
    verdict resolves; the verdict is the full polish's at 0.05, 0.3 and 2 standard errors
    from the optimum, in fewer evaluations."""
    dof = problem.n_obs - problem.n_free
    result = _at(problem, distance**2 / dof)  # an SSE gain of distance^2 s^2
    full = certify(problem, result)
    short = certify(problem, result, noise_tolerance=True)
    assert full["converged"] is short["converged"] is converged
    assert short["polish_nfev"] < full["polish_nfev"]


def test_noise_ftol_is_the_resolution_per_degree_of_freedom(problem):
    dof = problem.n_obs - problem.n_free
    assert noise_ftol(problem) == pytest.approx(RESOLVE_SE**2 / dof)
    assert noise_ftol(problem, 0.1) == pytest.approx(0.1 * RESOLVE_SE**2 / dof)


def test_a_search_carried_past_its_budget_says_so(problem):
    """A search carried on from the certificate's polish (``settle``) spent more than its
    budget: the texts said "2315 of 1000 evaluations"."""
    from fricid.fitted._file import _convergence_line

    result = _at(problem, 4.0 / 58)
    result["nfev"], result["max_evals"] = 2315, 1000
    conv = certify(problem, result)
    assert not conv["converged"]
    assert "2315 evaluations (budget 1000, carried on" in conv["reason"]
    assert "of 1000" not in conv["reason"]
    line = _convergence_line(conv, 2315, 1000)
    assert "2315 evaluations, budget 1000" in line and "of 1000" not in line
    assert "500 of 500 evaluations" in _convergence_line(conv, 500, 500)
