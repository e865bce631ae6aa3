"""``fricid robot design``: the design, its files and its printed promises."""

from __future__ import annotations

import json

import numpy as np
import yaml
from typer.testing import CliRunner

from fricid.cli import app
from fricid.cli.robot_design import parse_noise, parse_workspace

runner = CliRunner()

#: A quick design of the double pendulum.
QUICK = [
    "--robot",
    "double_pendulum",
    "--harmonics",
    "2",
    "--max-evaluations",
    "150",
    "--starts",
    "2",
    "--duration",
    "10",
    "--rate",
    "50",
    "--yaml-rate",
    "10",
    "--quiet",
]


def test_design_writes_the_files_and_prints_the_errors(tmp_path):
    out, csv, ros = tmp_path / "d.json", tmp_path / "t.csv", tmp_path / "t.yaml"
    res = runner.invoke(
        app,
        [
            "robot",
            "design",
            *QUICK,
            "--out",
            str(out),
            "--csv",
            str(csv),
            "--ros-yaml",
            str(ros),
            "--workspace",
            "joint1=-1:1",
        ],
    )
    assert res.exit_code == 0, res.output
    assert "condition number" in res.output and "best random start" in res.output
    assert "predicted standard errors with torque noise 0.05 N m" in res.output
    assert "joint2:Fc+" in res.output
    # the pendulum's URDF has no limits: what is assumed is said, no effort fraction made up
    assert "no limit in the URDF, so assumed: position +-3.142 rad for joint1, joint2" in res.output
    assert "effort not checked for joint1, joint2" in res.output
    assert " no limit" in res.output and "effort 0.0" not in res.output
    doc = json.loads(out.read_text())
    assert doc["margins"]["effort"] == [None, None]
    assert doc["joints"] == ["joint1", "joint2"] and doc["periods"] == 1
    assert doc["locked"] == {}
    assert doc["limits"]["upper"][0] <= 1.0
    points = yaml.safe_load(ros.read_text())["points"]
    times = [p["time_from_start"]["sec"] + 1e-9 * p["time_from_start"]["nanosec"] for p in points]
    assert np.all(np.diff(times) > 0) and times[-1] <= 12.0  # 10 s and two 1 s ramps
    rows = [ln for ln in csv.read_text().splitlines() if not ln.startswith("#")]
    assert rows[0].startswith("time [s],joint1.position [rad]") and len(rows) == 12 * 50 + 2


def test_a_zero_width_workspace_is_one_line_and_no_file(tmp_path):
    out = tmp_path / "d.json"
    res = runner.invoke(
        app, ["robot", "design", *QUICK, "--out", str(out), "--workspace", "joint2=0.3:0.3"]
    )
    assert res.exit_code == 2
    assert "joint2" in res.output and "cannot move" in res.output
    assert "Traceback" not in res.output and not out.exists()


def test_parse_workspace():
    assert parse_workspace("a=-1:1, b=0:0.5") == {"a": (-1.0, 1.0), "b": (0.0, 0.5)}
    assert parse_workspace(None) == {}
    for bad in ("a=1", "a:1", "=0:1", "a=x:1"):
        try:
            parse_workspace(bad)
        except Exception as exc:
            assert type(exc).__name__ == "ConfigError"
        else:
            raise AssertionError(bad)


def test_parse_noise():
    np.testing.assert_array_equal(parse_noise("0.05", 3), [0.05, 0.05, 0.05])
    np.testing.assert_array_equal(parse_noise("0.1,0.2", 2), [0.1, 0.2])
    for bad in ("0.1,0.2", "x", "-1", "nan"):
        try:
            parse_noise(bad, 3)
        except Exception as exc:
            assert type(exc).__name__ == "ConfigError"
        else:
            raise AssertionError(bad)


def test_ramps_too_short_for_the_limits_are_lengthened(tmp_path):
    """A quintic from rest to full speed in 0.1 s asks for far more acceleration than the
    design allows: the ramps are lengthened until the played trajectory keeps its limits."""
    import re

    out = tmp_path / "d.json"
    res = runner.invoke(app, ["robot", "design", *QUICK, "--ramp", "0.1", "--out", str(out)])
    assert res.exit_code == 0, res.output
    said = re.search(
        r"ramps lengthened from 0.1 s: with them the peaks were .*acceleration "
        r"([\d.]+) %",
        res.output,
    )
    assert said and float(said.group(1)) > 100.0, res.output
    played = re.search(r"played: .* acceleration ([\d.]+) %", res.output)
    assert float(played.group(1)) <= 100.0
    assert json.loads(out.read_text())["ramp"] > 0.1
