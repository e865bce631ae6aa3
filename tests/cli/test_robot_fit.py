"""``fricid robot fit``: a robot log file and a URDF in, the whole-arm fit file and a table out."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

pytest.importorskip("pinocchio")

from fricid.cli import app
from fricid.fitted.arm import ArmFit
from fricid.io import write_robot_log
from fricid.robot import RigidBodyModel, example_urdf

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "identify" / "dynamic"))
from _arm_truth import make_log, make_lugre_log

runner = CliRunner()

LAWS = [
    ("coulomb_viscous", {"f_c": 0.5, "beta": 0.3}),
    ("coulomb_viscous", {"f_c": 0.7, "beta": 0.2}),
]


@pytest.fixture(scope="module")
def pendulum_logs(tmp_path_factory):
    path, joints = example_urdf("double_pendulum")
    model = RigidBodyModel.from_urdf(path, joints)
    folder = tmp_path_factory.mktemp("arm")
    logs = []
    for seed in (3, 4):
        log = make_log(model, LAWS, duration=12.0, rate=250.0, seed=seed, noise=0.05)
        logs.append(write_robot_log(log, folder / f"log{seed}.csv"))
    return Path(path), logs


def test_robot_fit_writes_the_file_and_prints_a_row_per_joint(pendulum_logs, tmp_path):
    urdf, (log, second) = pendulum_logs
    out = tmp_path / "arm.json"
    fit_cv = ["robot", "fit", str(log), "--urdf", str(urdf), "--friction", "coulomb_viscous"]
    res = runner.invoke(app, [*fit_cv, "--validate", str(second), "-o", str(out)])
    assert res.exit_code == 0, res.output
    fit = ArmFit.load(out)
    assert fit.validation["joint1"]["source"] == "second log"
    assert fit.friction["joint2"]["parameters"]["f_c"]["value"] == pytest.approx(0.7, rel=0.03)
    for joint in ("joint1", "joint2"):
        assert joint in res.output
    assert "Base inertial parameters:" in res.output
    text = " ".join(res.output.split())
    if "consistent_ls" in fit.standard:  # in words, not a Python bool
        assert "least-squares estimate was" in text and "physical: True" not in text
    assert "IDIM-WLS" in res.output
    assert fit.provenance["reversal_window"] == 0.0
    assert fit.provenance["closed_loop"].startswith("not detected")  # decided from the data
    assert "Closed loop detected" not in res.output
    for flag, window, kind in (("--closed-loop", 1.0, "closed"), ("--open-loop", 0.0, "open")):
        told = tmp_path / f"{flag}.json"
        res = runner.invoke(app, [*fit_cv, flag, "-o", str(told)])
        assert res.exit_code == 0, res.output
        prov = ArmFit.load(told).provenance
        assert prov["reversal_window"] == window
        assert prov["closed_loop"] == f"given: {kind} loop"


def test_robot_fit_bad_option_is_one_line_and_no_file(pendulum_logs, tmp_path):
    urdf, (log, _) = pendulum_logs
    out = tmp_path / "arm.json"
    res = runner.invoke(
        app, ["robot", "fit", str(log), "--urdf", str(urdf), "--friction", "dahl", "-o", str(out)]
    )
    assert res.exit_code == 2
    assert "Traceback" not in res.output
    assert not out.exists()


@pytest.mark.slow
def test_a_log_that_cannot_tell_the_friction_gets_no(tmp_path):
    """The simulator's default double-pendulum log (20 s, seed 1) moves the joints too little
    for ten Stribeck parameters each: Coulomb levels come out +- 7 to 93 N m. That is a "no"
    with the reason, not "with caveats" (it was, before the Coulomb levels' width was judged)."""
    from fricid.robot import example_urdf

    urdf, _ = example_urdf("double_pendulum")
    log, out = tmp_path / "a.parquet", tmp_path / "arm.json"
    sim = ["robot", "simulate", "--robot", "double_pendulum", "--duration", "20"]
    assert runner.invoke(app, [*sim, "--seed", "1", "--out", str(log)]).exit_code == 0
    res = runner.invoke(app, ["robot", "fit", str(log), "--urdf", str(urdf), "-o", str(out)])
    assert res.exit_code == 0, res.output
    fit = ArmFit.load(out)
    for joint in fit.joints:
        assert fit.verdict(joint) == "no"
        assert "do not determine the joint's friction" in " ".join(fit.validation[joint]["reasons"])


def test_robot_fit_takes_an_example_robot_or_says_what_it_needs(pendulum_logs, tmp_path):
    _, (log, _) = pendulum_logs
    out = tmp_path / "arm.json"
    res = runner.invoke(app, ["robot", "fit", str(log), "-o", str(out)])
    assert res.exit_code == 2 and "give --urdf" in res.output and not out.exists()
    args = ["robot", "fit", str(log), "--robot", "double_pendulum", "--friction"]
    res = runner.invoke(app, [*args, "coulomb_viscous", "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert ArmFit.load(out).provenance["urdf"] == "double_pendulum.urdf"


@pytest.mark.slow  # about 15 s
def test_robot_fit_a_lugre_joint(tmp_path):
    """``--friction joint2=lugre``: the table shows the joint's LuGre row with its intervals
    (or why not), the file keeps the family and the second stage's record."""
    path, joints = example_urdf("double_pendulum")
    model = RigidBodyModel.from_urdf(path, joints)
    law = dict(sigma_0=1e4, sigma_1=2.0, sigma_2=0.3, tau_c=0.6, tau_s=0.9, w_s=0.08, delta=2.0)
    log = write_robot_log(
        make_lugre_log(model, LAWS, {1: law}, duration=20.0, seed=5), tmp_path / "lugre.csv"
    )
    out = tmp_path / "arm.json"
    args = ["robot", "fit", str(log), "--urdf", str(path), "--friction", "joint2=lugre"]
    res = runner.invoke(app, [*args, "-o", str(out)], terminal_width=250)
    assert res.exit_code == 0, res.output
    assert "lugre" in res.output and "sigma_0" in res.output
    fit = ArmFit.load(out)
    assert fit.friction["joint2"]["family"] == "lugre"
    assert fit.friction["joint1"]["family"] == "stribeck_asym"
    assert set(fit.provenance["lugre"]) == {"joint2"}
