"""Temperature as an option of the analytic families (issue 15): the Arrhenius viscous term of
``*_temp`` models, identified from virtual data, checked for identifiability, exported to C."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from _c_harness import SMOOTHINGS, compile_and_run, needs_cc, points, relative_error, zone_scale
from fricid.errors import ConfigError, IdentifiabilityWarning
from fricid.export.c import export_c
from fricid.fitted import FittedModel, OptimizerRecord
from fricid.identify import evaluate, fit
from fricid.models import MODELS, WithTemperature, get_model
from fricid.models._temperature import T_REF, arrhenius_factor
from fricid.models.smoothing import smooth_predict
from fricid.samples import FrictionSamples

#: A law written for this test: per-direction Stribeck levels, Arrhenius viscous term (e_t
#: 3000 K: the viscous coefficient falls by about 2.3x from 20 to 65 degC).
TRUE = {
    "tau_c_pos": 0.30,
    "tau_s_pos": 0.45,
    "w_s_pos": 0.05,
    "tau_v_pos": 0.20,
    "delta_pos": 1.0,
    "tau_c_neg": 0.25,
    "tau_s_neg": 0.40,
    "w_s_neg": 0.07,
    "tau_v_neg": 0.24,
    "delta_neg": 1.0,
    "e_t": 3000.0,
}
SIGMA = 0.005


def _grid(temperatures, seed: int) -> tuple[FrictionSamples, np.ndarray]:
    model = get_model("stribeck_temp_asym")
    v = np.concatenate([s * np.geomspace(0.01, 3.0, 12) for s in (1, -1)])
    V, T = (a.ravel() for a in np.meshgrid(v, np.asarray(temperatures, float)))
    X = np.column_stack([V, np.zeros_like(V), T])
    truth = model.predict(model.param_vector(TRUE), X)
    y = truth + SIGMA * np.random.default_rng(seed).standard_normal(V.size)
    return FrictionSamples(velocity=V, load=0.0, temperature=T, friction=y), truth


def test_names_compose_direction_and_temperature():
    m = get_model("stribeck_temp_asym")
    assert isinstance(m, WithTemperature) and m.is_asymmetric
    assert m.param_names == (*get_model("stribeck_asym").param_names, "e_t")
    assert m.units["e_t"] == "K"
    assert get_model("msk_temp").param_names == (*get_model("msk").param_names, "e_t")
    assert get_model(get_model("stribeck_temp"), asymmetric=True).name == "stribeck_temp_asym"
    for name in MODELS:  # the existing names keep their parameter vectors
        assert "e_t" not in get_model(name).param_names
    with pytest.raises(ConfigError, match="no viscous term"):
        get_model("vlt_temp")


def test_prediction_is_the_arrhenius_law():
    m = get_model("stribeck_temp")
    base = get_model("stribeck")
    theta = np.array([0.1, 0.2, 0.05, 0.3, 1.0, 2500.0])
    X = np.array([[0.7, 0.0, 10.0], [-0.4, 0.0, 70.0], [0.2, 0.0, T_REF], [0.0, 0.0, 30.0]])
    g = base.predict(np.r_[theta[:3], 0.0, theta[4]], X)
    want = g + 0.3 * np.exp(2500.0 * (1 / (X[:, 2] + 273.15) - 1 / (T_REF + 273.15))) * X[:, 0]
    np.testing.assert_allclose(m.predict(theta, X), want, rtol=1e-14)
    np.testing.assert_allclose(m.predict(theta, X[2:3]), base.predict(theta[:5], X[2:3]))
    assert arrhenius_factor(2500.0, 20.0) > 1.0 > arrhenius_factor(2500.0, 60.0)


def test_fit_recovers_a_known_temperature_law():
    samples, _ = _grid([20.0, 35.0, 50.0, 65.0], seed=3)
    held_out, truth = _grid([27.5, 42.5, 57.5], seed=4)
    with warnings.catch_warnings():
        warnings.simplefilter("error", IdentifiabilityWarning)
        fitted = fit(samples, "stribeck_temp_asym")
    # within 4 standard errors of the truth
    assert abs(fitted.params["e_t"] - TRUE["e_t"]) < 4 * fitted.parameters["e_t"].stderr
    for name in ("tau_v_pos", "tau_v_neg", "tau_c_pos", "tau_c_neg"):
        se = fitted.parameters[name].stderr
        assert abs(fitted.params[name] - TRUE[name]) < 4 * se, name
    # held-out temperatures: RMSE against the noisy data near the noise, against the truth
    # well below it
    assert evaluate(fitted, held_out)["rmse"] < 1.2 * SIGMA
    err = fitted.predict(held_out.X) - truth
    assert np.sqrt(np.mean(err**2)) < 0.5 * SIGMA
    # without the temperature law the same data leave a misfit of several noise levels
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IdentifiabilityWarning)  # w_s, delta: not the point
        plain = fit(samples, "stribeck_asym")
    assert evaluate(plain, held_out)["rmse"] > 3 * SIGMA


def test_one_temperature_does_not_determine_e_t():
    samples, _ = _grid([30.0], seed=5)
    with pytest.warns(IdentifiabilityWarning, match="e_t"):
        fit(samples, "stribeck_temp")


def test_model_file_round_trip(tmp_path):
    samples, _ = _grid([20.0, 50.0], seed=6)
    fitted = fit(samples, "stribeck_temp_asym", intervals="none")
    path = fitted.save(tmp_path / "m.json")
    back = FittedModel.load(path)
    assert back.model == "stribeck_temp_asym" and back.params == fitted.params
    np.testing.assert_array_equal(back.predict(samples.X), fitted.predict(samples.X))


@needs_cc
@pytest.mark.parametrize("name", ["stribeck_temp", "msk_temp_asym"])
def test_c_export_matches_python(tmp_path, name):
    model = get_model(name)
    theta = model.defaults()
    theta[-1] = 2800.0
    theta[: len(theta) // 2] *= 1.3  # the two directions differ
    fitted = FittedModel.from_values(
        name,
        dict(zip(model.param_names, map(float, theta), strict=True)),
        operating_range={"velocity": [-5.0, 5.0], "load": [-0.5, 0.5], "temperature": [0, 50]},
        optimizer=OptimizerRecord(method="test", seed=0),
    )
    X = points()
    for k, smoothing in enumerate(SMOOTHINGS):
        out = tmp_path / str(k)
        export_c(fitted, out, smoothing, source="test")
        got = compile_and_run(out, X)
        want = smooth_predict(fitted, X, smoothing)
        assert relative_error(got, want, zone_scale(fitted, X, smoothing)) <= 1e-12, smoothing
