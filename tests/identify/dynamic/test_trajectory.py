"""Trajectory experiments on the virtual joint and identification from them (issue 16)."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import ConfigError, ConvergenceWarning, DataError
from fricid.fitted import FittedModel, Parameter
from fricid.identify.dynamic.trajectory import DerivativeFilter, RateBiasWarning, fit_trajectory
from fricid.models import Stribeck
from fricid.sim import Joint, ModelLaw
from fricid.sim import trajectory as tr

JOINT = Joint(law=lambda v, load, temp: np.zeros_like(v), p_x=0.3, p_y=0.1, inertia=0.01)
STATIC = np.array([0.5, 0.8, 0.1, 0.2, 1.0])  # stribeck: tau_c, tau_s, w_s, tau_v, delta
TRUTH = tr.LuGreTruth()


def sweep_of(values: np.ndarray, stderr: float, half: float) -> FittedModel:
    """A Stribeck fit from sweeps: ``values`` with standard error ``stderr`` and the 95 %
    interval ``value +/- half``."""
    return FittedModel(
        model="stribeck",
        parameters={
            n: Parameter(n, float(v), stderr=stderr, ci95=(float(v) - half, float(v) + half))
            for n, v in zip(Stribeck().param_names, values, strict=True)
        },
    )


def covered(fitted, truth: dict[str, float]) -> dict[str, bool]:
    ends = {n: fitted.parameters[n].ci95 for n in truth}
    return {n: bool(ends[n][0] <= v <= ends[n][1]) for n, v in truth.items()}


@pytest.mark.parametrize("kind", tr.KINDS)
def test_every_experiment_gives_a_reader_like_log(kind):
    e = getattr(tr, kind)(duration=2.0)
    log = tr.simulate_trajectory(e, TRUTH, JOINT, seed=3)
    assert log.current is not None and log.torque_constant == 0.5
    assert log.meta["experiment"] == kind and log.meta["truth"]["sigma_0"] == 1e4
    assert np.all(np.isfinite(log.motor_torque))
    if kind == "presliding":  # below break-away: micro-radians only
        assert np.ptp(log.position) < 1e-3
    if kind in ("sine", "chirp", "multisine", "slow_multisine"):  # tracked, crossing zero velocity
        assert np.max(np.abs(log.position - e.q_ref)) < 2e-3
        assert np.any(np.diff(np.sign(e.v_ref)) != 0)


def test_static_truth_is_the_inverse_dynamics_and_refuses_torque_drives():
    law = ModelLaw(Stribeck(), STATIC)
    e = tr.sine(duration=1.0)
    log = tr.simulate_trajectory(e, law, JOINT, noise=tr.Noise.none())
    expected = (
        0.01 * e.a_ref + law(e.v_ref, 0, 25) - (0.3 * np.cos(e.q_ref) - 0.1 * np.sin(e.q_ref))
    )
    np.testing.assert_allclose(log.motor_torque, expected, atol=1e-9)
    with pytest.raises(ConfigError, match="dynamic truth"):
        tr.simulate_trajectory(tr.stick_slip(duration=1.0), law, JOINT)


def test_static_model_from_a_trajectory_within_intervals():
    law = ModelLaw(Stribeck(), STATIC)
    log = tr.simulate_trajectory(tr.multisine(duration=10.0, seed=2), law, JOINT, seed=2)
    fitted = fit_trajectory(log, "stribeck", "lm")
    truth = dict(zip(Stribeck().param_names, STATIC, strict=True))
    hits = covered(fitted, truth)
    joint = fitted.provenance["trajectory"]["joint"]
    hits.update(
        {
            n: joint[n]["ci95_low"] <= v <= joint[n]["ci95_high"]
            for n, v in (("inertia", 0.01), ("p_x", 0.3), ("p_y", 0.1))
        }
    )
    assert sum(hits.values()) >= len(hits) - 1, hits  # 95 % intervals: at most one miss of 8
    assert fitted.provenance["trajectory"]["derivative"]["method"] == "savgol"


def test_lugre_two_stage_route_covers_the_truth_on_two_seeds(tmp_path, monkeypatch):
    from fricid.identify.dynamic import _result
    from fricid.identify.dynamic._routes import _SimProblem
    from fricid.identify.problem import Problem

    searched = []  # every stage's search is a problem of the protocol, certified alike

    def spy(fits, *args):
        searched.extend(stage.problem for _, stage in fits)
        return converged(fits, *args)

    converged = _result.converged
    monkeypatch.setattr(_result, "converged", spy)
    hits, opened = {}, []
    for seed in (0, 1):
        log = tr.simulate_trajectory(
            tr.multisine(duration=10.0, seed=seed), TRUTH, JOINT, seed=seed
        )
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fitted = fit_trajectory(log, "lugre", "lm", seed=seed, route="two_stage")
        for n, ok in covered(fitted, TRUTH.params()).items():
            p = fitted.parameters[n]
            if p.low_open or p.high_open:  # not determined: counted apart, never as a hit
                opened.append((seed, n))
            else:
                hits[(seed, n)] = ok
        info = fitted.provenance["trajectory"]
        assert set(info["routes"]) == {"regression", "refinement_1", "simulation"}
        assert info["passivity"]["condition"].startswith("sigma_1 <=")
    assert len(searched) == 8 and all(isinstance(p, Problem) for p in searched)
    assert sum(isinstance(p, _SimProblem) for p in searched) == 4
    # only sigma_1 (damping ratio 0.05) may be left undetermined by 10 s of multi-sine
    assert {n for _, n in opened} <= {"sigma_1"}, opened
    # up to 14 intervals of 95 %: at most 2 misses is the honest floor (binomial, p 0.97)
    assert sum(hits.values()) >= len(hits) - 2, {k: v for k, v in hits.items() if not v}
    path = fitted.save(tmp_path / "lugre.json")
    again = FittedModel.load(path)
    assert again.model == "lugre" and again.params == pytest.approx(fitted.params)
    assert again.predict_point(0.5) == pytest.approx(
        fitted.params["tau_c"]
        + (fitted.params["tau_s"] - fitted.params["tau_c"])
        * np.exp(-((0.5 / fitted.params["w_s"]) ** fitted.params["delta"]))
        + fitted.params["sigma_2"] * 0.5
    )


def test_unconverged_trajectory_fit_withholds_its_intervals(tmp_path):
    """A trajectory identification's convergence is certified as an analytic fit's (a local
    least-squares polish of the problem each reported stage minimised), not taken from the
    optimiser's flag: a search cut short withholds every standard error and interval (the
    parameters', the joint's, the routes') and says why; a converged one keeps them."""
    from fricid.cli.trajectory import trajectory_text

    law = ModelLaw(Stribeck(), STATIC)
    log = tr.simulate_trajectory(tr.multisine(duration=4.0, seed=3), law, JOINT, seed=3)
    with pytest.warns(ConvergenceWarning, match="did not converge.*intervals are withheld"):
        cut = fit_trajectory(log, "stribeck", "bas", max_evals=40)
    conv = cut.convergence
    assert not conv["converged"] and conv["reason"].startswith("stage 'regression': method 'bas'")
    assert conv["polish_sse_ratio"] < 0.5 and conv["stages"][0]["stage"] == "regression"
    records = cut.parameters.values()
    assert all(np.isnan(p.stderr) and np.isnan(p.ci95[0]) for p in records)
    assert all(p.note and not (p.low_open or p.high_open) for p in records)
    info = cut.provenance["trajectory"]
    for row in [*info["joint"].values(), *info["routes"]["regression"]["parameters"].values()]:
        assert np.isnan(row["stderr"]) and np.isnan(row["ci95_high"]) and np.isfinite(row["value"])
    assert cut.report().startswith("NOT CONVERGED: stage 'regression'")
    saved = FittedModel.load(cut.save(tmp_path / "cut.json"))
    assert "inertia: 0.0" in trajectory_text(saved)
    assert "(no interval: the fit did not converge)" in trajectory_text(saved)

    good = fit_trajectory(log, "stribeck", "lm")
    conv = good.convergence
    assert conv["converged"] and conv["certified_by"] == "optimizer"
    assert conv["polish_sse_ratio"] == pytest.approx(1.0, abs=1e-6) and conv["polish_nfev"] > 0
    assert all(np.isfinite(p.stderr) for p in good.parameters.values())
    assert "+/- " in trajectory_text(good)


