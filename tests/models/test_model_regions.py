"""Each family's valid region (issue 25): a model file whose parameter lies outside it (w_s = 0,
w_s < 0, delta < 0, a negative Coulomb or viscous level, ...) is refused at load in one line
naming the file and the parameter, so it never reaches an export (the C export of w_s = 0
gave 0.000494 N m at 0.001 rad/s where the valid model gives 0.2557). A fit cannot end there
either: a fixed value or a search bound outside the region is a ConfigError."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import ConfigError, DataError
from fricid.fitted import FittedModel, OptimizerRecord
from fricid.identify import fit
from fricid.models import Parameter, get_model
from fricid.models.hybrid import backbone_of

#: Every family a model file may name with a parameter vector: analytic, per direction, with a
#: temperature law, both, and the dynamic models.
FAMILIES = (
    "coulomb_viscous",
    "stribeck",
    "msk",
    "vlt",
    "stribeck_asym",
    "vlt_asym",
    "msk_temp",
    "coulomb_viscous_temp_asym",
    "lugre",
    "dahl",
)
RANGE = {"velocity": [-1.0, 1.0], "load": [-0.5, 0.5], "temperature": [5.0, 45.0]}


def model_file(tmp_path, family: str, **change: float):
    """A model file of ``family`` at its default parameters, with ``change`` applied."""
    model = get_model(family)
    params = dict(zip(model.param_names, model.defaults().tolist(), strict=True))
    params.update(change)
    fitted = FittedModel.from_values(
        family, params, operating_range=RANGE, optimizer=OptimizerRecord(method="test")
    )
    path = tmp_path / f"{family}.json"
    path.write_text(json.dumps(fitted.to_dict()))
    return path


#: The regions each family declares, "> 0" or ">= 0" (the parameters absent here: any value).
EXPECTED = {
    "coulomb_viscous": {"f_c": ">=", "beta": ">="},
    "stribeck": {"tau_c": ">=", "tau_s": ">=", "w_s": ">", "tau_v": ">=", "delta": ">"},
    "msk": {
        **{name: ">=" for name in ("f_c", "f_s", "f_ck", "f_sk", "beta")},
        **{"v_s": ">", "xi": ">"},
    },
    "vlt": {
        **{name: ">=" for name in ("f_c", "f_ctl", "f_stl", "f_v0")},
        **{"v_tl0": ">", "v_v0": ">"},
    },
    "lugre": {
        **{name: ">=" for name in ("sigma_1", "sigma_2", "tau_c", "tau_s")},
        **{"sigma_0": ">", "w_s": ">", "delta": ">"},
    },
    "dahl": {"sigma_0": ">", "tau_c": ">", "alpha": ">", "sigma_2": ">="},
}


def expected(family: str) -> dict[str, str]:
    """The regions of a family's parameters, per direction for ``_asym``."""
    base = family.removesuffix("_asym").removesuffix("_temp")
    table = EXPECTED[base]
    if family.endswith("_asym"):
        return {f"{k}{s}": v for s in ("_pos", "_neg") for k, v in table.items()}
    return table


#: Values outside each kind of region.
OUTSIDE = {">": [0.0, -0.1, -1e-300], ">=": [-1e-9, -2.0]}

CASES = [
    (family, name, value)
    for family in FAMILIES
    for name, region in expected(family).items()
    for value in OUTSIDE[region]
]


def test_the_defaults_load(tmp_path):
    for family in FAMILIES:
        assert FittedModel.load(model_file(tmp_path, family)).model == family


@pytest.mark.parametrize(("family", "name", "value"), CASES)
def test_a_parameter_outside_its_region_is_refused_at_load(tmp_path, family, name, value):
    path = model_file(tmp_path, family, **{name: value})
    with pytest.raises(DataError) as info:
        FittedModel.load(path)
    message = str(info.value)
    assert message.startswith(str(path)) and "\n" not in message
    assert f"field 'parameters/{name}/value'" in message and "valid region" in message


