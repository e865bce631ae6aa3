"""Samples with velocity and friction only (issue 13): load and temperature not measured."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import ConfigError, DataError
from fricid.identify import fit
from fricid.io import read_samples, write_samples
from fricid.samples import FrictionSamples


def _two_column(path):
    half = np.array([0.05, 0.1, 0.2, 0.3, 0.5, 0.8, 1.2, 2.0])
    v = np.concatenate([-half[::-1], half])
    f = np.sign(v) * (0.3 + 0.2 * np.exp(-np.abs(v) / 0.2)) + 0.05 * v
    lines = ["velocity [rad/s],friction [N m]"] + [
        f"{a:.6g},{b:.6g}" for a, b in zip(v, f, strict=True)
    ]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_two_column_table_reads_with_load_and_temperature_not_measured(tmp_path):
    samples = read_samples(_two_column(tmp_path / "vf.csv"))
    assert samples.measured == ("velocity",)
    assert np.isnan(samples.load).all() and np.isnan(samples.temperature).all()
    out = write_samples(samples, tmp_path / "again.csv")
    header = next(line for line in out.read_text().splitlines() if not line.startswith("#"))
    assert "load" not in header and "temperature" not in header
    assert read_samples(out).measured == ("velocity",)


def test_partly_missing_load_is_still_an_error():
    with pytest.raises(DataError, match="non-finite") as err:
        FrictionSamples(velocity=[1.0, 2.0], load=[np.nan, 1.0], temperature=25, friction=[1, 2])
    assert err.value.column == "load"


def test_models_that_need_an_input_not_measured_say_so(tmp_path):
    samples = read_samples(_two_column(tmp_path / "vf.csv"))
    with pytest.raises(ConfigError, match=r"model 'vlt' needs .* have no load \(not measured\)"):
        fit(samples, "vlt")
    with pytest.raises(ConfigError, match=r"model 'msk' .* no load"):
        fit(samples, "msk")
    with pytest.raises(ConfigError, match=r"'rbf' .* no load"):
        fit(samples, "rbf", seed=0, settings={"inputs": ("velocity", "load")})
    # issue 15: by default the network takes the measured inputs (it was an error)
    assert fit(samples, "rbf", seed=0).state["inputs"] == ["velocity"]
    fitted = fit(samples, "stribeck")
    assert set(fitted.operating_range) == {"velocity"}
    assert np.isfinite(list(fitted.params.values())).all()


@pytest.mark.slow  # 1.2 s, quiet machine (the default run kept under 3 minutes)
def test_cli_fits_a_two_column_table(tmp_path):
    path = _two_column(tmp_path / "vf.csv")
    model = tmp_path / "m.json"
    result = CliRunner().invoke(app, ["fit", str(path), "--model", "stribeck", "-o", str(model)])
    assert result.exit_code == 0, result.output
    assert json.loads(model.read_text())["model"] == "stribeck"
    result = CliRunner().invoke(app, ["fit", str(path), "--model", "vlt", "-o", str(model)])
    assert result.exit_code == 2 and "no load (not measured)" in result.output
