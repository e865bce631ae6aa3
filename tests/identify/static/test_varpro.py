"""Issue 17: ``method="varpro"``, the exact least-squares optimum by variable projection.

varpro reaches the exact optimum from any start on the RWSAVSBAS Stribeck study and on
held-out analytic laws (parameters drawn at random), at no more cost than ``lm``; fixed
parameters, weights and robust losses are handled; the result is a normal fitted model with
intervals; the CLI offers it.
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import ConfigError, FricidWarning, IgnoredArgumentWarning
from fricid.experiments import stribeck_problem as sp
from fricid.identify import fit
from fricid.io import write_samples
from fricid.models import MODELS, FrictionModel, Parameter, get_model
from fricid.samples import FrictionSamples

#: Relative SSE above the optimum that still counts as the exact optimum (rounding).
EXACT = 1e-9


def quiet(*args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FricidWarning)
        return fit(*args, **kw)


@pytest.fixture(scope="module")
def study():
    """The RWSAVSBAS study problem: 17 samples, delta = 1, the study's box, its optimum."""
    v, y = sp.paper2_samples(0)
    samples = FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=y)
    names = [n for n in get_model("stribeck").param_names if n != "delta"]
    kw = {
        "fixed": {"delta": 1.0},
        "bounds": {n: tuple(b) for n, b in zip(names, sp.BOUNDS, strict=True)},
    }
    return samples, kw, sp.global_optimum(sp.StribeckProblem(v, y))[1]


def drawn(name: str, seed: int, noise: float = 0.01) -> FrictionSamples:
    """A held-out law: ``name`` with parameters drawn in [0.3, 1.7] x its defaults."""
    rng = np.random.default_rng(seed)
    m = get_model(name)
    v = np.repeat(np.geomspace(0.004, 2.0, 24), 2) * np.tile([1.0, -1.0], 24)
    X = np.column_stack([v, rng.uniform(-4, 4, v.size), rng.uniform(15, 45, v.size)])
    y = m.predict(m.defaults(X, np.ones(1)) * rng.uniform(0.3, 1.7, m.n_params), X)
    y = y + noise * np.abs(y).max() * rng.standard_normal(v.size)
    return FrictionSamples(velocity=v, load=X[:, 1], temperature=X[:, 2], friction=y)


def best_sse(samples, model, **kw) -> float:
    """The reference optimum: a generous 48-start lm."""
    return quiet(
        samples, model, "lm", intervals="none", options={"n_starts": 48}, max_evals=300_000, **kw
    ).metrics["sse"]


def starts(samples, model, kw) -> list[dict[str, float]]:
    """Box middle, lower and upper corners, and two random points (the fixed ones left out)."""
    m = get_model(model)
    b = m.bounds(samples.X, samples.y)
    for name, pair in kw.get("bounds", {}).items():
        b[m.param_names.index(name)] = pair
    rng = np.random.default_rng(3)
    points = [b.mean(axis=1), b[:, 0], b[:, 1], *(b[:, 0] + rng.random((2, len(b))) * np.ptp(b, 1))]
    fixed = kw.get("fixed", {})
    return [
        {n: float(x) for n, x in zip(m.param_names, p, strict=True) if n not in fixed}
        for p in points
    ]


@pytest.mark.parametrize("name", [*MODELS, "stribeck_asym"])
def test_declared_linear_parameters_enter_linearly(name):
    """f(a c1 + (1 - a) c2) = a f(c1) + (1 - a) f(c2) in the declared parameters, and the
    model is 0 when they all are (a linear combination, no offset)."""
    m = get_model(name)
    assert m.linear_params and set(m.linear_params) <= set(m.param_names)
    rng = np.random.default_rng(0)
    X = np.column_stack([rng.uniform(-2, 2, 40), rng.uniform(-3, 3, 40), rng.uniform(10, 50, 40)])
    lin = [m.param_names.index(n) for n in m.linear_params]
    t1 = m.defaults() * rng.uniform(0.5, 1.5, m.n_params)
    t2 = t1.copy()
    t2[lin] = rng.uniform(-1, 1, len(lin))
    mix = 0.3 * t1 + 0.7 * t2
    np.testing.assert_allclose(
        m.predict(mix, X), 0.3 * m.predict(t1, X) + 0.7 * m.predict(t2, X), atol=1e-12
    )
    zero = t1.copy()
    zero[lin] = 0.0
    np.testing.assert_allclose(m.predict(zero, X), 0.0, atol=1e-14)


