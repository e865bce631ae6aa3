"""One record per parameter and one optimiser record (``fricid.fitted._parameter``): what a
record holds, how the model file writes it, and the read-only views of ``FittedModel``."""

from __future__ import annotations

import json
import math
import re
from dataclasses import FrozenInstanceError, replace

import numpy as np
import pytest

from fricid.fitted import FittedModel, OptimizerRecord, Parameter, is_not_determined
from fricid.identify import fit
from fricid.samples import FrictionSamples

NAN = float("nan")


def stribeck_samples(seed: int = 0) -> FrictionSamples:
    v = np.concatenate([np.geomspace(0.01, 2, 10), -np.geomspace(0.01, 2, 10)])
    f = 0.1 * np.sign(v) + 0.05 * np.sign(v) * np.exp(-((v / 0.1) ** 2)) + 0.03 * v
    f = f + 0.001 * np.random.default_rng(seed).standard_normal(v.size)
    return FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=f, source="s")


@pytest.fixture(scope="module")
def fitted() -> FittedModel:
    return fit(stribeck_samples(), "stribeck", fixed={"delta": 1.0})


def test_a_record_round_trips_through_its_dict():
    p = Parameter(
        "w_s",
        0.1,
        unit="rad/s",
        init=0.2,
        bounds=(0.001, 2.0),
        stderr=0.01,
        ci95=(0.08, 2.0),
        ci95_halfwidth=0.02,
        high_open=True,
        note="reaches the bound w_s <= 2 rad/s",
        at_bound=False,
    )
    back = Parameter.from_dict("w_s", json.loads(json.dumps(p.to_dict())))
    assert back == p and "name" not in p.to_dict()
    with pytest.raises(FrozenInstanceError):
        p.value = 1.0  # records are immutable: a writer builds a new one
    assert replace(p, value=0.2).at_initial_value and not p.at_initial_value


def test_a_record_with_only_a_value_takes_the_defaults():
    p = Parameter.from_dict("f_c", {"value": 1})
    assert p == Parameter("f_c", 1.0, not_determined=True)  # no standard error, no note
    assert isinstance(p.value, float) and not p.has_interval and math.isnan(p.stderr)
    assert not p.at_initial_value and p.init is None and p.bounds is None
    # the flag is the judgement of the fit, read as version 1 files were
    assert not Parameter.from_dict("f_c", {"value": 1}, converged=False).not_determined
    assert not Parameter.from_dict("f_c", {"value": 1, "fixed": True}).not_determined
    assert not Parameter.from_dict("f_c", {"value": 1, "not_determined": False}).not_determined


def test_not_determined():
    assert is_not_determined("not determined: no spare samples (n <= p)", NAN, True)
    assert is_not_determined("not identified: the interval spans the box", 0.1, True)
    assert is_not_determined("", NAN, None) and not is_not_determined("", NAN, False)
    assert not is_not_determined("", 0.1, True)
    assert not is_not_determined("no interval: the fit did not converge", NAN, False)


def test_the_optimiser_record_round_trips_and_is_stored_once(fitted, tmp_path):
    opt = fitted.optimizer
    assert opt.method == "lm" and opt.seed == 0 and opt.status == 0 and opt.nfev > 0
    assert opt.max_evals >= opt.nfev and opt.history[-1][0] <= opt.nfev
    assert OptimizerRecord.from_dict(json.loads(json.dumps(opt.to_dict()))) == opt
    assert OptimizerRecord.from_dict(None) == OptimizerRecord()
    d = fitted.to_dict()
    assert d["optimizer"] == json.loads(json.dumps(opt.to_dict()))
    assert not {"method", "seed", "nfev", "status", "message", "history"} & set(d)
    assert set(d["convergence"]) == {
        "converged",
        "polish_sse_ratio",
        "polish_nfev",
        "certified_by",
    }


def test_the_fit_writes_one_record_per_parameter(fitted):
    assert list(fitted.parameters) == ["tau_c", "tau_s", "w_s", "tau_v", "delta"]
    delta = fitted.parameters["delta"]
    assert delta.fixed and delta.value == 1.0 and delta.init is None and delta.bounds is None
    assert fitted.free == ("tau_c", "tau_s", "w_s", "tau_v") and fitted.fixed == ("delta",)
    for name in fitted.free:
        p = fitted.parameters[name]
        assert p.unit == fitted.friction_model().units[name] and p.init is not None
        assert p.bounds[0] <= p.ci95[0] <= p.value <= p.ci95[1] <= p.bounds[1]
        assert p.stderr > 0 and p.ci95_halfwidth > p.stderr  # t(0.975) > 1
    assert np.asarray(fitted.correlation).shape == (4, 4)


def test_the_views_are_read_only(fitted):
    assert fitted.params == {n: p.value for n, p in fitted.parameters.items()}
    assert fitted.units == {n: p.unit for n, p in fitted.parameters.items()}
    with pytest.raises(TypeError):
        fitted.params["tau_c"] = 0.0  # a writer changes the record, not the view
    with pytest.raises(AttributeError):
        fitted.params = {}


def test_the_file_holds_the_records(fitted, tmp_path):
    d = json.loads(fitted.save(tmp_path / "m.json").read_text())
    record = d["parameters"]["tau_c"]
    p = fitted.parameters["tau_c"]
    assert record["value"] == p.value and record["ci95"] == list(p.ci95)
    assert record["bounds"] == list(p.bounds) and record["stderr"] == p.stderr
    assert d["parameters"]["delta"]["stderr"] is None  # NaN is written as null
    back = FittedModel.load(tmp_path / "m.json")
    assert back.to_dict() == fitted.to_dict() and back.report() == fitted.report()


def test_from_values_makes_a_model_of_values_alone():
    m = FittedModel.from_values("coulomb_viscous", {"f_c": 0.1, "beta": 0.05}, {"f_c": "N m"})
    assert m.params == {"f_c": 0.1, "beta": 0.05} and m.units == {"f_c": "N m", "beta": ""}
    assert m.optimizer == OptimizerRecord() and m.fixed == () and m.at_bound == ()
    assert m.predict_point(1.0) == pytest.approx(0.15)


def test_near_zero_value_prints_its_absolute_error_only():
    p = Parameter("tau_v", 4.3e-24, unit="N m s/rad", stderr=3.6e-3, bounds=(0.0, 1.0))
    m = FittedModel(model="coulomb_viscous", parameters={"f_c": Parameter("f_c", 0.4), "beta": p})
    line = next(ln for ln in m.report().splitlines() if ln.strip().startswith("beta"))
    assert "+/- 0.0036" in line and "%" not in line, line
    q = replace(p, value=0.5)
    m = FittedModel(model="coulomb_viscous", parameters={"f_c": Parameter("f_c", 0.4), "beta": q})
    line = next(ln for ln in m.report().splitlines() if ln.strip().startswith("beta"))
    assert "+/- 0.0036 (0.72%)" in line, line


def test_a_dimensionless_parameter_prints_no_unit():
    """A new user read "delta_pos:  4 1 +/- 19.5" (the unit "1" of a dimensionless exponent)
    as the digits of one number."""
    p = Parameter("delta", 4.0, unit="1", stderr=0.5, bounds=(0.2, 4.0))
    m = FittedModel(model="stribeck", parameters={"delta": p, "f_c": Parameter("f_c", 0.4)})
    line = next(ln for ln in m.report().splitlines() if ln.strip().startswith("delta"))
    assert re.match(r"^\s*delta:\s+4 \+/- 0\.5\b", line), line