def test_only_the_reported_stages_decide_a_trajectory_fits_convergence():
    """A search that only started a later search of all its parameters (the regression before
    the filtered route, the simulation before a refinement, every stage before ``joint``'s) is
    recorded, not polished; the stages whose estimates are reported decide."""
    from types import SimpleNamespace

    from fricid.identify.dynamic._outcome import _deciding
    from fricid.models import lugre

    regression = SimpleNamespace(names=[*Stribeck().param_names, "inertia", "p_x", "p_y"])
    simulation = SimpleNamespace(names=["sigma_0", "sigma_1"])
    every = SimpleNamespace(names=[*lugre.PARAM_NAMES, "inertia", "p_x", "p_y"])
    two_stage = [
        ("regression", regression),
        ("simulation", simulation),
        ("refinement_1", regression),
        ("simulation after refinement_1", simulation),
    ]
    assert _deciding(two_stage, lugre.STRIBECK_NAMES) == [False, False, True, True]
    joint = [*two_stage, ("simulation_joint", every)]
    assert _deciding(joint, lugre.STRIBECK_NAMES) == [False] * 4 + [True]
    filtered = [("regression", regression), ("filtered", every)]
    assert _deciding(filtered, lugre.STRIBECK_NAMES) == [False, True]
    assert _deciding(filtered, {}) == [True, True]  # without the renaming tau_v is not covered
    assert _deciding([("regression", regression)], {}) == [True]


