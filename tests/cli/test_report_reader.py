"""``fricid report`` reads a trajectory log as ``fricid fit --trajectory`` does: a log without
a temperature column, fitted with ``--reader-option temperature=25``, could not be reported
(the reader asked for that option, which the report did not take)."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from tests._paths import REPO
from typer.testing import CliRunner

from fricid.cli import app

sys.path.insert(0, str(REPO / "benchmarks"))
from _encoder_truth import encoder_log


def _csv(path, seed):
    log = encoder_log(seed, 4096, seconds=8.0)
    table = np.column_stack([log.time, log.position, log.velocity, log.torque])
    header = "time [s],position [rad],velocity [rad/s],torque [N m]"
    np.savetxt(path, table, delimiter=",", fmt="%.10g", header=header, comments="")
    return path


@pytest.mark.slow  # a fit and two reports through the command line: about 5 s
def test_report_takes_the_reader_options_of_fit(tmp_path):
    log, held = _csv(tmp_path / "log.csv", 0), _csv(tmp_path / "held.csv", 1)
    model = tmp_path / "m.json"
    opt = ["--reader-option", "temperature=25"]
    args = ["fit", str(log), "--trajectory", "-m", "coulomb_viscous", "-o", str(model), "-q"]
    res = CliRunner().invoke(app, [*args, *opt])
    assert res.exit_code == 0, res.output
    out = tmp_path / "rep"
    res = CliRunner().invoke(app, ["report", str(model), str(log), str(held), "-o", str(out)])
    assert res.exit_code != 0 and "--reader-option temperature=25" in res.output
    res = CliRunner().invoke(app, ["report", str(model), str(log), str(held), "-o", str(out), *opt])
    assert res.exit_code == 0, res.output
    text = (out / "report.md").read_text()
    assert "where it slides" in text and "nan" not in res.output.lower()


def test_reader_options_are_refused_for_a_model_of_samples(tmp_path):
    from fricid.fitted import FittedModel

    model = tmp_path / "m.json"
    FittedModel.from_values("coulomb_viscous", {"f_c": 0.3, "beta": 0.1}).save(model)
    samples = tmp_path / "s.csv"
    samples.write_text("velocity [rad/s],friction [N m]\n0.1,0.31\n0.2,0.32\n")
    args = ["report", str(model), str(samples), "--reader-option", "temperature=25"]
    res = CliRunner().invoke(app, [*args, "-o", str(tmp_path / "r"), "-q"])
    assert res.exit_code != 0 and "fitted to friction samples" in res.output