@pytest.mark.slow  # 5 s measured under load (default run kept short)
def test_varpro_reaches_the_study_optimum_from_any_start(study):
    samples, kw, optimum = study
    for x0 in starts(samples, "stribeck", kw):
        f = quiet(samples, "stribeck", "varpro", x0=x0, intervals="none", **kw)
        assert f.converged and f.optimizer.method == "varpro"
        assert f.metrics["sse"] <= optimum * (1 + EXACT), (x0, f.metrics["sse"], optimum)
        assert all(p.init is None for p in f.parameters.values())  # the search covers the box
    with pytest.warns(IgnoredArgumentWarning, match="x0 is not used"):
        fit(samples, "stribeck", "varpro", x0={"w_s": 0.5}, intervals="none", **kw)


@pytest.mark.parametrize(
    ("name", "seed"), [("stribeck", 11), ("msk", 12), ("vlt", 13), ("coulomb_viscous", 14)]
)
def test_varpro_reaches_the_optimum_of_held_out_laws(name, seed):
    samples = drawn(name, seed)
    ref = best_sse(samples, name)
    x0 = starts(samples, name, {})[2]  # the upper corner
    f = quiet(samples, name, "varpro", x0=x0, intervals="none")
    assert f.converged and f.metrics["sse"] <= ref * (1 + EXACT), (f.metrics["sse"], ref)


@pytest.mark.slow  # timing-sensitive: wall time against wall time, run by make test-all
def test_varpro_costs_no_more_than_lm(study):
    """Wall time summed over the study and two held-out laws (each the fastest of 3 runs,
    measured in this process): varpro is not slower than the default lm."""
    cases = [(study[0], "stribeck", study[1])]
    cases += [(drawn("stribeck", 21), "stribeck", {}), (drawn("coulomb_viscous", 22), "c", {})]
    total = {"varpro": 0.0, "lm": 0.0}
    for samples, model, kw in cases:
        model = "coulomb_viscous" if model == "c" else model
        for method in total:
            runs = []
            for _ in range(3):
                t = time.perf_counter()
                quiet(samples, model, method, intervals="none", **kw)
                runs.append(time.perf_counter() - t)
            total[method] += min(runs)
    assert total["varpro"] <= total["lm"], total


def test_fixed_parameters_linear_or_not(study):
    samples, kw, _ = study
    for fixed in ({"delta": 1.0, "tau_c": 0.05}, {"delta": 1.0, "w_s": 0.05}):
        args = {"fixed": fixed, "bounds": kw["bounds"]}
        f = quiet(samples, "stribeck", "varpro", intervals="none", **args)
        assert f.metrics["sse"] <= best_sse(samples, "stribeck", **args) * (1 + EXACT)
        assert all(f.params[n] == v for n, v in fixed.items())


def test_weights_and_asymmetric_model():
    samples = drawn("stribeck", 31)
    w = np.random.default_rng(0).uniform(0.2, 5.0, len(samples))
    f = quiet(samples, "stribeck", "varpro", weights=w, intervals="none")
    g = quiet(samples, "stribeck", "lm", weights=w, intervals="none", options={"n_starts": 48})
    assert f.statistics["chisqr"] <= g.statistics["chisqr"] * (1 + EXACT)
    asym = FrictionSamples(
        velocity=samples.X[:, 0],
        load=0.0,
        temperature=25.0,
        friction=samples.y,
        direction=np.sign(samples.X[:, 0]).astype(int),
    )
    f = quiet(asym, "stribeck_asym", "varpro", intervals="none")
    assert f.converged and f.metrics["sse"] <= best_sse(asym, "stribeck_asym") * (1 + EXACT)