def test_single_sine_cannot_separate_inertia_from_gravity():
    log = tr.simulate_trajectory(tr.sine(duration=6.0), TRUTH, JOINT, seed=1)
    fitted_or_error = None
    try:
        fitted_or_error = fit_trajectory(log, "lugre")
    except DataError as exc:
        assert "collinear" in str(exc)
        return
    # if the noise happens to give a positive J, its interval must be wide
    row = fitted_or_error.provenance["trajectory"]["joint"]["inertia"]
    assert row["stderr"] > 0.05 * abs(row["value"])


def test_options_are_checked():
    log = tr.simulate_trajectory(tr.multisine(duration=2.0), TRUTH, JOINT)
    with pytest.raises(ConfigError, match="trajectory identifies"):
        fit_trajectory(log, "vlt")
    with pytest.raises(ConfigError, match="simulation route"):
        fit_trajectory(log, "lugre", route="regression")
    with pytest.raises(ConfigError, match="rate_bias must be"):
        fit_trajectory(log, "lugre", rate_bias="correct")
    with pytest.raises(ConfigError, match="derivative filter"):
        DerivativeFilter(method="spline")
    from fricid.identify.dynamic.trajectory import ParallelFilter

    with pytest.raises(ConfigError, match="parallel filter"):
        ParallelFilter(cutoff=0.0)
    with pytest.raises(ConfigError, match="not below Nyquist"):
        fit_trajectory(log, "lugre", parallel=ParallelFilter(cutoff=600.0))
    short = tr.simulate_trajectory(tr.multisine(duration=0.6), TRUTH, JOINT)
    with pytest.raises(DataError, match="too short for the parallel filter"):
        fit_trajectory(short, "lugre")


def write_joint_bag(path: Path, log) -> Path:
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    JointState = ts.types["sensor_msgs/msg/JointState"]
    Header = ts.types["std_msgs/msg/Header"]
    Time = ts.types["builtin_interfaces/msg/Time"]
    t0 = 1_700_000_000_000_000_000
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        conn = w.add_connection("/joint_states", JointState.__msgtype__, typestore=ts)
        for t, q, v, u in zip(log.time, log.position, log.velocity, log.motor_torque, strict=True):
            ns = t0 + round(t * 1e9)
            msg = JointState(
                header=Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id=""),
                name=["elbow"],
                position=np.array([q]),
                velocity=np.array([v]),
                effort=np.array([u]),
            )
            w.write(conn, ns, ts.serialize_cdr(msg, JointState.__msgtype__))
    return path


