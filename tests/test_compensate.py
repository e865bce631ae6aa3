"""Friction compensation: the tracking simulation, its physics, and `fricid compensate`."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.control import (
    TrackingConfig,
    Truth,
    compensation_study,
    default_config,
    fitted_law,
    simulate_tracking,
)
from fricid.errors import ConfigError
from fricid.fitted import FittedModel
from fricid.models.smoothing import Smoothing
from fricid.sim import preset

runner = CliRunner()

#: A short, fast experiment: one period at 0.5 Hz, 0.2 ms steps (5000 steps).
FAST = {"frequency": 0.5, "periods": 1.0, "amplitude": 0.2, "dt": 2e-4}


def cv(f_c: float = 0.1, beta: float = 0.05) -> FittedModel:
    return FittedModel(
        model="coulomb_viscous",
        params={"f_c": f_c, "beta": beta},
        operating_range={"velocity": [0.01, 1.0], "load": [0, 0], "temperature": [25, 25]},
    )


def preset_truth(name: str) -> Truth:
    """The virtual joint of a simulation preset as the plant's truth (law and inertia)."""
    joint = preset(name, "quick").joint
    return Truth(joint.law, name, joint.inertia)


def paper2() -> FittedModel:
    names = ("tau_c", "tau_s", "w_s", "tau_v", "delta")
    theta = preset("paper2", "quick").joint.law.theta
    return FittedModel(
        model="stribeck",
        params=dict(zip(names, map(float, theta), strict=True)),
        operating_range={"velocity": [0.005, 4.0], "load": [0, 0], "temperature": [25, 25]},
    )


def test_without_friction_the_joint_follows_the_reference():
    r = compensation_study(cv(0.0, 0.0), TrackingConfig(**FAST))
    assert r.max["without"] < 1e-3 * FAST["amplitude"]
    assert r.rms["with"] == r.rms["without"]


def test_exact_coulomb_viscous_feedforward_removes_most_of_the_error():
    r = compensation_study(cv(), TrackingConfig(**FAST))
    assert r.rms["with"] < 0.2 * r.rms["without"]
    assert r.max["with"] < 0.5 * r.max["without"]
    assert r.improvement > 5


def test_pd_alone_lags_by_coulomb_over_kp():
    """While sliding slowly, PD control holds the Coulomb friction with an error F_c / K_p."""
    config = TrackingConfig(**FAST)
    r = compensation_study(cv(0.1, 0.0), config)
    kp, _ = config.gains
    t = r.runs["time"]
    steady = (t > 0.15) & (t < 0.35)  # mid-stroke, away from the reversal at t = 0.5 s
    np.testing.assert_allclose(r.runs["error"][0][steady], 0.1 / kp, rtol=0.1)


def test_joint_sticks_at_reversals():
    r = compensation_study(paper2(), TrackingConfig(**FAST))
    v = r.runs["velocity"][0]
    assert (v == 0.0).sum() > 50  # stuck for more than 10 ms at the reversals
    # stuck means the applied torque is within the break-away friction (0.64 N m)
    stays = (v[:-1] == 0.0) & (v[1:] == 0.0)
    assert np.all(np.abs(r.runs["torque"][0][:-1][stays]) <= 0.641 + 1e-9)


def test_virtual_joint_truth_and_the_model_agree_for_the_same_law():
    """paper2's true law is the Stribeck model with its Table 2 values: same result."""
    config = TrackingConfig(**FAST)
    a = compensation_study(paper2(), config)
    b = compensation_study(paper2(), config, truth=preset_truth("paper2"))
    np.testing.assert_allclose(b.rms["with"], a.rms["with"], rtol=1e-9)
    assert b.rms["with"] < b.rms["without"]


def test_mismatched_model_against_the_virtual_joint():
    """A plain Coulomb-viscous model still helps on the paper1 joint (gravity compensated)."""
    config = default_config(cv(0.2, 0.2), **FAST, load=0.18, temperature=25.0)
    r = compensation_study(cv(0.2, 0.2), config, truth=preset_truth("paper1"))
    assert r.rms["with"] < r.rms["without"]


