"""Sweeps on arms: gravity from the whole configuration, base gravity parameters identified
from the sweeps, every joint's friction (fricid.extract.arm, fricid.extract.arm_gravity)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

pytest.importorskip("pinocchio")

from _arm_sweeps import Law, arm_sweeps, perturbed
from fricid.errors import ConfigError, DataError
from fricid.extract import extract, fit_gravity_joint, moments
from fricid.extract.arm import extract_arm
from fricid.extract.arm_gravity import arm_moments, solve_levels
from fricid.robot import RigidBodyModel, base_parameters, example_urdf

PENDULUM_LAWS = {"joint1": Law(0.10, 0.08, 0.05, 0.04), "joint2": Law(0.06, 0.07, 0.03, 0.035)}
PANDA = ("panda_joint2", "panda_joint4", "panda_joint6")
PANDA_LAWS = {
    PANDA[0]: Law(1.0, 0.8, 0.5, 0.4),
    PANDA[1]: Law(0.6, 0.7, 0.3, 0.35),
    PANDA[2]: Law(0.3, 0.25, 0.1, 0.12),
}


def _rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


@pytest.fixture(scope="module")
def pendulum():
    """Double pendulum sweeps (noise 0.01 N m): each speed in another pose of the other
    joint; the identification model's bodies 10-20 % off."""
    path, joints = example_urdf("double_pendulum")
    truth = RigidBodyModel.from_urdf(path, joints)
    spans = {"joint1": (-1.2, 1.2), "joint2": (-1.2, 1.2)}
    poses = {
        "joint1": [np.array([0.0, q]) for q in (-0.9, 0.0, 0.9)],
        "joint2": [np.array([q, 0.0]) for q in (-0.9, 0.0, 0.9)],
    }
    log = arm_sweeps(truth, spans, poses, PENDULUM_LAWS, seed=1)
    return truth, perturbed(truth, np.random.default_rng(3)), log


@pytest.fixture(scope="module")
def pendulum_result(pendulum):
    """The arm extraction of the double pendulum's sweeps (shared by two tests)."""
    _, ident, log = pendulum
    return extract_arm(log, ident)


@pytest.fixture(scope="module")
def panda():
    """Three Panda joints (2, 4, 6; the others locked at 0), noise 0.05 N m, bodies 10-20 %
    off in the identification model."""
    path, _ = example_urdf("panda")
    truth = RigidBodyModel.from_urdf(path, PANDA)
    spans = {PANDA[0]: (-1.2, 1.2), PANDA[1]: (-2.8, -0.4), PANDA[2]: (0.3, 3.3)}
    poses = {
        PANDA[0]: [np.array([0.0, a, b]) for a, b in ((-2.2, 1.0), (-1.6, 1.8), (-1.0, 2.6))],
        PANDA[1]: [np.array([a, 0.0, b]) for a, b in ((-0.6, 1.0), (0.0, 1.8), (0.6, 2.6))],
        PANDA[2]: [np.array([a, b, 0.0]) for a, b in ((-0.6, -2.2), (0.0, -1.6), (0.6, -1.0))],
    }
    log = arm_sweeps(truth, spans, poses, PANDA_LAWS, noise=0.05, rate=50.0, seed=1)
    return truth, perturbed(truth, np.random.default_rng(11)), log


def _level_se(result, joint) -> np.ndarray:
    """Each by-direction row's standard error from the joint fit (its level's: noise and the
    gravity parameters' uncertainty, which all rows of a joint share)."""
    se = {
        (lv["direction"], round(abs(lv["velocity"]), 2)): lv["friction_se"]
        for lv in result.gravity.joint_levels(joint)
    }
    bd = result[joint].by_direction
    keys = zip(bd.direction.astype(int), np.abs(bd.velocity).round(2), strict=True)
    return np.array([se[(d, float(v))] for d, v in keys])


def _errors(result, laws) -> dict[str, np.ndarray]:
    """Per joint, the by-direction friction's error against the truth [N m]."""
    return {
        j: r.by_direction.friction - laws[j](r.by_direction.velocity) for j, r in result.items()
    }


def _eq7_errors(log, laws) -> dict[str, np.ndarray]:
    """Per joint, the single-joint path's (eq. 7, joint fit) friction error [N m]."""
    out = {}
    for joint in laws:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the eq. 7 residual warning is expected here
            bd = extract(log.joint(joint), gravity="joint").by_direction
        out[joint] = bd.friction - laws[joint](bd.velocity)
    return out