def test_cli_fits_lugre_from_a_ros2_bag(tmp_path):
    e = tr.multisine(duration=8.0, rate=500.0, seed=4)
    log = tr.simulate_trajectory(e, TRUTH, JOINT, seed=4)
    bag = write_joint_bag(tmp_path / "run", log)
    out = tmp_path / "elbow.json"
    result = CliRunner().invoke(
        app,
        [
            "fit",
            str(bag),
            "--trajectory",
            "--model",
            "lugre",
            "--format",
            "rosbag",
            "--reader-option",
            "joint=elbow",
            "--reader-option",
            "temperature=25",
            "--out",
            str(out),
        ],
    )
    assert result.exit_code == 0, result.output
    assert "[[Trajectory]]" in result.output and "passivity" in result.output
    fitted = FittedModel.load(out)
    assert fitted.model == "lugre"
    assert fitted.params["tau_c"] == pytest.approx(0.5, rel=0.05)
    joint = json.loads(out.read_text())["provenance"]["trajectory"]["joint"]
    assert joint["inertia"]["value"] == pytest.approx(0.01, rel=0.1)


def test_cli_refuses_a_log_without_motion(tmp_path):
    result = CliRunner().invoke(app, ["fit", str(tmp_path / "missing.csv"), "--trajectory"])
    assert result.exit_code == 2


