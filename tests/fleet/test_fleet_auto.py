"""A fleet row with ``model=auto`` selects the family as ``fricid fit --model auto`` does, and
its results row carries the same family, held-out ratio and verdict as that command's model."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import scipy.io
from typer.testing import CliRunner

from fricid.cli import app
from fricid.fitted import FittedModel
from fricid.fleet import SerialExecutor, run_fleet
from fricid.io import write_samples
from fricid.samples import FrictionSamples


def _samples() -> FrictionSamples:
    rng = np.random.default_rng(4)
    speed = np.geomspace(0.05, 3.0, 12)
    v = np.r_[-speed, speed]
    law = 0.3 + 0.2 * np.exp(-((np.abs(v) / 0.2) ** 2)) + 0.1 * np.abs(v)
    return FrictionSamples(
        velocity=v,
        load=None,
        temperature=None,
        friction=np.sign(v) * law + rng.normal(0, 0.005, 24),
    )


def test_fleet_auto_row_matches_fit_auto(tmp_path: Path):
    s = _samples()
    scipy.io.savemat(tmp_path / "means.mat", {"v": s.velocity, "f": s.friction})
    write_samples(s, tmp_path / "samples.csv")
    (tmp_path / "fleet.csv").write_text(
        "robot,joint,log,reader,model,variables,units\n"
        'r,j1,means.mat,mat,auto,velocity=v;friction=f,"velocity=rad/s;friction=N m"\n',
        encoding="utf-8",
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_fleet(tmp_path / "fleet.csv", tmp_path / "out", executor=SerialExecutor())
        res = CliRunner().invoke(
            app,
            ["fit", str(tmp_path / "samples.csv"), "-m", "auto", "-o", str(tmp_path / "m.json")],
        )
    assert res.exit_code == 0, res.output
    row = run.table.iloc[0]
    assert row["status"] == "ok" and row["model"] == "auto"
    cli = FittedModel.load(tmp_path / "m.json")
    assert row["chosen"] == cli.model
    assert row["trust"] == cli.trust["level"]
    assert np.isclose(row["heldout_ratio"], cli.trust["heldout_ratio"], rtol=1e-6)
    written = pd.read_csv(tmp_path / "out" / "results.csv")
    assert written.loc[0, "chosen"] == cli.model
