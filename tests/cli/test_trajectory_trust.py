"""A model identified from a trajectory ends with the trust verdict too: printed by ``fricid
fit --trajectory``, stored in the model file, and shown by ``fricid report`` (before, the
file's ``trust`` was null and neither printed one)."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from fricid.cli import app


@pytest.mark.slow  # simulate, fit and report through the command line: 4.4 s
def test_fit_trajectory_prints_stores_and_reports_the_verdict(tmp_path):
    log = tmp_path / "multisine.parquet"
    args = ["simulate", "--trajectory", "multisine", "--duration", "2", "-o", str(log), "-q"]
    assert CliRunner().invoke(app, args).exit_code == 0
    model = tmp_path / "m.json"
    res = CliRunner().invoke(
        app, ["fit", str(log), "--trajectory", "--model", "stribeck", "--out", str(model), "-q"]
    )
    assert res.exit_code == 0, res.output
    assert "[[Trust]]" in res.output and "Trust: " in res.output
    stored = json.loads(model.read_text())["trust"]
    assert stored and stored["level"] in ("yes", "with caveats", "no")
    # one log, no measured scatter: never an unqualified "yes"
    assert stored["level"] != "yes"
    out = tmp_path / "rep"
    res = CliRunner().invoke(app, ["report", str(model), str(log), "--out", str(out), "-q"])
    assert res.exit_code == 0, res.output
    assert "Trust: " in (out / "report.md").read_text()