def _check_recovery(truth, ident, log, laws, eq7_floor, res=None):
    """The arm path recovers every level within 4 standard errors and the base gravity
    parameters within 4; the eq. 7 path leaves errors of at least ``eq7_floor`` times the
    friction's RMS on the joints whose gravity is coupled. Returns the RMS figures."""
    res = extract_arm(log, ident) if res is None else res
    fit = res.gravity
    base = base_parameters(ident, gravity_only=True)
    beta_true = base.project(truth.parameters())
    assert np.all(np.abs(fit.beta - beta_true) < 4 * fit.beta_se)
    # the URDF's masses are off: its parameters are far outside those intervals
    assert np.any(np.abs(fit.beta_urdf - beta_true) > 20 * fit.beta_se)
    z = [
        (lv["friction"] - laws[lv["joint"]](lv["velocity"])) / lv["friction_se"]
        for lv in fit.levels
    ]
    assert np.all(np.abs(z) < 4), z
    arm = _errors(res, laws)
    eq7 = _eq7_errors(log, laws)
    urdf = _errors(extract_arm(log, ident, identify=False), laws)
    figures = {}
    for joint, law in laws.items():
        size = _rms(law(res[joint].by_direction.velocity))
        se = _rms(_level_se(res, joint))
        figures[joint] = (_rms(arm[joint]), _rms(eq7[joint]), _rms(urdf[joint]), size, se)
        assert _rms(arm[joint]) < 3 * se  # within noise
        assert _rms(urdf[joint]) > 10 * _rms(arm[joint])  # the URDF's masses leave errors
    coupled = [j for j in laws if figures[j][1] > eq7_floor * figures[j][3]]
    return res, figures, coupled


def test_double_pendulum_arm_path_recovers_friction_eq7_does_not(pendulum, pendulum_result):
    truth, ident, log = pendulum
    _, figures, coupled = _check_recovery(
        truth, ident, log, PENDULUM_LAWS, 0.8, res=pendulum_result
    )
    # measured (joint1 / joint2): arm path 0.0008 / 0.0006 N m RMS (standard errors 0.0007 /
    # 0.0005), eq. 7 path 0.21 / 0.21 N m, the URDF's masses 0.031 / 0.031 N m; friction
    # 0.11 / 0.08 N m RMS
    assert coupled == ["joint1", "joint2"], figures


@pytest.mark.slow  # 2.4 s measured under load (two arm extractions, three eq. 7 ones)
def test_panda_three_joints_arm_path_recovers_friction(panda):
    truth, ident, log = panda
    res, figures, coupled = _check_recovery(truth, ident, log, PANDA_LAWS, 0.8)
    # measured (joints 2 / 4 / 6): arm path 0.0037 / 0.0039 / 0.0028 N m RMS (standard
    # errors 0.0043 / 0.0034 / 0.0025), eq. 7 path 2.46 / 2.84 / 0.003 N m (joint 6's gravity
    # varies here as eq. 7's), the URDF's masses 0.35 / 0.63 / 0.21 N m; friction 1.12 / 0.81
    # / 0.33
    assert coupled == ["panda_joint2", "panda_joint4"], figures
    for joint, r in res.items():
        # the load column is the joint's gravity torque, averaged per set-point
        levels = {
            (lv["direction"], round(abs(lv["velocity"]), 2)): lv["load"]
            for lv in res.gravity.joint_levels(joint)
        }
        bd = r.by_direction
        keys = zip(bd.direction.astype(int), np.abs(bd.velocity).round(2), strict=True)
        want = [levels[(d, float(v))] for d, v in keys]
        np.testing.assert_allclose(bd.load, want, rtol=0, atol=1e-12)
        assert r.samples.meta["extract"]["gravity"] == "arm"
        assert r.samples.meta["gravity"]["method"] == "arm"


def _one_joint_passes(rng, model, base):
    """Random passes of a one-joint robot: positions over part of a turn, torques with a
    friction per set-point, a gravity and noise."""
    stats_arm, stats_eq7, group, direction = [], [], [], []
    for k in range(6):
        for _ in range(3):
            q = np.sort(rng.uniform(-2.0, 2.0, 80)) + rng.uniform(-0.3, 0.3)
            tau = 0.3 * np.cos(q) - 0.2 * np.sin(q) + 0.1 * (k + 1) + rng.normal(0, 0.01, q.size)
            w = base.columns(model.gravity_regressor(q[:, None]))[:, 0, :]
            stats_arm.append(arm_moments(w, tau))
            stats_eq7.append(moments(q, tau))
            group.append(k)
            direction.append(1 if k % 2 else -1)
    return np.array(stats_arm), np.array(stats_eq7), np.array(group), np.array(direction)


