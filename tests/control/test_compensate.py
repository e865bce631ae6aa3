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
    return FittedModel.from_values(
        "coulomb_viscous",
        {"f_c": f_c, "beta": beta},
        operating_range={"velocity": [0.01, 1.0], "load": [0, 0], "temperature": [25, 25]},
    )


def preset_truth(name: str) -> Truth:
    """The virtual joint of a simulation preset as the plant's truth (law and inertia)."""
    joint = preset(name, "quick").joint
    return Truth(joint.law, name, joint.inertia)


def paper2() -> FittedModel:
    names = ("tau_c", "tau_s", "w_s", "tau_v", "delta")
    theta = preset("paper2", "quick").joint.law.theta
    return FittedModel.from_values(
        "stribeck",
        dict(zip(names, map(float, theta), strict=True)),
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


@pytest.mark.slow  # 2 s measured under load (default run kept short)
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
    res = runner.invoke(app, ["compensate", str(model), "--truth", "gms", "--no-plot"])
    assert res.exit_code == 2 and "unknown truth 'gms'" in res.output
    # lugre is a truth since issue 16; a static model then needs its bristle parameters
    res = runner.invoke(app, ["compensate", str(model), "--truth", "lugre", "--no-plot"])
    assert res.exit_code == 2 and "SIGMA_0,SIGMA_1" in res.output
    res = runner.invoke(app, ["compensate", str(model), "--dt", "-1", "--no-plot"])
    assert res.exit_code == 2 and "'dt' must be a number > 0" in res.output


def test_extrapolated_feedforward_is_noted():
    model = paper2()
    model.operating_range["velocity"] = [0.05, 4.0]
    r = compensation_study(model, TrackingConfig(**FAST))
    assert any("below the identified speeds (|v| < 0.05 rad/s)" in n for n in r.notes)
    r = compensation_study(model, TrackingConfig(**FAST), smoothing=Smoothing("linear", 0.05))
    assert not r.notes


# ---------------------------------------------------------------- LuGre truth (issue 16)

from fricid.control import LuGreTruth, lugre_compensation_study, lugre_parameters  # noqa: E402
from fricid.control.dynamic import RUNS, crossing_mask  # noqa: E402
from fricid.control.plant import drive, lugre_step  # noqa: E402
from fricid.errors import FricidWarning  # noqa: E402
from fricid.models import lugre  # noqa: E402

#: passive LuGre joint: sigma_0, sigma_1, sigma_2, tau_c, tau_s, w_s, delta
LUGRE = (1e3, 0.5, 0.1, 0.3, 0.5, 0.05, 2.0)


def stribeck_of_lugre() -> FittedModel:
    """The static part of LUGRE, as a sweep identification would give it."""
    s2, tau_c, tau_s, w_s, delta = LUGRE[2:]
    return FittedModel.from_values(
        "stribeck",
        {"tau_c": tau_c, "tau_s": tau_s, "w_s": w_s, "tau_v": s2, "delta": delta},
        operating_range={"velocity": [0.01, 2.0], "load": [0, 0], "temperature": [25, 25]},
    )


@pytest.mark.slow  # 2 s measured under load (default run kept short)
def test_lugre_observer_beats_static_feedforward_at_crossings():
    theta = lugre_parameters(stribeck_of_lugre(), 1e3, 0.5)
    np.testing.assert_array_equal(theta, LUGRE)
    r = lugre_compensation_study(theta, TrackingConfig(**FAST), truth=LuGreTruth(LUGRE))
    pd, static, observer = (r.rms_crossing[name] for name in RUNS)
    assert static < 0.2 * pd
    assert observer < 0.25 * static  # measured 0.11 (0.07 against 0.63 mrad)
    assert r.rms[RUNS[2]] < r.rms[RUNS[1]] < r.rms[RUNS[0]]
    assert "smaller than static" in r.verdict()
    assert r.to_dict()["crossing_rms_error_rad"][RUNS[2]] == observer


def test_lugre_observer_with_wrong_bristles_still_measured_honestly():
    """A model whose sigma_0 is 10x off: the study reports what happened, whichever wins."""
    theta = lugre_parameters(stribeck_of_lugre(), 1e4, 0.5)
    r = lugre_compensation_study(theta, TrackingConfig(**FAST), truth=LuGreTruth(LUGRE))
    obs, stat = r.rms_crossing[RUNS[2]], r.rms_crossing[RUNS[1]]
    assert ("smaller" in r.verdict()) == (obs < stat)


def test_lugre_plant_steady_state_is_the_static_law():
    """Driven at constant torque above break-away, the LuGre joint slides where
    u = g(v) + sigma_2 v, the steady state of fricid.models.lugre."""
    run = drive(np.full(20000, 0.45), 1e-4, 0.01, lugre_theta=LUGRE)
    v = run["velocity"][-1]
    np.testing.assert_allclose(
        lugre.steady_state(np.array(LUGRE), np.array([v]))[0], 0.45, rtol=1e-4
    )
    sliding = run["position"][-1]
    # below break-away it stays in pre-sliding: the deflection u / sigma_0 = 0.2 mrad plus
    # LuGre's known slow drift under a constant force (0.69 mrad after 0.5 s here)
    run = drive(np.full(5000, 0.2), 1e-4, 0.01, lugre_theta=LUGRE)
    assert 0.2 / LUGRE[0] < run["position"][-1] < 1e-3 < 1e-3 * sliding


def test_lugre_parameters_and_truth_checks():
    with pytest.raises(ConfigError, match="SIGMA_0,SIGMA_1"):
        lugre_parameters(stribeck_of_lugre())
    with pytest.raises(ConfigError, match="Stribeck curve"):
        lugre_parameters(FittedModel(model="msk"))
    with pytest.raises(ConfigError):
        LuGreTruth((1e3, 0.5, 0.1, 0.0, 0.5, 0.05, 2.0))  # tau_c = 0
    with pytest.raises(ConfigError, match="crossing window"):
        crossing_mask(TrackingConfig(**FAST), 0.5)
    theta = list(LUGRE)
    theta[1] = 5.0  # sigma_1 above the passivity bound 0.6
    with pytest.warns(FricidWarning, match="not passive"):
        lugre_compensation_study(theta, TrackingConfig(**FAST), truth=LuGreTruth(LUGRE))


def test_a_per_direction_model_drives_the_observer_with_its_own_levels():
    """A ``lugre_asym`` model file feeds the observer its 10 parameters: with the same levels
    both ways it is the symmetric model to the bit; weaker backwards it changes the run."""
    names = lugre.ASYM_NAMES
    same = dict(zip(names, lugre.wide(np.array(LUGRE))[0], strict=True))
    fitted = FittedModel.from_values("lugre_asym", same)
    theta = lugre_parameters(fitted)
    assert theta.size == 10
    config, truth = TrackingConfig(**FAST), LuGreTruth(LUGRE)
    a = lugre_compensation_study(theta, config, truth=truth)
    b = lugre_compensation_study(LUGRE, config, truth=truth)
    assert a.rms == b.rms and a.rms_crossing == b.rms_crossing
    assert a.to_dict()["lugre_parameters"]["tau_c_neg"] == LUGRE[3]
    weaker = dict(same, tau_c_neg=0.2, tau_s_neg=0.35)
    c = lugre_compensation_study(
        lugre_parameters(FittedModel.from_values("lugre_asym", weaker)), config, truth=truth
    )
    assert c.rms_crossing[RUNS[2]] != b.rms_crossing[RUNS[2]]
    assert c.rms[RUNS[0]] == b.rms[RUNS[0]]  # PD alone does not read the model
    with pytest.raises(ConfigError, match="7 finite LuGre parameters are needed"):
        LuGreTruth(tuple(theta))  # the plant has one level both ways


def test_cli_compensate_lugre_truth(tmp_path):
    stribeck_of_lugre().save(tmp_path / "s.json")
    args = ["compensate", str(tmp_path / "s.json"), "--truth", "lugre", "--frequency", "0.5"]
    args += ["--periods", "1", "--no-plot"]
    res = runner.invoke(app, [*args, "--lugre", "1000,0.5", "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    crossing = data["crossing_rms_error_rad"]
    assert crossing["LuGre observer"] < crossing["static feed-forward"]
    res = runner.invoke(app, [*args, "--lugre", "1000"])
    assert res.exit_code == 2 and "SIGMA_0,SIGMA_1" in res.output
    res = runner.invoke(app, [*args[:2], "--lugre", "1000,0.5", "--no-plot"])
    assert res.exit_code == 2 and "--truth lugre" in res.output
    plot = tmp_path / "lugre.png"
    res = runner.invoke(app, [*args[:-1], "--lugre", "1000,0.5", "--plot", str(plot)])
    assert res.exit_code == 0, res.output
    # the true joint is named: a new user took it for the one the model was identified on
    assert "True joint: the built-in LuGre joint (sigma_0 1000, sigma_1 0.5" in res.stdout
    assert plot.stat().st_size > 10_000
    assert "LuGre observer's RMS error is" in " ".join(res.stdout.split())


def test_lugre_step_batches_runs_like_the_compiled_drive():
    """plant.lugre_step over (k,) runs, stepped from Python, matches drive's compiled loop."""
    dt, u = 1e-4, 0.45 * np.sin(np.linspace(0, 6, 300))
    ref = drive(u, dt, 0.01, lugre_theta=LUGRE)
    z, v = np.zeros(2), np.zeros(2)
    theta = np.vstack([LUGRE, LUGRE])
    for i in range(u.size):
        np.testing.assert_allclose(v, ref["velocity"][i], rtol=1e-12, atol=1e-15)
        z, v, f = lugre_step(theta, z, v, np.full(2, u[i]), 0.01, dt)
        np.testing.assert_allclose(f, ref["friction"][i], rtol=1e-12, atol=1e-15)


def test_velocity_noise_is_seeded_and_reaches_the_observer():
    config, truth = TrackingConfig(**FAST), LuGreTruth(LUGRE)
    a = lugre_compensation_study(LUGRE, config, truth=truth, velocity_noise=0.02, seed=1)
    b = lugre_compensation_study(LUGRE, config, truth=truth, velocity_noise=0.02, seed=1)
    clean = lugre_compensation_study(LUGRE, config, truth=truth)
    assert a.rms == b.rms and "white noise" in a.notes[-1]
    assert a.rms_crossing[RUNS[2]] > 2 * clean.rms_crossing[RUNS[2]]
    with pytest.raises(ConfigError, match="velocity_noise"):
        lugre_compensation_study(LUGRE, config, truth=truth, velocity_noise=-1.0)
