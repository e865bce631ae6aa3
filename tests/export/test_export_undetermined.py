"""A trajectory model with a parameter the data do not determine is not exported unless the
user allows it, and then the exported file names it."""

from __future__ import annotations

import dataclasses

import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.export import ExportError, refuse_undetermined, undetermined_parameters
from fricid.fitted import FittedModel

runner = CliRunner()
#: The MuJoCo timestep check is tested in test_mujoco_step.py.
NO_CHECK = ("--no-timestep-check",)
LUGRE = dict(sigma_0=1e3, sigma_1=0.5, sigma_2=0.1, tau_c=0.3, tau_s=0.5, w_s=0.05, delta=2.0)
NOTE = "not identified: the 95 % interval spans the whole search range [0.001, 1000]"


def trajectory_model(undetermined: tuple[str, ...] = ("sigma_1",), **prov) -> FittedModel:
    """A LuGre model as a trajectory fit records it, ``undetermined`` marked so."""
    fitted = FittedModel.from_values(
        "lugre",
        LUGRE,
        operating_range={"velocity": [-2.0, 2.0]},
        provenance={"trajectory": {"route": "filtered"}, **prov},
    )
    for name in undetermined:
        fitted.parameters[name] = dataclasses.replace(
            fitted.parameters[name], note=NOTE, not_determined=True
        )
    return fitted


def test_only_a_trajectory_models_undetermined_parameters_count():
    assert undetermined_parameters(trajectory_model(("sigma_1", "sigma_0"))) == [
        "sigma_0",
        "sigma_1",
    ]
    assert undetermined_parameters(trajectory_model(())) == []
    static = trajectory_model()
    static.provenance = {}  # not from a trajectory: the static path's own rules apply
    assert undetermined_parameters(static) == []
    with pytest.raises(ExportError, match=r"does not determine sigma_1 of the 'lugre'"):
        refuse_undetermined(trajectory_model(), allow=False)
    refuse_undetermined(trajectory_model(), allow=True)


def test_cli_refuses_then_names_an_undetermined_parameter(tmp_path):
    path = tmp_path / "lugre.json"
    trajectory_model().save(path)
    assert FittedModel.load(path).parameters["sigma_1"].not_determined  # kept in the file
    out = tmp_path / "lugre.mjcf"
    res = runner.invoke(app, ["export", str(path), "--to", "mjcf", "-o", str(out)])
    assert res.exit_code == 2 and not out.exists()
    assert "--allow-undetermined" in " ".join(res.output.split())
    res = runner.invoke(
        app,
        ["export", str(path), "--to", "mjcf", "-o", str(out), "--allow-undetermined", *NO_CHECK],
    )
    assert res.exit_code == 0, res.output
    text = out.read_text()
    assert "NOT DETERMINED by the trajectory, exported as identified: sigma_1" in text
    determined = tmp_path / "determined.json"
    trajectory_model(()).save(determined)
    res = runner.invoke(
        app, ["export", str(determined), "--to", "mjcf", "-o", str(out), "--no-timestep-check"]
    )
    assert res.exit_code == 0 and "NOT DETERMINED" not in out.read_text()