def test_one_joint_robot_arm_fit_is_eq7_joint_fit():
    """On a one-joint robot the arm fit is eq. 7's joint fit (without the load-dependent
    friction term): the same frictions, standard errors and gravity torque."""
    path, _ = example_urdf("double_pendulum")
    model = RigidBodyModel.from_urdf(path, ["joint1"])
    base = base_parameters(model, gravity_only=True)
    assert base.rank == 2
    arm, eq7, group, direction = _one_joint_passes(np.random.default_rng(5), model, base)
    sol = solve_levels(arm, group)
    ref = fit_gravity_joint(eq7, group, direction, load_friction=False)
    np.testing.assert_allclose(sol.level, ref.friction, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(sol.level_se, ref.friction_se, rtol=1e-7)
    q = np.linspace(-3, 3, 13)
    w = base.columns(model.gravity_regressor(q[:, None]))[:, 0, :]
    # fricid's motor torque is tau_f + g (robot) = tau_f - tau_g (eq. 8)
    np.testing.assert_allclose(w @ sol.beta, -ref.torque(q), rtol=1e-9, atol=1e-12)
    assert sol.determined.all()


def test_one_joint_robot_extract_arm_agrees_with_single_joint_extract():
    """End to end on a one-joint robot: the arm path's frictions agree with the single-joint
    path's (eq. 7, joint fit) within their standard errors."""
    path, _ = example_urdf("double_pendulum")
    model = RigidBodyModel.from_urdf(path, ["joint1"])
    laws = {"joint1": PENDULUM_LAWS["joint1"]}
    log = arm_sweeps(model, {"joint1": (-1.5, 1.5)}, {"joint1": [np.zeros(1)]}, laws, seed=4)
    res = extract_arm(log, perturbed(model, np.random.default_rng(2)))
    single = extract(log.joint("joint1"), gravity="joint")
    a, b = res["joint1"].by_direction, single.by_direction
    np.testing.assert_allclose(a.velocity, b.velocity, rtol=1e-6)
    se = np.hypot(_level_se(res, "joint1"), single.gravity.friction_se)
    assert np.all(np.abs(a.friction - b.friction) < 3 * se)
    # the load is eq. 7's gravity torque tau_g (eq. 8: tau_m = tau_f - tau_g)
    np.testing.assert_allclose(a.load, b.load, atol=0.01)


def test_unswept_parameters_keep_the_urdf_values(pendulum):
    """Only joint 1 swept, joint 2 held at one position: the base parameters the sweeps
    cannot tell apart keep the URDF's values, are named, and have no standard error."""
    truth, ident, _ = pendulum
    log = arm_sweeps(
        truth, {"joint1": (-1.2, 1.2)}, {"joint1": [np.array([0.0, 0.4])]}, PENDULUM_LAWS
    )
    res = extract_arm(log, ident)
    fit = res.gravity
    assert list(res) == ["joint1"]
    assert np.isnan(fit.beta_se).any() and fit.notes
    assert "do not determine" in fit.notes[0]
    err = res["joint1"].by_direction.friction - PENDULUM_LAWS["joint1"](
        res["joint1"].by_direction.velocity
    )
    assert _rms(err) < 3 * _rms(_level_se(res, "joint1"))


def test_errors_name_the_joint(pendulum):
    truth, ident, log = pendulum
    with pytest.raises(ConfigError, match="elbow"):
        extract_arm(log, ident, joints=["elbow"])
    with pytest.raises(DataError, match="joint2"):
        extract_arm(log.select(["joint1"]), ident)
    held = arm_sweeps(truth, {"joint1": (-1.2, 1.2)}, {"joint1": [np.zeros(2)]}, PENDULUM_LAWS)
    with pytest.raises(DataError, match="joint2: no constant-velocity sweep"):
        extract_arm(held, ident, joints=["joint1", "joint2"])


def test_identify_fit_recovers_each_joints_law_from_the_arm_samples(pendulum_result):
    """The per-direction samples of each joint go to the existing families: the
    Coulomb-viscous law per direction comes back from ``fricid.identify.fit``."""
    from fricid.identify import fit

    res = pendulum_result
    for joint, law in PENDULUM_LAWS.items():
        fitted = fit(res[joint].by_direction, "coulomb_viscous_asym")
        want = {"f_c_pos": law.fc_pos, "beta_pos": law.fv_pos}
        want |= {"f_c_neg": law.fc_neg, "beta_neg": law.fv_neg}
        for name, value in want.items():
            p = fitted.parameters[name]
            # measured: within 0.0022 N m (or N m s/rad) of the truth; the friction levels
            # are within about 0.001 N m, over speeds 0.2-0.8 rad/s
            assert abs(p.value - value) < 0.004, (joint, name, p)


def test_other_joints_moving_during_a_sweep(pendulum):
    """The other joint moves at constant speed (0.15 rad/s) through every sweep instead of
    being held: the Coriolis and centrifugal torques are the model's, the companion's own
    steady motion is a set-point of its joint, and every friction is recovered."""
    truth, ident, _ = pendulum
    spans = {"joint1": (-1.2, 1.2), "joint2": (-1.2, 1.2)}
    poses = {"joint1": [np.array([0.0, 0.3])], "joint2": [np.array([-0.4, 0.0])]}
    log = arm_sweeps(truth, spans, poses, PENDULUM_LAWS, companion=0.15, rate=50.0, seed=6)
    res = extract_arm(log, ident)
    for joint, law in PENDULUM_LAWS.items():
        bd = res[joint].by_direction
        assert np.any(np.isclose(np.abs(bd.velocity), 0.15, rtol=0.02))
        assert _rms(bd.friction - law(bd.velocity)) < 3 * _rms(_level_se(res, joint))
    z = [
        (lv["friction"] - PENDULUM_LAWS[lv["joint"]](lv["velocity"])) / lv["friction_se"]
        for lv in res.gravity.levels
    ]
    assert np.all(np.abs(z) < 4), z