def test_robust_loss_is_a_polished_local_fit_and_says_so():
    samples = drawn("stribeck", 41)
    kw = {"loss": "soft_l1", "f_scale": 0.002 * np.abs(samples.y).max(), "intervals": "none"}
    f = quiet(samples, "stribeck", "varpro", **kw)
    g = quiet(samples, "stribeck", "lm", **kw)
    assert f.converged and "robust loss" in f.optimizer.message
    assert f.statistics["chisqr"] == pytest.approx(g.statistics["chisqr"], rel=1e-3)


def test_result_has_intervals_like_lm(study):
    samples, kw, _ = study
    f = quiet(samples, "stribeck", "varpro", **kw)
    g = quiet(samples, "stribeck", "lm", **kw)
    assert f.ci_method == g.ci_method and f.convergence["certified_by"] == "optimizer"
    for n in f.free:
        ends = f.parameters[n].ci95
        assert ends == pytest.approx(g.parameters[n].ci95, rel=1e-3, abs=1e-9)


class _NoLinear(FrictionModel):
    name = "nolinear"
    parameters = (Parameter("a", "N m", "torque", 0.5, 0.0, 2.0),)

    def _predict(self, theta, X):
        return np.tanh(theta[:, :1] * X[None, :, 0])


def test_model_without_linear_parameters_and_bad_options_are_refused():
    samples = drawn("stribeck", 51)
    with pytest.raises(ConfigError, match="declares none"):
        fit(samples, _NoLinear(), "varpro")
    with pytest.raises(ConfigError, match="no option"):
        fit(samples, "stribeck", "varpro", options={"n_starts": 3})


@pytest.mark.slow  # 1.4 s, quiet machine (default run kept short)
def test_cli_lists_and_fits_with_varpro(tmp_path):
    runner = CliRunner()
    res = runner.invoke(app, ["methods"])
    assert res.exit_code == 0 and "varpro" in res.output
    path = write_samples(drawn("stribeck", 61), tmp_path / "s.csv")
    out = tmp_path / "m.json"
    res = runner.invoke(app, ["fit", str(path), "--method", "varpro", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert out.exists() and "varpro" in res.output


def test_projected_problem_follows_the_problem_protocol(study):
    """varpro's inner problem (the nonlinear parameters, the linear ones solved) is a problem
    of the protocol: its loss at varpro's nu is the full problem's at varpro's result, and
    certification applies to it as to any fit."""
    from fricid.identify.problem import IdentificationProblem, Problem
    from fricid.identify.static.convergence import certify
    from fricid.identify.static.varpro import _blocks, _Projection, linear_split, varpro

    samples, kw, f_opt = study
    problem = IdentificationProblem(get_model("stribeck"), samples, **kw)
    lin, nl = linear_split(problem)
    proj = _Projection(problem, _blocks(problem, lin, nl)[0], problem.start())
    assert isinstance(proj, Problem)
    assert proj.free_names == ["w_s"] and proj.n_free == 1 and proj.n_obs == samples.y.size
    res = varpro(problem)
    nu = res.x[nl][None]
    assert proj.evaluate(nu)[0] == pytest.approx(res.fun, rel=1e-12)
    np.testing.assert_allclose(proj.expand(nu)[0], res.x, rtol=1e-12, atol=1e-15)
    inner = {**res, "x": res.x[nl], "fun": float(proj.evaluate(nu)[0])}
    assert certify(proj, type(res)(inner))["converged"]
    assert res.fun <= f_opt * (1 + EXACT)
