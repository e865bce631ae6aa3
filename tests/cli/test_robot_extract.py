"""``fricid robot extract``: a robot log of sweeps to one samples file per joint and the
gravity parameters, with a table per joint."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from typer.testing import CliRunner

pytest.importorskip("pinocchio")

from _arm_sweeps import Law, arm_sweeps
from fricid.cli import app
from fricid.io import read_samples, write_robot_log
from fricid.robot import RigidBodyModel, example_urdf

runner = CliRunner()
LAWS = {"joint1": Law(0.10, 0.08, 0.05, 0.04), "joint2": Law(0.06, 0.07, 0.03, 0.035)}


@pytest.fixture(scope="module")
def pendulum_files(tmp_path_factory):
    """The double pendulum's sweeps as a wide CSV, and a URDF whose masses are 10-20 % off."""
    import xml.etree.ElementTree as ET

    path, joints = example_urdf("double_pendulum")
    truth = RigidBodyModel.from_urdf(path, joints)
    poses = {
        "joint1": [np.array([0.0, q]) for q in (-0.9, 0.0, 0.9)],
        "joint2": [np.array([q, 0.0]) for q in (-0.9, 0.0, 0.9)],
    }
    spans = {"joint1": (-1.2, 1.2), "joint2": (-1.2, 1.2)}
    log = arm_sweeps(truth, spans, poses, LAWS, rate=50.0, seed=2)
    folder = tmp_path_factory.mktemp("robot_extract")
    log_path = write_robot_log(log, folder / "sweeps.csv")
    tree = ET.parse(path)
    for mass in tree.getroot().iter("mass"):
        mass.set("value", repr(float(mass.get("value")) * 1.15))
    urdf = folder / "pendulum.urdf"
    tree.write(urdf)
    return log_path, urdf, folder


def test_robot_extract_writes_samples_per_joint_and_gravity(pendulum_files):
    log_path, urdf, folder = pendulum_files
    out = folder / "out"
    res = runner.invoke(
        app, ["robot", "extract", str(log_path), "--urdf", str(urdf), "-o", str(out)]
    )
    assert res.exit_code == 0, res.output
    # a table per joint (its set-points), then a row per joint
    assert "joint1: 6 set-points" in res.stdout and "joint2: 6 set-points" in res.stdout
    assert "base gravity parameters (identified from the sweeps" in res.stdout
    assert "nan" not in res.stdout  # an undetermined parameter says so, not "+- nan"
    doc = json.loads((out / "gravity.json").read_text(encoding="utf-8"))
    assert doc["method"] == "arm" and doc["identified"] is True
    assert set(doc["files"]) == {"joint1", "joint2"}
    for joint, law in LAWS.items():
        samples = read_samples(out / doc["files"][joint])
        err = samples.friction - law(samples.velocity)
        # measured: 0.0004 / 0.0005 N m RMS (friction 0.11 / 0.08 N m RMS)
        assert np.sqrt(np.mean(err**2)) < 0.003, (joint, err)


def test_the_printed_set_points_are_the_samples_written(pendulum_files):
    """Each joint's printed table lists exactly the rows of its samples file: velocity,
    friction, load and samples as written (the arm fit's levels, one per row)."""
    log_path, urdf, folder = pendulum_files
    out = folder / "table"
    res = runner.invoke(
        app, ["robot", "extract", str(log_path), "--urdf", str(urdf), "-o", str(out)]
    )
    assert res.exit_code == 0, res.output
    lines = res.stdout.splitlines()
    for joint in LAWS:
        start = next(i for i, line in enumerate(lines) if line.startswith(f"{joint}:")) + 2
        printed = [line.split() for line in lines[start : start + 6]]
        samples = read_samples(out / f"{joint}.csv")
        order = np.lexsort((samples.velocity, samples.temperature))
        for cells, i in zip(printed, order, strict=True):
            v, f, se, load, passes, count = (float(c) for c in cells[1:])
            assert v == pytest.approx(samples.velocity[i], rel=1e-3)
            assert f == pytest.approx(samples.friction[i], rel=1e-4)
            assert load == pytest.approx(samples.load[i], rel=1e-3, abs=1e-4)
            assert count == samples.count[i] and se > 0 and passes >= 1