@pytest.mark.parametrize(
    ("name", "value", "rule"),
    [("w_s", 0.0, "w_s > 0"), ("w_s", -0.066, "w_s > 0"), ("delta", -1.0, "delta > 0")],
)
@pytest.mark.parametrize("target", ["c", "urdf", "mjcf", "yaml"])
def test_no_export_of_an_invalid_model(tmp_path, name, value, rule, target):
    """The issue's files: each exported to all four targets, exit 0; now exit 2, one line,
    nothing written."""
    path = model_file(tmp_path, "stribeck", **{name: value})
    out = tmp_path / "out"
    out.mkdir()
    dest = out if target == "c" else out / f"friction.{target}"
    res = CliRunner().invoke(app, ["export", str(path), "--to", target, "-o", str(dest)])
    assert res.exit_code == 2, res.output
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert len(lines) == 1 and path.name in lines[0] and rule in lines[0], res.output
    assert not any(out.iterdir())


def test_the_declared_regions():
    for family in FAMILIES:
        model = get_model(family)
        declared = {p.name: p.region for p in model.parameters}
        want = {k: {">": "positive", ">=": "nonnegative"}[v] for k, v in expected(family).items()}
        assert {k: v for k, v in declared.items() if v != "any"} == want, family


def test_the_region_edges():
    """The region's edge: a Coulomb level or viscous coefficient of exactly 0 is valid."""
    model = get_model("stribeck")
    theta = model.param_vector({"tau_c": 0.0, "tau_s": 0.0, "w_s": 1e-6, "tau_v": 0.0, "delta": 1})
    assert model.region_violation(theta) is None
    bad = model.region_violation(np.array([0.1, 0.2, 0.0, 0.0, 1.0]))
    assert bad is not None and bad[0].name == "w_s" and bad[1] == 0.0


def test_a_family_declares_bounds_inside_its_region():
    with pytest.raises(ConfigError, match="leave its valid region w_s > 0"):
        Parameter("w_s", "rad/s", "velocity", 0.1, 0.0, 1.0, "Stribeck velocity", "positive")
    with pytest.raises(ConfigError, match="unknown region"):
        Parameter("x", "1", "one", 0.0, 0.0, 1.0, "", "sometimes")
    for family in FAMILIES:
        model = get_model(family)
        for p in model.parameters:
            assert p.admits(p.lower) and p.admits(p.upper) and p.admits(p.default), (family, p)


def _samples():
    from fricid.samples import FrictionSamples

    v = np.concatenate([np.geomspace(0.01, 1, 10), -np.geomspace(0.01, 1, 10)])
    f = np.sign(v) * (0.2 + 0.1 * np.exp(-np.abs(v) / 0.05)) + 0.05 * v
    return FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=f, source="t")


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"fixed": {"delta": -1.0}}, "'delta' fixed at -1.0, outside its valid region (delta > 0)"),
        ({"fixed": {"w_s": 0.0}}, "'w_s' fixed at 0.0"),
        ({"bounds": {"tau_v": (-1.0, 1.0)}}, "'tau_v' bounded below by -1.0"),
        ({"bounds": {"w_s": (0.0, 1.0)}}, "'w_s' bounded below by 0.0"),
    ],
)
def test_a_fit_cannot_leave_the_region(kwargs, words):
    with pytest.raises(ConfigError, match=words.replace("(", r"\(").replace(")", r"\)")):
        fit(_samples(), "stribeck", **kwargs)


def test_the_cli_refuses_a_bound_outside_the_region(tmp_path):
    from fricid.io import write_samples

    path = write_samples(_samples(), tmp_path / "s.csv")
    out = tmp_path / "m.json"
    args = ["fit", str(path), "--model", "stribeck", "--bound", "tau_v=-1:1", "--out", str(out)]
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 2 and "tau_v >= 0" in res.output, res.output
    assert not out.exists()


def test_a_hybrid_backbone_outside_its_region():
    state = {"backbone": {"model": "stribeck", "params": {"tau_c": 0.1, "tau_s": 0.2}}}
    state["backbone"]["params"].update(w_s=-0.05, tau_v=0.01, delta=1.0)
    with pytest.raises(DataError, match="w_s > 0") as info:
        backbone_of(state)
    assert info.value.column == "state.backbone.params.w_s"
