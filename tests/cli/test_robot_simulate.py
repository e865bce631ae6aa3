"""``fricid robot simulate``: a whole arm's log, its truth and its MJCF."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

pytest.importorskip("pinocchio")

from fricid.cli import app
from fricid.io import read_robot_log

runner = CliRunner()


def run(*args):
    return runner.invoke(app, ["robot", "simulate", *(str(a) for a in args)])


def test_writes_the_log_truth_and_mjcf(tmp_path):
    out, truth, mjcf = tmp_path / "arm.csv", tmp_path / "truth.json", tmp_path / "arm.xml"
    result = run(
        "--robot", "double_pendulum", "--duration", 0.5, "--seed", 3, "--encoder-counts", 4096,
        "--torque-noise", 0.02, "--out", out, "--truth", truth, "--mjcf", mjcf,
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    log = read_robot_log(out)
    assert log.joints == ("joint1", "joint2") and len(log) == 500
    steps = np.diff(log.position, axis=0) / (2 * np.pi / 4096)
    assert np.allclose(steps, np.round(steps), atol=1e-6)
    record = json.loads(truth.read_text())
    assert set(record["friction"]) == {"joint1", "joint2"}
    assert record["friction"]["joint1"]["tau_c_pos"] != record["friction"]["joint1"]["tau_c_neg"]
    assert record["torque_noise_std"] == [0.02, 0.02]
    mujoco = pytest.importorskip("mujoco")
    assert mujoco.MjModel.from_xml_path(str(mjcf)).njnt == 2


def test_sweeps_of_one_joint(tmp_path):
    out = tmp_path / "sweep.parquet"
    result = run(
        "--robot", "double_pendulum", "--sweep", "joint2", "--velocities", "0.5,1",
        "--duration", 2, "--out", out, "--friction", "none", "--controller", "torque",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    log = read_robot_log(out)
    assert np.ptp(log.position[:, 0]) < 1e-3 < np.ptp(log.position[:, 1])


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--robot", "nope"), "no example robot"),
        (("--robot", "panda", "--urdf", "x.urdf"), "not both"),
        (("--robot", "double_pendulum", "--sweep", "elbow"), "no joint 'elbow'"),
        (("--robot", "double_pendulum", "--friction", "lugre"), "--friction"),
        (("--robot", "double_pendulum", "--controller", "p"), "controller"),
        (("--robot", "double_pendulum", "--duration", -1), "--duration"),
        (("--robot", "double_pendulum", "--integrator-step", 1), "--integrator-step"),
    ],
)
def test_bad_options_are_one_line_and_no_file(tmp_path, args, message):
    out = tmp_path / "log.csv"
    result = run("--duration", 0.2, *args, "--out", out)
    assert result.exit_code == 2
    assert message in result.output and "Traceback" not in result.output
    assert not out.exists()
    bad = run("--robot", "double_pendulum", "--duration", 0.2, "--out", tmp_path / "log.txt")
    assert bad.exit_code == 2 and ".csv" in bad.output


def test_the_integrator_step_is_the_one_taken(tmp_path):
    """The chatter warning's advice can be followed from the command line."""
    out, truth = tmp_path / "arm.csv", tmp_path / "truth.json"
    result = run(
        "--robot", "double_pendulum", "--duration", 0.2, "--integrator-step", 1.25e-4,
        "--out", out, "--truth", truth,
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    record = json.loads(truth.read_text())
    assert record["integrator_step_s"] == pytest.approx(1.25e-4)
    assert record["friction_model"] == "stribeck_asym"  # every joint's


def test_a_lugre_joint(tmp_path):
    out, truth, mjcf = tmp_path / "arm.csv", tmp_path / "truth.json", tmp_path / "arm.xml"
    result = run(
        "--robot", "double_pendulum", "--duration", 0.3, "--lugre", "joint2",
        "--out", out, "--truth", truth, "--mjcf", mjcf,
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    record = json.loads(truth.read_text())
    assert record["friction_models"] == {"joint1": "stribeck_asym", "joint2": "lugre"}
    assert record["friction_model"] == "per joint"  # was "stribeck_asym" whatever the joints
    assert set(record["friction"]["joint2"]) >= {"sigma_0", "sigma_1", "sigma_2"}
    assert "joint2: LuGre friction" in mjcf.read_text()
    bad = run("--robot", "double_pendulum", "--duration", 0.2, "--lugre", "elbow", "--out", out)
    assert bad.exit_code == 2 and "--lugre" in bad.output


def test_a_sweep_runs_its_whole_plan_unless_cut_short(tmp_path):
    """Without --duration the sweeps run every speed both ways; a shorter --duration is warned
    of with the speeds it still holds (60 s held none of the five default speeds both ways)."""
    from fricid.cli.robot_simulate import _duration, _model, _reference

    model = _model("double_pendulum", None, None)
    reference = _reference(model, "joint1", "0.5,1", 5, 0.1, 0)
    assert _duration(reference, None) == reference.duration > 6
    out = tmp_path / "short.parquet"
    result = run(
        "--robot", "double_pendulum", "--sweep", "joint1", "--velocities", "1,0.5",
        "--duration", 6, "--out", out, "--friction", "none", "--controller", "torque",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    message = " ".join(result.output.split())
    assert "cuts the sweeps short" in message and "both directions of 1 rad/s only" in message
