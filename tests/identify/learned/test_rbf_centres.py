"""``fit --model rbf --centers 0`` (issue 25) showed scikit-learn's error with a traceback; the
number of centres is now checked before training: one ConfigError line, exit 2, no file."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import ConfigError
from fricid.identify import fit
from fricid.io import write_samples
from fricid.samples import FrictionSamples


def samples() -> FrictionSamples:
    v = np.concatenate([np.geomspace(0.01, 2, 15), -np.geomspace(0.01, 2, 15)])
    f = np.sign(v) * (0.2 + 0.1 * np.exp(-np.abs(v) / 0.05)) + 0.05 * v
    return FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=f, source="t")


@pytest.mark.parametrize("model", ["rbf", "hybrid"])
@pytest.mark.parametrize("centers", ["0", "-3"])
def test_cli_centers_below_one(tmp_path, model, centers):
    path = write_samples(samples(), tmp_path / "s.csv")
    out = tmp_path / "m.json"
    args = ["fit", str(path), "--model", model, "--centers", centers, "--out", str(out)]
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 2, res.output
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert len(lines) == 1 and "--centers" in lines[0] and f"got {centers}" in lines[0], lines
    assert "Traceback" not in res.output and not out.exists()


@pytest.mark.parametrize("centers", [0, -1, 2.5, True, "4"])
def test_api_centers_not_a_count(centers):
    with pytest.raises(ConfigError, match="whole number >= 1"):
        fit(samples(), "rbf", settings={"network": {"n_centers": centers}})
