"""Whole-arm identification (``fricid.identify.dynamic.arm.fit_arm``) against a truth of our own
(``_arm_truth``: inverse dynamics along a multi-sine, friction per joint and direction, 2^17
count encoders, torque noise)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _arm_truth import CV_LAWS, make_log, stribeck_law

pytest.importorskip("pinocchio")

from fricid.errors import ConfigError, DataError
from fricid.fitted import FittedModel
from fricid.fitted.arm import ArmFit
from fricid.identify.dynamic.arm import fit_arm
from fricid.robot import RigidBodyModel, example_urdf, is_consistent


@pytest.fixture(scope="module")
def pendulum_fit(pendulum):
    log = make_log(pendulum, CV_LAWS, duration=20.0, seed=3, noise=0.05)
    return fit_arm(log, pendulum, friction="coulomb_viscous_asym")


def _z(fit: ArmFit, laws) -> dict[str, float]:
    out = {}
    for joint, (_, truth) in zip(fit.joints, laws, strict=True):
        for name, rec in fit.friction[joint]["parameters"].items():
            out[f"{joint}:{name}"] = (rec["value"] - truth[name]) / rec["stderr"]
    return out


def test_double_pendulum_recovers_friction_within_intervals(pendulum_fit):
    fit = pendulum_fit
    for joint, (_, truth) in zip(fit.joints, CV_LAWS, strict=True):
        for name, rec in fit.friction[joint]["parameters"].items():
            low, high = rec["ci95"]
            assert not rec["not_determined"]
            assert low < rec["value"] < high
            # the interval is informative: a few per cent of the value at most
            assert high - low < 0.05 * abs(truth[name])
            assert abs(rec["value"] - truth[name]) < 0.02 * abs(truth[name])
    z = _z(fit, CV_LAWS)
    assert max(abs(v) for v in z.values()) < 3.0, z
    covered = sum(
        rec["ci95"][0] <= truth[n] <= rec["ci95"][1]
        for j, (_, truth) in zip(fit.joints, CV_LAWS, strict=True)
        for n, rec in fit.friction[j]["parameters"].items()
    )
    assert covered >= 7
    for joint in fit.joints:
        assert fit.validation[joint]["ratio"] < 1.5
        assert fit.verdict(joint) in ("yes", "with caveats")
    assert fit.provenance["estimator"] == "IDIM-WLS"
    assert fit.provenance["cutoff"] > 3 * fit.provenance["cutoff_bounds"]["motion"] - 1e-9
    assert fit.standard["consistent_ls"] is True


def test_base_parameters_cover_the_truth(pendulum, pendulum_fit):
    from fricid.robot import base_parameters

    truth = base_parameters(pendulum).project(pendulum.parameters())
    base = pendulum_fit.base
    assert len(base["names"]) == len(truth)
    inside = [lo <= t <= hi for t, (lo, hi) in zip(truth, base["ci95"], strict=True)]
    assert sum(inside) >= len(truth) - 1


def test_a_joint_that_never_moves_is_not_determined(pendulum):
    log = make_log(pendulum, CV_LAWS, duration=20.0, seed=5, noise=0.05, hold=(1,))
    fit = fit_arm(log, pendulum, friction="coulomb_viscous_asym")
    still = fit.joints[1]
    params = fit.friction[still]["parameters"]
    assert all(rec["not_determined"] and rec["value"] is None for rec in params.values())
    assert fit.verdict(still) == "no"
    assert "does not move" in " ".join(fit.validation[still]["reasons"])
    with pytest.raises(ConfigError, match="not determined"):
        fit.joint_model(still)
    # the moving joint is still identified
    moving = fit.friction[fit.joints[0]]["parameters"]
    assert abs(moving["f_c_pos"]["value"] - 0.5) < 0.02


def test_file_round_trip_and_joint_models(pendulum_fit, tmp_path):
    path = pendulum_fit.save(tmp_path / "arm.json")
    doc = json.loads(path.read_text())
    assert doc["kind"] == "fricid-arm" and doc["schema_version"] == 1
    back = ArmFit.load(path)
    assert back.joints == pendulum_fit.joints
    assert back.friction == json.loads(json.dumps(pendulum_fit.to_dict()))["friction"]
    model = back.joint_model(back.joints[1])
    assert model.model == "coulomb_viscous_asym"
    f = model.predict(np.array([[0.5, 0.0, 25.0], [-0.5, 0.0, 25.0]]), warn=False)
    assert f[0] == pytest.approx(0.7 + 0.3 * 0.5, rel=0.02)
    assert f[1] == pytest.approx(-0.4 - 0.3 * 0.5, rel=0.02)
    # the joint's model is an ordinary model file
    again = FittedModel.load(model.save(tmp_path / "joint2.json"))
    assert again.params == pytest.approx(model.params)


def test_bad_inputs(pendulum, tmp_path):
    log = make_log(pendulum, CV_LAWS, duration=5.0, seed=3)
    with pytest.raises(ConfigError, match="family"):
        fit_arm(log, pendulum, friction="dahl")
    with pytest.raises(DataError, match="joint"):
        fit_arm(log.rename({"joint1": "other"}), pendulum)
    (tmp_path / "x.json").write_text('{"kind": "something"}')
    with pytest.raises(DataError, match="whole-arm"):
        ArmFit.load(tmp_path / "x.json")


@pytest.mark.slow
def test_panda_recovers_friction_per_joint_and_direction():
    path, joints = example_urdf("panda")
    model = RigidBodyModel.from_urdf(path, joints)
    rng = np.random.default_rng(1)
    laws = [stribeck_law(rng) for _ in model.joints]
    log = make_log(model, laws, duration=40.0, seed=3, noise=0.05)
    fit = fit_arm(log, model, friction="stribeck_asym")
    for joint, (_, truth) in zip(fit.joints, laws, strict=True):
        params = fit.friction[joint]["parameters"]
        for name in ("tau_c_pos", "tau_c_neg", "tau_v_pos", "tau_v_neg"):
            assert params[name]["value"] == pytest.approx(truth[name], rel=0.05), (joint, name)
        assert fit.validation[joint]["ratio"] < 1.5
        assert fit.verdict(joint) != "no"
    z = _z(fit, laws)
    linear = [v for k, v in z.items() if k.split(":")[1].startswith(("tau_c", "tau_v"))]
    assert np.mean(np.abs(linear) < 1.96) >= 0.8


def test_the_one_public_fit_takes_a_robot_log(pendulum, pendulum_fit):
    from fricid.identify import fit, kind_of

    log = make_log(pendulum, CV_LAWS, duration=20.0, seed=3, noise=0.05)
    assert kind_of(log, "arm") == "arm"
    out = fit(log, "coulomb_viscous_asym", settings={"robot": pendulum})
    assert isinstance(out, ArmFit)
    assert out.friction == pendulum_fit.friction
    with pytest.raises(ConfigError, match="rigid-body model"):
        fit(log, "arm")
    with pytest.raises(ConfigError, match="does not take method"):
        fit(log, "arm", "lm", settings={"robot": pendulum})
    with pytest.raises(ConfigError, match="not: seed_count"):
        fit(log, "arm", settings={"robot": pendulum, "seed_count": 1})


def test_friction_family_per_joint(pendulum):
    laws = [
        ("coulomb_viscous", {"f_c": 0.5, "beta": 0.3}),
        CV_LAWS[1],
    ]
    log = make_log(pendulum, laws, duration=20.0, seed=7, noise=0.05)
    fit = fit_arm(
        log, pendulum, friction={"joint1": "coulomb_viscous", "joint2": "coulomb_viscous_asym"}
    )
    assert fit.friction["joint1"]["family"] == "coulomb_viscous"
    assert set(fit.friction["joint1"]["parameters"]) == {"f_c", "beta"}
    assert fit.friction["joint2"]["family"] == "coulomb_viscous_asym"
    for joint, (_, truth) in zip(fit.joints, laws, strict=True):
        for name, rec in fit.friction[joint]["parameters"].items():
            assert not rec["not_determined"]
            assert abs(rec["value"] - truth[name]) < 0.03 * truth[name], (joint, name)
    with pytest.raises(ConfigError, match="not in the model"):
        fit_arm(log, pendulum, friction={"elbow": "coulomb_viscous"})


def test_not_physical_least_squares_is_replaced_by_a_consistent_solution(pendulum):
    # a short, slow, noisy log excites little: the least-squares base parameters come out
    # where no physical links give them
    log = make_log(pendulum, CV_LAWS, duration=6.0, seed=1, noise=1.0, speed=0.3)
    fit = fit_arm(log, pendulum, friction="coulomb_viscous_asym")
    plain = fit_arm(log, pendulum, friction="coulomb_viscous_asym", consistent=False)
    assert fit.standard["used"] == "consistent"
    assert not fit.standard["consistent_ls"] and fit.standard["d2"] > 1.0
    assert is_consistent(np.array(fit.standard["values"])).all()
    assert np.allclose(fit.base["values_ls"], plain.base["values"])
    assert not np.allclose(fit.base["values"], fit.base["values_ls"])
    for joint in fit.joints:  # the held-out torque fit is barely worse
        assert fit.validation[joint]["rmse"] <= 1.1 * plain.validation[joint]["rmse"]


def test_rows_near_a_reversal_are_left_out_over_the_filter_window():
    # a joint reversing (no decimated row of the filtered velocity falls below the threshold
    # there) beside one always moving
    from fricid.identify.dynamic.arm import (
        MIN_SPEED,
        VELOCITY_NOISE_FACTOR,
        WINDOW_PERIODS,
        _moving,
    )
    from fricid.identify.dynamic.arm._signals import prepare_signals

    rate, f = 1000.0, 0.25
    t = np.arange(round(20 * rate)) / rate
    q = np.column_stack([np.sin(2 * np.pi * f * t) / (2 * np.pi * f), 0.5 * t])
    tau = np.random.default_rng(0).normal(0.0, 0.05, q.shape)
    sig = prepare_signals(t, q, tau, counts=2**17, cutoff=10.0, stops=True)
    assert _moving(sig)[np.abs(sig.dq[:, 0]) > 0.01, 0].all()  # by default: the threshold
    keep = _moving(sig, WINDOW_PERIODS)
    reversals = (np.arange(10) + 0.5) / (2 * f)  # cos(2 pi f t) = 0
    gap = np.min(np.abs(sig.time[:, None] - reversals[None, :]), axis=1)
    window = WINDOW_PERIODS / sig.cutoff
    assert not keep[gap < window - 2 / rate, 0].any()
    # the slow samples about a reversal: the friction's velocity below its threshold
    v_min = max(VELOCITY_NOISE_FACTOR * sig.friction_velocity_noise[0], MIN_SPEED)
    slow = v_min / (2 * np.pi * f)  # |acceleration| 2 pi f at a reversal
    assert keep[gap > window + slow + 2 / rate, 0].all()
    assert keep[:, 1].all()


@pytest.mark.slow
def test_closed_loop_coulomb_bias_is_removed_by_the_reversal_window(pendulum):
    from _arm_truth import make_pd_log

    from fricid.identify.dynamic.arm import WINDOW_PERIODS

    rng = np.random.default_rng(10_001)
    bounds = {"f_c_pos": (0.3, 1.0), "beta_pos": (0.1, 0.6)}
    bounds |= {"f_c_neg": (0.3, 1.0), "beta_neg": (0.1, 0.6)}
    laws = [
        ("coulomb_viscous_asym", {k: rng.uniform(*b) for k, b in bounds.items()}) for _ in range(2)
    ]
    log = make_pd_log(pendulum, laws, seed=1, duration=20.0, disturbance=0.0)

    fits = {}

    def mean_z(window, kind):
        fits[window] = fit = fit_arm(
            log, pendulum, friction="coulomb_viscous_asym", reversal_window=window
        )
        z = _z(fit, laws)
        return np.mean([v for k, v in z.items() if k.split(":")[1].startswith(kind)])

    assert mean_z(0.0, "f_c") < -2.0  # the threshold alone: Coulomb several errors low
    assert abs(mean_z(WINDOW_PERIODS, "f_c")) < 1.5
    assert abs(mean_z(WINDOW_PERIODS, "beta")) < 1.5
    # not told: the sticks at the reversals show in the first fit's residuals
    assert abs(mean_z(None, "f_c")) < 1.5
    prov = fits[None].provenance
    assert prov["reversal_window"] == WINDOW_PERIODS
    assert prov["closed_loop"].startswith("detected: the residuals of joint1, joint2")
    assert fits[0.0].provenance["closed_loop"] == "given: open loop"  # told: nothing decided
    assert fits[0.0].provenance["stick_signature"] == prov["stick_signature"]


def test_a_law_without_the_stribeck_rise_is_named_beside_a_closed_loop(pendulum):
    """An open-loop arm with Stribeck friction fitted with a Coulomb-viscous law: the law's
    missing rise leaves a misfit near the reversals as sticks do, and the decision says that
    it may be either (a new-user trial had read "joint sticking while a position loop builds
    torque" on such logs)."""
    rng = np.random.default_rng(7)
    laws = [stribeck_law(rng) for _ in range(2)]
    log = make_log(pendulum, laws, duration=20.0, seed=7, noise=0.05)
    text = fit_arm(log, pendulum, friction="coulomb_viscous_asym").provenance["closed_loop"]
    assert text.startswith("detected") and "without the Stribeck rise" in text, text
    same = fit_arm(log, pendulum, friction="stribeck_asym").provenance["closed_loop"]
    assert same.startswith("not detected"), same


def test_an_open_loop_log_is_not_taken_for_a_closed_loop_one(pendulum_fit):
    """The residuals of an arm that follows its reference exactly (no loop, no sticks) near
    its reversals are no larger than elsewhere: the rows there stay in."""
    prov = pendulum_fit.provenance
    assert prov["closed_loop"].startswith("not detected")
    assert prov["reversal_window"] == 0.0
    for joint in prov["stick_signature"]:
        assert joint["p"] > 0.01 and joint["excess"] < 0.5, prov["stick_signature"]


def test_a_friction_level_below_zero_is_not_printed_as_a_number(pendulum):
    """A torque that pushes with the motion (a sign convention wrong on one joint's torque
    channel, a drive's compensation left on) gives a Coulomb level below zero beyond its
    interval: no family describes that as friction, so it is not determined, not a number."""
    laws = [
        CV_LAWS[0],
        (
            "coulomb_viscous_asym",
            {"f_c_pos": -0.4, "beta_pos": 0.3, "f_c_neg": 0.4, "beta_neg": 0.3},
        ),
    ]
    log = make_log(pendulum, laws, duration=20.0, seed=3, noise=0.05)
    fit = fit_arm(log, pendulum, friction="coulomb_viscous_asym")
    rec = fit.friction[fit.joints[1]]["parameters"]["f_c_pos"]
    assert rec["not_determined"] and rec["value"] is None
    assert "below zero" in rec["note"]
    assert fit.verdict(fit.joints[1]) != "yes"
    assert not fit.friction[fit.joints[0]]["parameters"]["f_c_pos"]["not_determined"]


def test_a_level_below_zero_within_its_interval_is_not_determined_either(pendulum):
    """A viscous level the data barely see comes out below zero with an interval that reaches
    zero: the data say it is small, not how small. It is not determined (the joint's verdict is
    not "yes"), and the joint's model is refused with its name, not written for a later
    command to reject as outside the family's valid region."""
    laws = [
        CV_LAWS[0],
        (
            "coulomb_viscous_asym",
            {"f_c_pos": 0.4, "beta_pos": -0.002, "f_c_neg": 0.4, "beta_neg": 0.3},
        ),
    ]
    log = make_log(pendulum, laws, duration=20.0, seed=3, noise=0.2)
    fit = fit_arm(log, pendulum, friction="coulomb_viscous_asym")
    rec = fit.friction[fit.joints[1]]["parameters"]["beta_pos"]
    assert rec["not_determined"] and rec["value"] is None, rec
    assert "below zero" in rec["note"] and "reaches zero" in rec["note"]
    assert fit.verdict(fit.joints[1]) != "yes"
    with pytest.raises(ConfigError, match="beta_pos"):
        fit.joint_model(fit.joints[1])
    assert not fit.friction[fit.joints[0]]["parameters"]["beta_pos"]["not_determined"]
