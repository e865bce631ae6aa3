"""A whole robot as one fleet row (``urdf``): its joints identified together as ``fricid robot
fit`` does (:func:`fricid.workflow.run_robot`), a results row per joint, the whole-arm fit file
in the store; the manifest's robot columns are checked as strictly as the others."""

from __future__ import annotations

import math
import shutil
import textwrap
from pathlib import Path

import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import DataError
from fricid.fitted.arm import ArmFit
from fricid.fleet import SerialExecutor, read_manifest, read_results, run_fleet
from fricid.robot.examples import example_urdf
from fricid.workflow import run_robot

runner = CliRunner()


@pytest.fixture(scope="module")
def arm(tmp_path_factory) -> Path:
    """A folder with a 3 s log of the simulated double pendulum and its URDF."""
    folder = tmp_path_factory.mktemp("arm")
    log = folder / "logs" / "dp.parquet"
    log.parent.mkdir()
    res = runner.invoke(
        app,
        ["robot", "simulate", "--robot", "double_pendulum", "--duration", "3", "--rate", "400",
         "--base-frequency", "0.5", "--out", str(log)],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    urdf, _ = example_urdf("double_pendulum")
    shutil.copy(urdf, folder / "dp.urdf")
    return folder


def write(folder: Path, text: str, name: str = "fleet.yaml") -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def test_robot_row_gives_a_row_per_joint_and_the_arm_file(arm, tmp_path):
    manifest = write(
        arm,
        """\
        joints:
          - {robot: dp, log: logs/dp.parquet, urdf: dp.urdf, friction: coulomb_viscous_asym}
        """,
    )
    out = tmp_path / "out"
    run = run_fleet(manifest, out, executor=SerialExecutor(), date="2026-01-02")
    assert (run.computed, run.failed) == (1, 0)
    want = run_robot(arm / "logs" / "dp.parquet", arm / "dp.urdf", friction="coulomb_viscous_asym")
    table = read_results(out)
    assert list(table["joint"]) == list(want.joints)
    assert set(table["model"]) == {"arm"} and set(table["chosen"]) == {"coulomb_viscous_asym"}
    stored = ArmFit.load(out / "models" / "dp" / "arm.arm.json")
    assert set(table["model_file"]) == {"models/dp/arm.arm.json"}
    for _, row in table.iterrows():
        joint = row["joint"]
        # the same identification as the command's, nothing recomputed by the fleet
        assert row["trust"] == want.verdict(joint) == stored.verdict(joint)
        for name, rec in want.friction[joint]["parameters"].items():
            value = stored.friction[joint]["parameters"][name]["value"]
            assert value == rec["value"]
            want_value = math.nan if rec["value"] is None else rec["value"]  # not determined
            assert row[f"param_{name}"] == pytest.approx(want_value, nan_ok=True)
        ratio = want.validation[joint]["ratio"]
        expected = ratio if ratio is not None and math.isfinite(ratio) else math.nan
        assert row["heldout_ratio"] == pytest.approx(expected, nan_ok=True)
    # a second run finds the log, the URDF and the settings unchanged
    again = run_fleet(manifest, out, executor=SerialExecutor(), date="2026-01-02")
    assert (again.computed, again.skipped) == (0, 1)


def test_a_changed_urdf_changes_the_settings(arm, tmp_path):
    folder = tmp_path / "copy"
    folder.mkdir()
    shutil.copy(arm / "dp.urdf", folder / "dp.urdf")
    manifest = write(folder, "robot,log,urdf\ndp,dp.parquet,dp.urdf\n", "m.csv")
    before = read_manifest(manifest).joints[0].settings()
    urdf = folder / "dp.urdf"
    urdf.write_text(urdf.read_text(encoding="utf-8") + "\n", encoding="utf-8")
    after = read_manifest(manifest).joints[0].settings()
    assert before["urdf_hash"] != after["urdf_hash"]  # the robot runs again


def test_missing_urdf_fails_the_row_not_the_fleet(arm, tmp_path):
    manifest = write(
        arm,
        """\
        robot,joint,log,urdf
        dp,arm,logs/dp.parquet,missing.urdf
        """,
        "missing.csv",
    )
    run = run_fleet(manifest, tmp_path / "out", executor=SerialExecutor())
    assert run.failed == 1
    (row,) = run.table.to_dict("records")
    assert row["status"] == "failed" and "missing.urdf" in row["error"]


def test_robot_row_paths_and_defaults(arm):
    manifest = write(
        arm,
        """\
        defaults: {model: [stribeck], seed: 3}
        joints:
          - {robot: r1, joint: j0, log: logs/j0.parquet}
          - {robot: dp, log: logs/dp.parquet, urdf: dp.urdf, joints: [joint1, Joint2]}
        """,
        "mixed.yaml",
    )
    one, robot = read_manifest(manifest).joints
    assert not one.is_robot and one.seed == 3
    assert robot.is_robot and robot.joint == "arm" and robot.models == ("arm",)
    assert robot.urdf == arm / "dp.urdf"  # relative to the manifest, as the log
    assert robot.arm_joints == ("joint1", "Joint2")  # URDF names keep their case
    assert robot.friction == "stribeck_asym"
    assert robot.settings()["urdf_hash"] is not None


@pytest.mark.parametrize(
    ("row", "column", "words"),
    [
        ("dp,arm,logs/dp.parquet,dp.urdf,stribeck,", "model", "a robot row"),
        ("dp,j1,logs/dp.parquet,,,stribeck_asym", "friction", "give the row its 'urdf'"),
        ("dp,arm,logs/dp.parquet,dp.urdf,,dahl", "friction", "must be one of"),
    ],
)
def test_manifest_refuses_columns_of_the_other_kind_of_row(arm, row, column, words):
    manifest = write(arm, f"robot,joint,log,urdf,model,friction\n{row}\n", "bad.csv")
    with pytest.raises(DataError) as info:
        read_manifest(manifest)
    assert info.value.row == 2 and info.value.column == column
    assert words in str(info.value)


def test_drift_leaves_a_robots_joints_out_instead_of_failing():
    import pandas as pd

    from fricid.fleet import compare

    row = {"robot": "dp", "joint": "joint1", "model": "arm", "chosen": "coulomb_viscous",
           "status": "ok", "param_f_c": 0.2, "ci95_f_c": 0.01, "param_beta": 0.1,
           "ci95_beta": 0.01}  # fmt: skip
    before = pd.DataFrame([row])
    now = pd.DataFrame([{**row, "param_f_c": 0.5}])
    drift = compare(now, before)  # get_model("arm") would raise: no such family
    assert len(drift.joints) == 0
