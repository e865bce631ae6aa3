"""Profile intervals only where the Jacobian's are not trustworthy, and ``auto``'s folds
screened cheaply (fricid.identify.static.curvature, uncertainty, select, validate)."""

from __future__ import annotations

import importlib
import warnings

import numpy as np
import pytest
from scipy import stats

from fricid.errors import FricidWarning
from fricid.extract import extract
from fricid.identify import IdentificationProblem, fit
from fricid.identify.static import profile
from fricid.identify.static.curvature import checked_ends
from fricid.identify.static.uncertainty import jacobian_uncertainty
from fricid.models import get_model
from fricid.samples import FrictionSamples
from fricid.sim import preset, simulate

validate_module = importlib.import_module("fricid.identify.validate")


@pytest.fixture(scope="module")
def paper2():
    scenario = preset("paper2", "reduced")
    return extract(simulate(scenario, seed=0), **scenario.extract_options()).samples


def quiet_fit(*args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FricidWarning)
        return fit(*args, **kw)


def coulomb_viscous(tau_v: float, noise: float = 0.01, seed: int = 0) -> FrictionSamples:
    v = np.repeat(np.linspace(0.1, 2.0, 8), 2) * np.tile([1.0, -1.0], 8)
    rng = np.random.default_rng(seed)
    f = np.sign(v) * 0.3 + tau_v * v + noise * rng.standard_normal(v.size)
    return FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=f)


def test_a_linear_model_is_checked_on_every_side_at_the_wald_ends():
    """Coulomb-viscous is linear in its parameters: the profile is the quadratic, so every
    side is checked and its end is the Jacobian's value +/- t se."""
    samples = coulomb_viscous(0.2)
    problem = IdentificationProblem(get_model("coulomb_viscous"), samples)
    x = quiet_fit(samples, "coulomb_viscous", intervals="none")
    theta = np.array([x.params[n] for n in problem.free_names])
    se, cov = jacobian_uncertainty(problem.residuals, theta, problem.n_obs)
    r = problem.residuals(theta[None])[0]
    ends, checked, lowest = checked_ends(problem, theta, cov, float(r @ r))
    assert checked.all()
    half = stats.t.ppf(0.975, problem.n_obs - problem.n_free) * se
    np.testing.assert_allclose(ends[:, 0], theta - half, rtol=1e-5)
    np.testing.assert_allclose(ends[:, 1], theta + half, rtol=1e-5)
    assert lowest >= float(r @ r) * (1 - 1e-9)


def test_a_side_whose_wald_end_leaves_the_box_is_profiled(monkeypatch):
    """Little viscous friction in noisy data: beta's Wald interval crosses its bound 0 below,
    and f_c's trace leaves the box above (beta < 0 there): those two sides are profiled
    (beta's found open at 0), the other two, where the quadratic holds, are not."""
    samples = coulomb_viscous(0.05, noise=0.05, seed=3)
    calls = []
    real = profile.profile_intervals
    monkeypatch.setattr(
        profile, "profile_intervals", lambda *a, **k: calls.append(k["sides"]) or real(*a, **k)
    )
    f = quiet_fit(samples, "coulomb_viscous")
    assert len(calls) == 1
    sides = calls[0]
    assert list(f.free) == ["f_c", "beta"]
    np.testing.assert_array_equal(sides, [[False, True], [True, False]])
    p = f.parameters["beta"]
    assert p.low_open and p.ci95[0] == p.bounds[0] == 0.0 and not p.high_open


def test_default_fit_profiles_no_side_where_the_quadratic_holds(paper2, monkeypatch):
    """The 4-parameter Stribeck on 17 samples: the quadratic approximation holds at every
    Wald end, so the default fit makes no profile re-fit (it made 63), and its ends are the
    full profile's to 1 % of each interval's width."""
    full = quiet_fit(paper2, "stribeck", fixed={"delta": 1.0}, intervals="profile")
    refits = []
    real = profile._Refit.__call__
    monkeypatch.setattr(
        profile._Refit, "__call__", lambda self, *a: refits.append(1) or real(self, *a)
    )
    f = quiet_fit(paper2, "stribeck", fixed={"delta": 1.0})
    assert not refits
    assert f.ci_method == "profile"
    for name, p in f.parameters.items():
        if p.fixed:
            continue
        want = np.array(full.parameters[name].ci95)
        width = want[1] - want[0]
        assert np.all(np.abs(np.array(p.ci95) - want) <= 0.01 * width), (name, p.ci95, want)
        assert not p.low_open and not p.high_open


def test_validation_folds_compute_no_intervals(paper2, monkeypatch):
    """A fold's fit is used for its predictions only: no interval, whatever is asked."""
    asked = []
    real = validate_module.fit
    monkeypatch.setattr(
        validate_module,
        "fit",
        lambda *a, **k: asked.append(k.get("intervals")) or real(*a, **k),
    )
    v = validate_module.validate(
        paper2, "coulomb_viscous", "kfold:3", fixed=None, intervals="profile"
    )
    assert asked == ["none"] * 3 and np.isfinite(v.rmse)


def test_auto_refits_the_folds_together_with_the_same_heldout_error(paper2, monkeypatch):
    """``auto``'s folds start from each candidate's optimum on all samples and are refitted
    together (no fit per fold), and the held-out errors are those of a fit per fold from the
    default start."""
    per_fold = []
    real = validate_module.fit
    monkeypatch.setattr(
        validate_module, "fit", lambda *a, **k: per_fold.append(a[1]) or real(*a, **k)
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FricidWarning)
        chosen = fit(paper2, "auto", settings={"scheme": "kfold:4"})
    assert per_fold == []
    monkeypatch.setattr(validate_module, "fit", real)
    scored = [r for r in chosen.selection["table"] if r["heldout_rmse"] is not None]
    assert len(scored) == 3
    for row in scored:
        model, _, fixed = row["model"].partition(" (delta=")
        plain = validate_module.validate(
            paper2, model, "kfold:4", fixed={"delta": 1.0} if fixed else None
        )
        assert row["heldout_rmse"] == pytest.approx(plain.rmse, rel=1e-5), row
