"""Identification: recovery of known parameters, fixed parameters, uncertainty, model files."""

from __future__ import annotations

import json

import numpy as np
import pytest

from fricid.errors import ConfigError, DataError
from fricid.fitted import SCHEMA_VERSION, FittedModel
from fricid.identify import evaluate, fit
from fricid.models import get_model
from fricid.samples import FrictionSamples

TRUTH = {"tau_c": 0.084, "tau_s": 0.641, "w_s": 0.066, "tau_v": 0.0026, "delta": 1.0}


def stribeck_samples(noise: float, seed: int, n: int = 40) -> FrictionSamples:
    rng = np.random.default_rng(seed)
    v = np.geomspace(0.005, 4.0, n)
    m = get_model("stribeck")
    y = m.predict(m.param_vector(TRUTH), v) + rng.normal(0.0, noise, v.size)
    return FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=y, source="synthetic")


def test_noiseless_stribeck_recovered_exactly():
    f = fit(stribeck_samples(0.0, 0), "stribeck", fixed={"delta": 1.0})
    for name, value in TRUTH.items():
        assert f.params[name] == pytest.approx(value, rel=1e-6), name
    assert f.metrics["sse"] < 1e-20
    assert f.fixed == ("delta",) and f.parameters["delta"].fixed


@pytest.mark.parametrize("method", ["lm", "trf"])
def test_noisy_stribeck_within_standard_errors(method):
    """With noise, each free parameter lies within 4 standard errors of the truth, and the
    standard errors are honest: not absurdly small or large against the scatter over seeds."""
    errors = []
    for seed in range(5):
        f = fit(stribeck_samples(0.003, seed), "stribeck", method, fixed={"delta": 1.0})
        for name in ("tau_c", "tau_s", "w_s", "tau_v"):
            z = (f.params[name] - TRUTH[name]) / f.parameters[name].stderr
            errors.append(z)
            assert abs(z) < 4.0, (seed, name, z)
    # the z-scores behave like standard normals: their RMS is near 1
    assert 0.4 < np.sqrt(np.mean(np.square(errors))) < 1.8


def test_asymmetric_fit_recovers_each_direction():
    m = get_model("coulomb_viscous_asym")
    v = np.concatenate([np.linspace(0.05, 1, 10), -np.linspace(0.05, 1, 10)])
    theta = m.param_vector({"f_c_pos": 0.3, "beta_pos": 0.1, "f_c_neg": 0.2, "beta_neg": 0.15})
    s = FrictionSamples(velocity=v, load=0, temperature=25, friction=m.predict(theta, v))
    f = fit(s, m)
    np.testing.assert_allclose(f.theta(), theta, rtol=1e-6)


def test_asymmetric_needs_both_directions():
    s = stribeck_samples(0.0, 0)
    with pytest.raises(ConfigError, match="positive direction only"):
        fit(s, "stribeck_asym")
    combined = FrictionSamples(
        velocity=[0.1, 0.2], load=0, temperature=25, friction=[1, 1], direction=[0, 0]
    )
    with pytest.raises(ConfigError, match="combine both directions"):
        fit(combined, "stribeck_asym")


def test_bad_fixed_and_bounds_and_too_few_samples():
    s = stribeck_samples(0.0, 0)
    with pytest.raises(ConfigError, match="cannot fix unknown parameter"):
        fit(s, "stribeck", fixed={"xi": 1.0})
    with pytest.raises(ConfigError, match="lower < upper"):
        fit(s, "stribeck", bounds={"w_s": (1.0, 0.5)})
    with pytest.raises(ConfigError, match="unknown parameter 'nope'"):
        fit(s, "stribeck", bounds={"nope": (0, 1)})
    with pytest.raises(ConfigError, match="cannot identify"):
        fit(s.subset(np.arange(3)), "stribeck")
    with pytest.raises(ConfigError, match="unknown method"):
        fit(s, "stribeck", method="simplex")


def test_same_seed_same_fit():
    s = stribeck_samples(0.003, 1)
    a = fit(s, "stribeck", seed=3)
    b = fit(s, "stribeck", seed=3)
    assert a.params == b.params


def test_model_file_round_trip(tmp_path):
    s = stribeck_samples(0.003, 2)
    f = fit(s, "stribeck", fixed={"delta": 1.0})
    path = f.save(tmp_path / "m.json")
    g = FittedModel.load(path)
    assert g.params == f.params
    np.testing.assert_array_equal(g.predict(s.X), f.predict(s.X))
    assert evaluate(g, s)["sse"] == pytest.approx(f.metrics["sse"])
    assert "tau_c" in g.report() and "(fixed)" in g.report()


def test_model_file_errors(tmp_path):
    p = tmp_path / "bad.json"
    p.write_text("{not json")
    with pytest.raises(DataError, match=r"bad\.json, row 1: not valid JSON"):
        FittedModel.load(p)
    f = fit(stribeck_samples(0.0, 0), "coulomb_viscous")
    d = f.to_dict()
    d["schema_version"] = SCHEMA_VERSION + 1
    p.write_text(json.dumps(d))
    with pytest.raises(DataError, match="newer than this fricid"):
        FittedModel.load(p)
    with pytest.raises(DataError, match="cannot read the model file"):
        FittedModel.load(tmp_path / "missing.json")
