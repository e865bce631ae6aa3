"""IdentificationProblem, the SVD covariance, the fit report, fit(samples, "rbf") and the model
registry behind FittedModel.predict."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import fricid.models
from fricid.errors import (
    ConfigError,
    ConvergenceWarning,
    DataError,
    IgnoredArgumentWarning,
)
from fricid.fitted import FittedModel
from fricid.identify import IdentificationProblem, fit
from fricid.identify.static.uncertainty import covariance_svd, jacobian_uncertainty
from fricid.models import STATEFUL, get_model, get_predictor
from fricid.models.rbf import NETWORK
from fricid.samples import FrictionSamples

TRUTH = {"tau_c": 0.084, "tau_s": 0.641, "w_s": 0.066, "tau_v": 0.0026, "delta": 1.0}


def stribeck_samples(noise: float = 0.003, seed: int = 0, n: int = 40) -> FrictionSamples:
    rng = np.random.default_rng(seed)
    v = np.geomspace(0.005, 4.0, n)
    m = get_model("stribeck")
    y = m.predict(m.param_vector(TRUTH), v) + rng.normal(0.0, noise, v.size)
    return FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=y)


def network_samples(n: int = 120, seed: int = 0) -> FrictionSamples:
    rng = np.random.default_rng(seed)
    v = rng.uniform(-1.0, 1.0, n)
    load = rng.uniform(0.0, 2.0, n)
    temp = rng.uniform(20.0, 40.0, n)
    y = 0.2 * np.tanh(v / 0.05) + 0.1 * v + 0.02 * load + 0.001 * temp
    return FrictionSamples(velocity=v, load=load, temperature=temp, friction=y)


# -- IdentificationProblem -------------------------------------------------------------------


def test_problem_evaluates_a_batch_with_fixed_parameters_and_weights():
    s = stribeck_samples(0.0)
    model = get_model("stribeck")
    p = IdentificationProblem(model, s, fixed={"delta": 1.0})
    assert p.free_names == ["tau_c", "tau_s", "w_s", "tau_v"] and p.n_free == 4
    truth = np.array([[TRUTH[n] for n in p.free_names]])
    T = np.vstack([truth, truth * 1.1])
    R = p.residuals(T)
    assert R.shape == (2, s.y.size)
    f = p.evaluate(T)
    assert f[0] < 1e-25 and f[1] > 0
    np.testing.assert_allclose(f, np.sum(R**2, axis=1))
    mse = IdentificationProblem(model, s, fixed={"delta": 1.0}, loss="mse").evaluate(T)
    np.testing.assert_allclose(mse, f / s.y.size)
    w = np.linspace(0.0, 2.0, s.y.size)
    pw = IdentificationProblem(model, s, fixed={"delta": 1.0}, weights=w)
    full = model.predict(p.expand(T), s.X) - s.y
    np.testing.assert_allclose(pw.evaluate(T), (full**2) @ w)
    assert p.at_bound(p.bounds[:, 0].copy()) == p.free_names


def test_problem_generic_model_needs_array_bounds_and_refuses_bad_input():
    class Line:
        def predict(self, T, X):
            return T[:, :1] + T[:, 1:2] * X[None, :, 0]

    X, y = np.linspace(0, 1, 5)[:, None], 1.0 + 2.0 * np.linspace(0, 1, 5)
    p = IdentificationProblem(Line(), (X, y), bounds=[(-5, 5), (-5, 5)])
    assert p.evaluate(np.array([[1.0, 2.0]]))[0] == 0.0
    with pytest.raises(ConfigError, match="needs bounds"):
        IdentificationProblem(Line(), (X, y))
    with pytest.raises(ConfigError, match="unknown loss"):
        IdentificationProblem(Line(), (X, y), bounds=[(0, 1)] * 2, loss="l1")
    with pytest.raises(ConfigError, match="weights"):
        IdentificationProblem(Line(), (X, y), bounds=[(0, 1)] * 2, weights=[1.0, -1, 1, 1, 1])
    with pytest.raises(ConfigError, match="cannot fix unknown"):
        IdentificationProblem(get_model("stribeck"), stribeck_samples(), fixed={"xi": 1})


def test_residual_problem_follows_the_problem_protocol_and_is_certified_alike():
    """Any batch residual function makes a problem of the protocol that
    ``IdentificationProblem`` follows; certification treats the two alike."""
    from fricid.identify.problem import Problem, ResidualProblem
    from fricid.identify.static.convergence import certify
    from fricid.optim import minimize

    s = stribeck_samples(0.003)
    p = IdentificationProblem(get_model("stribeck"), s, fixed={"delta": 1.0})
    q = ResidualProblem(p.residuals, p.bounds, p.free_names, p.y)
    assert isinstance(p, Problem) and isinstance(q, Problem)
    assert not isinstance(object(), Problem)
    assert (q.n_obs, q.n_free, q.free_names) == (p.n_obs, p.n_free, p.free_names)
    T = p.bounds[:, 0] + np.random.default_rng(1).random((7, 4)) * np.ptp(p.bounds, axis=1)
    np.testing.assert_array_equal(q.evaluate(T), p.evaluate(T))
    np.testing.assert_array_equal(q.expand(T), T)
    for method, evals in (("lm", None), ("bas", 200)):
        res = minimize(
            None, p.bounds, method, seed=0, max_evals=evals, residuals=p.residuals, x0=p.start()
        )
        a, b = certify(p, res), certify(q, res)
        assert a == b and a["converged"] is (method == "lm")
    with pytest.raises(ConfigError, match="one row per name"):
        ResidualProblem(p.residuals, p.bounds[:2], p.free_names, p.y)


# -- covariance by SVD -------------------------------------------------------------------------


def test_svd_covariance_on_a_singular_jacobian_keeps_what_is_determined():
    rng = np.random.default_rng(0)
    a = rng.normal(size=30)
    J = np.column_stack([a, a, rng.normal(size=30)])  # columns 0 and 1 identical: rank 2
    cov, determined = covariance_svd(J, 1.0)
    assert list(determined) == [False, False, True]
    assert np.isnan(cov[0]).all() and np.isnan(cov[:, 1]).all()
    # the determined parameter's variance is what its own column gives
    # (orthogonal to the others up to sampling: compare with the full-rank sub-problem)
    sub = np.linalg.pinv(J[:, [0, 2]].T @ J[:, [0, 2]])
    assert cov[2, 2] == pytest.approx(sub[1, 1], rel=1e-9)
    # full rank: the pseudo-inverse is the inverse
    J2 = J[:, [0, 2]]
    cov2, det2 = covariance_svd(J2, 2.0)
    assert det2.all()
    np.testing.assert_allclose(cov2, 2.0 * np.linalg.inv(J2.T @ J2), rtol=1e-10)


def test_unidentifiable_parameter_has_no_stderr_and_warns():
    # y = (a + b) v: a and b cannot be told apart, c (an offset) can
    v = np.linspace(0.1, 1.0, 20)
    y = 0.3 * v + 0.1 + np.random.default_rng(1).normal(0, 1e-3, v.size)

    def res(T):
        return (T[:, :1] + T[:, 1:2]) * v + T[:, 2:3] - y

    stderr, cov = jacobian_uncertainty(res, np.array([0.1, 0.2, 0.1]), v.size)
    assert np.isnan(cov[0]).all() and np.isfinite(cov[2, 2])
    assert np.isnan(stderr[:2]).all() and np.isfinite(stderr[2]) and stderr[2] > 0
    # one velocity only: Coulomb and viscous friction cannot be told apart, and fit refuses
    # before fitting, naming them (issue 12: no model file from data that cannot determine it)
    s = FrictionSamples(
        velocity=[0.5] * 5, load=0, temperature=25, friction=[0.3, 0.31, 0.29, 0.3, 0.305]
    )
    with pytest.raises(DataError, match=r"single velocity level .* f_c, beta"):
        fit(s, "coulomb_viscous")


# -- fit report --------------------------------------------------------------------------------


def test_fit_report_prints_what_the_file_stores(tmp_path):
    f = fit(stribeck_samples(), "stribeck", fixed={"delta": 1.0})
    assert f.optimizer.status == 0 and f.optimizer.message.startswith("converged")
    st = f.statistics
    assert st["ndata"] == 40 and st["nvarys"] == 4 and st["nfree"] == 36
    assert st["chisqr"] == pytest.approx(f.metrics["sse"])
    assert st["redchi"] == pytest.approx(st["chisqr"] / 36)
    assert st["aic"] == pytest.approx(40 * np.log(st["chisqr"] / 40) + 8)
    assert st["bic"] == pytest.approx(40 * np.log(st["chisqr"] / 40) + np.log(40) * 4)
    assert st["rsquared"] == pytest.approx(f.metrics["fitness"])
    starts = {n: p.init for n, p in f.parameters.items() if p.init is not None}
    assert set(starts) == {"tau_c", "tau_s", "w_s", "tau_v"}
    g = FittedModel.load(f.save(tmp_path / "m.json"))
    assert g.statistics == pytest.approx(f.statistics)
    assert {n: p.init for n, p in g.parameters.items() if p.init is not None} == starts
    text = g.report()
    assert text == f.report()
    for field in (
        "[[Fit Statistics]]",
        "# function evals",
        "# data points      = 40",
        "# variables        = 4",
        "chi-square",
        "reduced chi-square",
        "Akaike info crit",
        "Bayesian info crit",
        "R-squared",
        "[[Variables]]",
        "(init = ",
        "delta:",
        "(fixed)",
        "[[Correlations]]",
    ):
        assert field in text, field
    # correlations above the threshold, largest first
    lines = [ln for ln in text.splitlines() if ln.strip().startswith("C(")]
    values = [abs(float(ln.split("=")[1])) for ln in lines]
    assert values == sorted(values, reverse=True) and min(values) > 0.1
    assert len([ln for ln in g.report(min_correl=0.5).splitlines() if "C(" in ln]) < len(lines)


def test_fit_report_flags_boundary_and_initial_value():
    s = stribeck_samples()
    with pytest.warns(ConvergenceWarning):
        f = fit(s, "stribeck", "lm", fixed={"delta": 1.0}, bounds={"w_s": (0.1, 0.2)}, max_evals=1)
    text = f.report()
    assert "[at initial value]" in text and f.optimizer.status == 1
    assert any(p.at_initial_value for p in f.parameters.values())
    f = fit(s, "stribeck", fixed={"delta": 1.0}, bounds={"w_s": (0.1, 0.2)})
    assert f.parameters["w_s"].at_bound and f.at_bound == ("w_s",)
    assert "[at boundary]" in f.report()


def test_old_model_files_without_the_new_fields_still_load(tmp_path):
    f = fit(stribeck_samples(), "stribeck", fixed={"delta": 1.0})
    d = f.to_dict()
    for key in ("status", "message"):
        d["optimizer"].pop(key)
    for record in d["parameters"].values():
        record.pop("init")
    d.pop("statistics")
    path = tmp_path / "old.json"
    path.write_text(json.dumps(d))
    g = FittedModel.load(path)
    assert g.optimizer.status is None and g.statistics == {}
    assert all(p.init is None for p in g.parameters.values())
    assert "chi-square" in g.report() and "R-squared" in g.report()


# -- the RBF network through identify.fit, and dispatch by model ------------------------------


def test_identify_fit_rbf_equals_fit_rbf():
    from fricid.identify.learned.rbf import fit_rbf

    s = network_samples()
    a = fit(s, "rbf", "lsq", seed=3, settings={"network": {"n_centers": 10}})
    b = fit_rbf(s, n_centers=10, trainer="lsq", random_state=3)
    assert a.model == b.model == "rbf" and a.optimizer.method == b.optimizer.method == "lsq"
    assert a.state == b.state
    np.testing.assert_array_equal(a.predict(s.X), b.predict(s.X))
    assert (
        fit(s, "rbf", seed=3, settings={"network": {"n_centers": 10}}).state == a.state
    )  # default: lsq
    c = fit(
        s,
        "rbf",
        "bas",
        seed=3,
        max_evals=60,
        settings={"network": {"n_centers": 6, "target_mse": None}},
    )
    d = fit_rbf(s, n_centers=6, trainer="bas", random_state=3, max_epochs=2, target_mse=None)
    assert c.optimizer.method == "bas/hybrid" and c.state == d.state
    assert c.optimizer.nfev == d.optimizer.nfev == 60 and a.optimizer.status is None
    assert c.optimizer.status == 1 and "budget" in c.optimizer.message
    # the samples hold both directions: one network per direction (issue 11, defect 1)
    assert c.state["symmetry"] == "per_direction"
    # searched centres: no effective degrees of freedom, so no nvarys, AIC or BIC (issue 15)
    assert c.statistics["ndata"] == 120 and "nvarys" not in c.statistics
    assert "effective degrees of freedom are undefined" in c.statistics_note
    assert c.convergence["converged"] is False and "budget" in c.convergence["reason"]


def test_identify_fit_rbf_rejects_named_parameter_arguments():
    s = network_samples(40)
    with pytest.raises(ConfigError, match="no named parameters: fixed"):
        fit(s, "rbf", fixed={"tau_c": 1.0})
    with pytest.raises(ConfigError, match="does not take callback"):
        fit(s, "rbf", settings={"network": {"n_centers": 4}}, callback=lambda r: None)
    with pytest.raises(ConfigError, match="analytic identification takes no settings"):
        fit(stribeck_samples(), "coulomb_viscous", settings={"network": {"n_centers": 4}})
    with pytest.raises(ConfigError, match="trains with method lsq, bas, ga; got 'lm'"):
        fit(s, "rbf", "lm")


def test_lsq_trainer_warns_about_the_options_it_ignores():
    from fricid.identify.learned.rbf import RBFNetRegressor

    s = network_samples(40)
    with pytest.warns(IgnoredArgumentWarning, match="ignores encoding, method_options") as rec:
        RBFNetRegressor(4, encoding="full", method_options={"n_iter": 3}).fit(s.X, s.y)
    assert rec[0].filename == __file__
    with warnings.catch_warnings():
        warnings.simplefilter("error", IgnoredArgumentWarning)
        RBFNetRegressor(4, random_state=0).fit(s.X, s.y)
        RBFNetRegressor(4, trainer="bas", max_epochs=1, random_state=0).fit(s.X, s.y)


def test_fitted_model_dispatches_prediction_through_the_model_registry(monkeypatch):
    s = network_samples(60)
    rbf = fit(s, "rbf", settings={"network": {"n_centers": 5}})
    cv = fit(stribeck_samples(), "coulomb_viscous")
    assert get_predictor("rbf") is NETWORK and STATEFUL["rbf"] is NETWORK
    assert get_predictor("coulomb_viscous").stateful is False
    assert rbf.kind == "rbf" and cv.kind == "analytic"
    calls = []

    class Spy:
        stateful = True

        def predict(self, state, X):
            calls.append(state)
            return np.zeros(len(X))

    monkeypatch.setitem(STATEFUL, "rbf", Spy())
    assert np.all(rbf.predict(s.X) == 0.0) and calls == [rbf.state]
    assert not hasattr(fricid.models, "RBFNetRegressor")
    with pytest.raises(ConfigError, match="unknown model"):
        get_predictor("nope")


def test_problem_docstring_example_runs():
    import doctest

    import fricid.identify.problem as module

    assert doctest.testmod(module).failed == 0


def test_a_fit_with_as_many_parameters_as_samples_says_its_reduced_chi_square_is_undefined():
    """Four samples and a four-parameter law: no degrees of freedom, so the report says the
    reduced chi-square is undefined instead of printing nan."""
    samples = FrictionSamples(
        velocity=[-1.0, -0.5, 0.5, 1.0], load=0.0, temperature=25.0,
        friction=[-0.3, -0.25, 0.25, 0.3],
    )  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        text = fit(samples, "coulomb_viscous_asym", "lm").report()
    assert "reduced chi-square = undefined" in text and "nan" not in text.lower()


def test_an_interval_far_wider_than_the_standard_error_says_so():
    """A profile interval at a bound, 4.6 times the curvature's +/- 1.96 se on one side: the
    report says to read the interval (a new user had read the +/- as 17 % precision); one as
    wide as the +/- says nothing more."""
    from fricid.fitted import Parameter
    from fricid.fitted._report import _variable_note

    wide = Parameter("beta_pos", 0.0215, stderr=0.00357, ci95=(0.0, 0.0537))
    assert "4.6x +/- 1.96 standard errors: read it" in _variable_note(wide, "profile")
    usual = Parameter("beta_pos", 0.0215, stderr=0.00357, ci95=(0.0145, 0.0285))
    assert "standard errors: read it" not in _variable_note(usual, "profile")