@pytest.mark.slow  # 3 s measured under load (default run kept short)
def test_any_optimiser_and_static_part_from_sweeps():
    log = tr.simulate_trajectory(tr.multisine(duration=6.0, seed=5), TRUTH, JOINT, seed=5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit_trajectory(log, "lugre", "bas", max_evals=60, seed=1)
    assert fitted.optimizer.method == "bas" and fitted.convergence is not None
    assert fitted.provenance["trajectory"]["routes"]["filtered"]["nfev"] <= 60
    sweep = sweep_of(STATIC, stderr=0.001, half=0.002)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        two = fit_trajectory(log, "lugre", static=sweep)
    assert two.provenance["trajectory"]["static_from"] == "sweeps"
    assert two.params["tau_s"] == 0.8 and two.parameters["tau_s"].ci95[0] == pytest.approx(0.798)
    assert set(two.provenance["trajectory"]["routes"]["regression"]["parameters"]) == {
        "inertia",
        "p_x",
        "p_y",
    }


def test_passivity_is_judged_at_the_estimate_and_the_worst_corner():
    from fricid.identify.dynamic._outcome import passivity as _passivity

    names = list(TRUTH.params())
    values = TRUTH.theta
    wide_high = values.copy()
    wide_high[1] = 10.0  # sigma_1 up to 10 N m s/rad inside the interval: not passive there
    p = _passivity(names, values, values * 0.99, wide_high)
    assert p["passive"] and not p["passive_across_ci95"]
    damped = values.copy()
    damped[1] = 5.0
    assert not _passivity(names, damped, damped, damped)["passive"]


def test_multiple_shooting_segments_carry_the_bristle_state():
    from fricid.models import lugre

    t = np.arange(200) * 1e-3
    tau = 0.6 * np.sin(2 * np.pi * 3 * t)
    run = lugre.simulate_joint(TRUTH.theta, 0.01, 0.0, 0.0, 1e-3, tau, n_sub=4)
    reset = np.zeros(t.size, dtype=bool)
    reset[[0, 80]] = True
    measured = (run["position"], run["velocity"])
    again = lugre.simulate_joint(
        TRUTH.theta,
        0.01,
        0.0,
        0.0,
        1e-3,
        tau,
        n_sub=4,
        reset=reset,
        measured=measured,
        carry=np.arange(t.size) == 80,
    )
    # restarting the motion from itself with z carried on changes nothing after sample 80
    np.testing.assert_allclose(again["state"][80:], run["state"][80:], rtol=1e-9, atol=1e-15)
    fresh = lugre.simulate_joint(
        TRUTH.theta, 0.01, 0.0, 0.0, 1e-3, tau, n_sub=4, reset=reset, measured=measured
    )
    assert abs(fresh["state"][80] - run["state"][80]) > 1e-9  # force balance: another z


def test_bristle_damping_determined_when_the_static_part_is_known():
    """A well-damped bristle mode (damping ratio 0.4) with the static part from sweeps: the
    simulation route determines sigma_1 (it did not before segments carried z on)."""
    theta = TRUTH.theta.copy()
    theta[1] = 8.0
    log = tr.simulate_trajectory(
        tr.multisine(duration=10.0, seed=0),
        tr.LuGreTruth(theta=theta),
        JOINT,
        noise=tr.Noise.none(),
    )
    sweep = sweep_of(STATIC, stderr=1e-6, half=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit_trajectory(log, "lugre", static=sweep)
    assert not fitted.parameters["sigma_1"].low_open
    assert not fitted.parameters["sigma_1"].high_open
    assert fitted.params["sigma_1"] == pytest.approx(8.0, rel=0.05)
    assert fitted.params["sigma_0"] == pytest.approx(1e4, rel=0.1)


def test_slow_multisine_holds_each_speed_both_ways_then_the_multisine():
    e = tr.slow_multisine(duration=20.0, seed=1)
    half = e.time < 10.0
    for s in (0.03, 0.05, 0.1, 0.2, 0.3):  # each plateau forwards and backwards, ~0.75 s
        for sign in (1, -1):
            held = np.isclose(e.v_ref[half], sign * s, rtol=0, atol=1e-12).sum()
            assert 0.7 < held * 1e-3 < 0.8
    assert abs(e.q_ref[half][-1]) < 1e-6  # the pairs are symmetric: back at the start
    # one continuous reference: velocity is the position's derivative, no jumps
    dv = np.gradient(e.q_ref, 1e-3) - e.v_ref
    assert np.max(np.abs(dv[1:-1])) < 5e-4 and np.max(np.abs(np.diff(e.v_ref))) < 0.02
    m = tr.multisine(duration=20.0, seed=1)
    tail = e.time >= 11.0  # after the fade: the multi-sine itself, shifted to the start
    np.testing.assert_allclose(e.v_ref[tail], m.v_ref[1000 : 1000 + tail.sum()], atol=1e-12)


def test_simulate_trajectory_refuses_an_unknown_experiment_and_writes_nothing(tmp_path):
    from typer.testing import CliRunner

    from fricid.cli import app

    out = tmp_path / "t.parquet"
    res = CliRunner().invoke(app, ["simulate", "--trajectory", "spiral", "--out", str(out)])
    assert res.exit_code == 2 and "--trajectory must be one of" in res.output
    res = CliRunner().invoke(
        app, ["simulate", "--trajectory", "sine", "--duration", "0", "--out", str(out)]
    )
    assert res.exit_code == 2 and "--duration must be between 1 and 3600 s" in res.output
    # options of the other kind of log are refused, not ignored
    res = CliRunner().invoke(
        app, ["simulate", "--trajectory", "sine", "--preset", "paper2", "--out", str(out)]
    )
    assert res.exit_code == 2 and "--preset paper2: not for --trajectory" in res.output
    res = CliRunner().invoke(app, ["simulate", "--duration", "5", "--out", str(out)])
    assert res.exit_code == 2 and "--duration is the length of a --trajectory" in res.output
    assert not out.exists()


def test_mean_friction_is_the_period_mean_of_a_fine_simulation():
    from fricid.models import lugre

    up, n, dt = 4, 401, 1e-3
    v_sub = 0.2 * np.sin(np.arange((n - 1) * up + 1) * dt / up * 2 * np.pi * 1.3)
    F = lugre.mean_friction(TRUTH.theta, v_sub, dt, up, 0.0)
    fine = 256  # each sub-step cut again: the rectangle rule's error shrinks as 1/fine
    _, Z = lugre.simulate(TRUTH.theta, np.repeat(v_sub[1:], fine), dt / up / fine, 0.0)
    Z = np.concatenate([[0.0], Z])
    per = up * fine
    z_mean = Z[1:].reshape(n - 1, per).mean(axis=1)
    v_mean = v_sub[1:].reshape(n - 1, up).mean(axis=1)
    th = TRUTH.theta
    ref = th[0] * z_mean + th[1] * np.diff(Z[::per]) / dt + th[2] * v_mean
    np.testing.assert_allclose(F[1:], ref, atol=2e-4)
    with pytest.raises(ConfigError, match="per period"):
        lugre.mean_friction(TRUTH.theta, v_sub[:-1], dt, up)


def test_filtered_route_is_consistent_on_a_noise_free_log():
    """Every LuGre parameter with J, p_x, p_y at once by the parallel-filtered equation error:
    noise-free, the static part and the joint within a few per mille, sigma_0 and sigma_1
    within the error of the bristle drive between samples (module notes of
    ``_trajectory_filtered``: sigma_0 +3 %, sigma_1 -20 % on 20 s), a bias fricid estimates
    by simulation at the estimate and warns about, its corrected values closer to the truth."""
    log = tr.simulate_trajectory(
        tr.multisine(duration=8.0, seed=21), TRUTH, JOINT, noise=tr.Noise.none()
    )
    with pytest.warns(RateBiasWarning, match=r"logging at 1000 Hz biases sigma_0 \+.*10000 Hz"):
        fitted = fit_trajectory(log, "lugre")
    info = fitted.provenance["trajectory"]
    assert info["route"] == "filtered" and set(info["routes"]) == {"regression", "filtered"}
    assert info["parallel_filter"]["cutoff"] == 20.0 and fitted.converged
    stages = fitted.convergence["stages"]  # the regression only started the filtered route
    assert [b["stage"] for b in stages] == ["regression", "filtered"]
    assert stages[0]["superseded"] and stages[1]["certified_by"] == "optimizer"
    assert info["parallel_filter"]["decimate"] == 10  # 1 kHz to 100 Hz: five times 20 Hz
    truth = TRUTH.params()
    for n in ("sigma_2", "tau_c", "tau_s", "w_s", "delta"):
        assert fitted.params[n] == pytest.approx(truth[n], rel=5e-3), n
    for n, v in (("inertia", 0.01), ("p_x", 0.3), ("p_y", 0.1)):
        assert info["joint"][n]["value"] == pytest.approx(v, rel=5e-3), n
    assert fitted.params["sigma_0"] == pytest.approx(1e4, rel=0.1)
    assert fitted.params["sigma_1"] == pytest.approx(1.0, rel=0.35)
    assert not any(p.low_open or p.high_open for p in fitted.parameters.values())
    rb = info["rate_bias"]
    assert rb["internal_rate"] == pytest.approx(16000.0) and rb["log_rate"] == pytest.approx(1e3)
    for n, v in (("sigma_0", 1e4), ("sigma_1", 1.0)):  # 8 s: +3.0 %, -17 % to +0.7 %, +2.7 %
        assert abs(rb[n]["corrected"] / v - 1) < 0.3 * abs(fitted.params[n] / v - 1), n
    assert "rate_bias" not in fit_trajectory(log, "lugre", rate_bias="off").provenance["trajectory"]


@pytest.mark.slow  # 3 s measured under load (default run kept short)
def test_filtered_route_covers_the_truth_with_noise_and_the_cli_selects_routes(tmp_path):
    log = tr.simulate_trajectory(tr.multisine(duration=15.0, seed=22), TRUTH, JOINT, seed=22)
    fitted = fit_trajectory(log, "lugre")
    hits = covered(fitted, TRUTH.params())
    # sigma_1's calibrated widening (x4.43 on a log scale, _outcome.CALIBRATED_WIDENING) takes
    # its interval over the whole box here: reported not determined, no claim
    sigma_1 = fitted.parameters["sigma_1"]
    assert sigma_1.not_determined and sigma_1.low_open and sigma_1.high_open
    others = (p for n, p in fitted.parameters.items() if n != "sigma_1")
    assert not any(p.low_open or p.high_open for p in others)
    assert sum(hits.values()) >= 6, hits  # 7 intervals of 95 %: at most one miss
    from fricid.io.tables import write_rawlog

    path = write_rawlog(log, tmp_path / "traj.parquet")
    for route in ("filtered", "two_stage"):
        out = tmp_path / f"{route}.json"
        result = CliRunner().invoke(
            app,
            [
                "fit",
                str(path),
                "--trajectory",
                "--model",
                "lugre",
                "--route",
                route,
                "--out",
                str(out),
            ],
        )
        assert result.exit_code == 0, result.output
        info = json.loads(out.read_text())["provenance"]["trajectory"]
        assert info["route"] == route
        if route == "filtered":  # the report block and the rate bias's one-line warning
            assert "parallel filter (both sides)" in result.output
            assert "rate bias at 1000 Hz" in result.output and "rate_bias" in info
            saved = json.loads(out.read_text())["provenance"]["warnings"]
            assert any(w.startswith("RateBiasWarning: logging at 1000 Hz") for w in saved)
    bad = CliRunner().invoke(app, ["fit", str(path), "--trajectory", "--route", "spline"])
    assert bad.exit_code == 2 and "unknown route" in bad.output


def test_rate_bias_says_why_it_was_not_estimated(monkeypatch):
    """A simulation at the estimate that diverges leaves the reason, and no warning."""
    log = tr.simulate_trajectory(tr.multisine(duration=3.0, seed=23), TRUTH, JOINT, seed=23)
    from fricid.models import lugre

    def diverged(*args, **kwargs):
        n = np.asarray(args[5]).size
        return {k: np.full(n, np.nan) for k in ("position", "velocity", "torque")}

    monkeypatch.setattr(lugre, "simulate_joint", diverged)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RateBiasWarning)
        fitted = fit_trajectory(log, "lugre")
    rb = fitted.provenance["trajectory"]["rate_bias"]
    assert rb["skipped"] == "the simulation at the estimate diverged" and "sigma_0" not in rb
    from fricid.cli.trajectory import trajectory_text

    assert "rate bias: not estimated (the simulation at the estimate diverged)" in (
        trajectory_text(fitted)
    )


def test_an_interval_that_spans_the_box_is_not_identified(tmp_path):
    """The README's 10 s multi-sine does not inform sigma_1: its interval spans the whole
    search box, and the parameter record says so (not determined, with the reason), as an
    analytic fit's does; the parameters the log informs keep closed intervals."""
    runner = CliRunner()
    log = tmp_path / "traj.parquet"
    res = runner.invoke(app, ["simulate", "--trajectory", "multisine", "--duration", "10",
                              "--out", str(log)])  # fmt: skip
    assert res.exit_code == 0, res.output
    res = runner.invoke(app, ["fit", str(log), "--trajectory", "--model", "lugre",
                              "--out", str(tmp_path / "l.json")])  # fmt: skip
    assert res.exit_code == 0, res.output
    fitted = FittedModel.load(tmp_path / "l.json")
    spans = [n for n, p in fitted.parameters.items() if p.low_open and p.high_open]
    assert "sigma_1" in spans
    for name in spans:
        record = fitted.parameters[name]
        assert record.not_determined and record.note.startswith("not identified")
    assert fitted.parameters["sigma_2"].not_determined is False
    assert "[not identified: the 95 % interval spans" in res.stdout


def test_a_stick_slip_log_is_identified_not_taken_for_presliding():
    """fricid's own stick-slip experiment slides in slips of some milliseconds between sticks:
    the 0.2 s guard after each stick had left too few sliding samples, the log went to the
    pre-sliding route, which refused it as a torque of the wrong sign. The guard is then cut
    to a share of the stretches between slow ones, and the filtered route identifies it."""
    log = tr.simulate_trajectory(tr.stick_slip(duration=10.0), TRUTH, JOINT, seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit_trajectory(log, "lugre")
    assert fitted.provenance["trajectory"]["route"] == "filtered"
    truth = {"sigma_0": 1e4, "inertia": 0.01, "p_x": 0.3}
    joint = fitted.provenance["trajectory"]["joint"]
    ends = {n: (joint[n]["ci95_low"], joint[n]["ci95_high"]) for n in ("inertia", "p_x")}
    ends["sigma_0"] = fitted.parameters["sigma_0"].ci95
    for name, value in truth.items():
        low, high = ends[name]
        assert low <= value <= high, (name, low, high)