def test_smoothed_feedforward_and_determinism():
    config = TrackingConfig(**FAST)
    a = compensation_study(paper2(), config, smoothing=Smoothing("tanh", 0.01))
    b = compensation_study(paper2(), config, smoothing=Smoothing("tanh", 0.01))
    assert a.rms == b.rms
    assert np.abs(a.feedforward).max() < 0.641


def test_batch_runs_are_independent():
    config = TrackingConfig(**FAST)
    law = fitted_law(cv())
    n = config.n_steps + 1
    ff = np.vstack([np.zeros(n), np.full(n, 0.01), np.zeros(n)])
    runs = simulate_tracking(law, ff, config)
    np.testing.assert_array_equal(runs["error"][0], runs["error"][2])
    assert not np.array_equal(runs["error"][0], runs["error"][1])


def test_bad_configuration():
    with pytest.raises(ConfigError, match="'dt' must be a number > 0"):
        TrackingConfig(dt=0.0)
    with pytest.raises(ConfigError, match="too many"):
        TrackingConfig(dt=1e-7, periods=10)
    with pytest.raises(ConfigError, match="'law' must be callable"):
        Truth("lugre")
    with pytest.raises(ConfigError, match="'inertia' must be a number > 0"):
        Truth(fitted_law(cv()), "cv", inertia=0.0)


def test_truth_comes_from_the_caller():
    """A law given by the caller is the plant: here friction twice the model's."""
    config = TrackingConfig(**FAST)
    law = fitted_law(cv())
    doubled = Truth(lambda v, load, t: 2.0 * law(v, load, t), "double", inertia=0.02)
    r = compensation_study(cv(), config, truth=doubled)
    exact = compensation_study(cv(), config)
    assert r.truth == "double" and r.config.inertia == 0.02
    assert any("inertia 0.02 kg m^2 from the 'double' joint" in n for n in r.notes)
    assert r.rms["with"] > exact.rms["with"]


def test_control_does_not_import_sim():
    """The simulation presets are the caller's business (DESIGN.md layers)."""
    import ast
    from pathlib import Path

    import fricid.control

    for path in Path(fricid.control.__file__).parent.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                assert not (node.module or "").startswith(("sim", "fricid.sim")), path


def test_default_config_stays_in_the_operating_range():
    config = default_config(paper2())
    peak = config.amplitude * 2 * np.pi * config.frequency
    assert peak == pytest.approx(2.0)  # half of the 4 rad/s identified


def test_compensate_command(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    model = cv().save(tmp_path / "cv.json")
    res = runner.invoke(
        app,
        [
            "compensate",
            str(model),
            "--frequency",
            "0.5",
            "--periods",
            "1",
            "--peak-velocity",
            "0.6",
        ],
    )
    assert res.exit_code == 0, res.output
    assert "PD + friction feed-forward" in res.stdout and "RMS error [mrad]" in res.stdout
    png = tmp_path / "cv.compensation.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    res = runner.invoke(
        app,
        [
            "compensate",
            str(model),
            "--frequency",
            "0.5",
            "--periods",
            "1",
            "--no-plot",
            "--json",
            "--truth",
            "paper2",
        ],
    )
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    assert doc["truth"] == "paper2" and set(doc["rms_error_rad"]) == {"without", "with"}


def test_compensate_command_errors(tmp_path):
    model = cv().save(tmp_path / "cv.json")
    res = runner.invoke(app, ["compensate", str(model), "--truth", "lugre", "--no-plot"])
    assert res.exit_code == 2 and "unknown truth 'lugre'" in res.output
    res = runner.invoke(app, ["compensate", str(model), "--dt", "-1", "--no-plot"])
    assert res.exit_code == 2 and "'dt' must be a number > 0" in res.output


def test_extrapolated_feedforward_is_noted():
    model = paper2()
    model.operating_range["velocity"] = [0.05, 4.0]
    r = compensation_study(model, TrackingConfig(**FAST))
    assert any("below the identified speeds (|v| < 0.05 rad/s)" in n for n in r.notes)
    r = compensation_study(model, TrackingConfig(**FAST), smoothing=Smoothing("linear", 0.05))
    assert not r.notes