def test_an_example_robot_stands_for_its_urdf(pendulum_files):
    """--robot names an example robot's URDF as robot fit's does; neither or both is one line."""
    log_path, urdf, folder = pendulum_files
    out = folder / "example"
    res = runner.invoke(
        app, ["robot", "extract", str(log_path), "--robot", "double_pendulum", "-o", str(out)]
    )
    assert res.exit_code == 0, res.output
    assert json.loads((out / "gravity.json").read_text())["urdf"] == "double_pendulum.urdf"
    for extra in ([], ["--robot", "double_pendulum", "--urdf", str(urdf)]):
        res = runner.invoke(app, ["robot", "extract", str(log_path), *extra])
        assert res.exit_code == 2 and "--urdf" in res.output and "Traceback" not in res.output


def test_robot_extract_bad_joint_is_one_line(pendulum_files):
    log_path, urdf, folder = pendulum_files
    out = folder / "bad"
    res = runner.invoke(
        app,
        [
            "robot",
            "extract",
            str(log_path),
            "--urdf",
            str(urdf),
            "--joints",
            "elbow",
            "-o",
            str(out),
        ],
    )
    assert res.exit_code == 2
    assert "elbow" in res.output and "Traceback" not in res.output
    assert not out.exists()


def test_robot_extract_urdf_masses_keeps_the_urdf(pendulum_files):
    """--urdf-masses: the gravity of the URDF (masses 15 % high here) is removed as it is,
    and its error stays in the friction."""
    log_path, urdf, folder = pendulum_files
    out = folder / "urdf_masses"
    args = ["robot", "extract", str(log_path), "--urdf", str(urdf), "--urdf-masses"]
    res = runner.invoke(app, [*args, "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert "the URDF's (not identified)" in res.stdout
    doc = json.loads((out / "gravity.json").read_text(encoding="utf-8"))
    assert doc["identified"] is False
    samples = read_samples(out / doc["files"]["joint2"])
    err = samples.friction - LAWS["joint2"](samples.velocity)
    # measured: 0.025 N m RMS, a third of the friction 0.081 N m (0.0005 when identified)
    assert np.sqrt(np.mean(err**2)) > 0.01


def test_a_log_without_temperature_names_the_option(pendulum_files, tmp_path):
    """Sweeps without a temperature channel: the error names the command's --temperature
    (a command-line user gets the option, not only the Python argument)."""
    from fricid.io import read_robot_log

    log_path, urdf, _ = pendulum_files
    bare = replace(read_robot_log(log_path), temperature=None, source="bare")
    path = write_robot_log(bare, tmp_path / "bare.csv")
    res = runner.invoke(app, ["robot", "extract", str(path), "--urdf", str(urdf)])
    assert res.exit_code == 2, res.output
    assert "has no temperature" in res.output and "--temperature" in res.output


def test_runs_left_out_of_the_set_points_are_listed_with_their_speeds():
    """A requested speed missing from a joint's table (a stick-slip run, no steady plateau)
    shows under it: the kind, what it means and the speed; flagged set-points too."""
    from fricid.cli.robot_extract import _not_averaged
    from fricid.extract import extract_arm

    path, joints = example_urdf("double_pendulum")
    truth = RigidBodyModel.from_urdf(path, joints)
    poses = {"joint2": [np.array([q, 0.0]) for q in (-0.9, 0.0, 0.9)]}
    log = arm_sweeps(truth, {"joint2": (-1.2, 1.2)}, poses, {"joint2": LAWS["joint2"]}, rate=50.0)
    q = extract_arm(log, truth)["joint2"].quality
    assert _not_averaged(q) == []  # every run averaged, nothing flagged
    kind, flagged, velocity = q.kind.copy(), q.flagged.copy(), q.velocity.copy()
    first, second = np.flatnonzero(q.setpoints)[:2]
    kind[first], velocity[first] = "unsteady", -0.2
    flagged[second] = True
    lines = _not_averaged(replace(q, kind=kind, flagged=flagged, velocity=velocity))
    assert lines[0].startswith("  not averaged: 1 unsteady run(s) (no steady plateau")
    assert lines[0].endswith("at -0.2 rad/s")
    assert lines[1].startswith("  flagged (scatter far above their neighbours): ")


def test_one_recording_per_joint_is_read_as_one_log(pendulum_files, tmp_path):
    """Joint 1's sweeps in one file and joint 2's in another: both joints' samples, the
    gravity identified once from both, the files named in gravity.json; a file at another
    rate is refused with both rates and its name."""
    from fricid.io import read_robot_log

    log_path, urdf, _ = pendulum_files
    whole = read_robot_log(log_path)
    half = int(np.flatnonzero(whole.velocity[:, 1] != 0)[0]) - 1  # joint 2's sweeps begin
    first = write_robot_log(whole.slice(0, half), tmp_path / "joint1.csv")
    second = write_robot_log(whole.slice(half, len(whole)), tmp_path / "joint2.csv")
    out = tmp_path / "out"
    args = ["robot", "extract", str(first), str(second), "--urdf", str(urdf), "-o", str(out)]
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    assert "joint1: 6 set-points" in res.stdout and "joint2: 6 set-points" in res.stdout
    doc = json.loads((out / "gravity.json").read_text(encoding="utf-8"))
    assert doc["log"] == "joint1.csv + joint2.csv"
    for joint, law in LAWS.items():
        samples = read_samples(out / doc["files"][joint])
        err = samples.friction - law(samples.velocity)
        assert np.sqrt(np.mean(err**2)) < 0.003, (joint, err)
    fast = whole.slice(half, len(whole))
    fast = replace(fast, time=fast.time[0] + (fast.time - fast.time[0]) / 2)
    other = write_robot_log(fast, tmp_path / "fast.csv")
    res = runner.invoke(app, [*args[:3], str(other), *args[4:-1], str(tmp_path / "no")])
    assert res.exit_code == 2, res.output
    assert "fast.csv: sampled at 100 Hz" in res.output and "at 50 Hz" in res.output
    assert not (tmp_path / "no").exists()


def test_temperature_is_for_the_recordings_without_one(pendulum_files, tmp_path):
    """One recording with a temperature column, one without: --temperature is recorded for
    the one without (the table reader had refused the first: "temperature= was given")."""
    from fricid.io import read_robot_log

    log_path, urdf, _ = pendulum_files
    whole = read_robot_log(log_path)
    half = int(np.flatnonzero(whole.velocity[:, 1] != 0)[0]) - 1
    first = write_robot_log(whole.slice(0, half), tmp_path / "with.csv")
    bare = replace(whole.slice(half, len(whole)), temperature=None)
    second = write_robot_log(bare, tmp_path / "without.csv")
    out = tmp_path / "out"
    args = ["robot", "extract", str(first), str(second), "--urdf", str(urdf)]
    res = runner.invoke(app, [*args, "--temperature", "25", "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert "joint1: 6 set-points" in res.stdout and "joint2: 6 set-points" in res.stdout


def test_numbered_columns_are_the_urdf_s_moving_joints_in_order(pendulum_files, tmp_path):
    """A table of q1, dq1, tau1, q2, ... (as --help offers) with --urdf: joint 1 is the
    URDF's first moving joint (before: "no joint of the log (1, 2) is a moving joint")."""
    import pandas as pd

    from fricid.io import read_robot_log

    log_path, urdf, _ = pendulum_files
    log = read_robot_log(log_path)
    table = {"time [s]": log.time, "temperature [degC]": log.temperature[:, 0]}
    for k in range(2):
        table[f"q{k + 1} [rad]"] = log.position[:, k]
        table[f"dq{k + 1} [rad/s]"] = log.velocity[:, k]
        table[f"tau{k + 1} [N m]"] = log.torque[:, k]
    path = tmp_path / "numbered.csv"
    pd.DataFrame(table).to_csv(path, index=False)
    res = runner.invoke(
        app, ["robot", "extract", str(path), "--urdf", str(urdf), "-o", str(tmp_path / "o")]
    )
    assert res.exit_code == 0, res.output
    assert "read as the URDF's moving joints in order: joint1, joint2" in res.output
    assert "joint1: 6 set-points" in res.stdout and "joint2: 6 set-points" in res.stdout
