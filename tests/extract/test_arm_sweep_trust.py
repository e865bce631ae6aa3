"""Sweeps on arms from data that could mislead: a coarse encoder's finite-difference velocity,
sweeps too short to tell gravity from friction, a held joint that creeps, and the samples
file against the arm fit it reports (fricid.extract.arm)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

pytest.importorskip("pinocchio")

from _arm_sweeps import Law, arm_sweeps, perturbed
from fricid.errors import DataQualityWarning
from fricid.extract.arm import CONFOUNDED, extract_arm
from fricid.robot import RigidBodyModel, example_urdf
from fricid.samples import RobotLog

LAWS = {"joint1": Law(0.10, 0.08, 0.05, 0.04), "joint2": Law(0.06, 0.07, 0.03, 0.035)}
EVERY_POSE = {
    "joint1": [np.array([0.0, q]) for q in (-0.9, 0.0, 0.9)],
    "joint2": [np.array([q, 0.0]) for q in (-0.9, 0.0, 0.9)],
}


@pytest.fixture(scope="module")
def pendulum():
    path, joints = example_urdf("double_pendulum")
    return RigidBodyModel.from_urdf(path, joints)


def _extract(log, model, **kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = extract_arm(log, perturbed(model, np.random.default_rng(3)), **kwargs)
    return result, [str(w.message) for w in caught if issubclass(w.category, DataQualityWarning)]


def test_short_sweeps_that_confound_gravity_and_friction_are_warned(pendulum):
    """Joint 1 swept over 0.8 rad on one side, joint 2 nearly still: the gravity parameters'
    error alone moves the set-point frictions by more than the samples' scatter (they come
    out up to 0.06 N m off, 6x the noise), and fricid says so."""
    poses = {"joint1": [np.array([0.0, q]) for q in (0.0, 0.01, 0.02)]}
    log = arm_sweeps(pendulum, {"joint1": (0.6, 1.4)}, poses, LAWS, seed=1)
    result, found = _extract(log, pendulum)
    assert any(m.startswith(CONFOUNDED) and "joint1" in m for m in found), found
    assert any(n.startswith(CONFOUNDED) for n in result.gravity.notes)
    meta = result["joint1"].by_direction.meta["gravity"]
    assert any(n.startswith(CONFOUNDED) for n in meta["notes"])


def test_sweeps_of_every_joint_in_several_poses_are_not_warned(pendulum):
    spans = {"joint1": (-1.2, 1.2), "joint2": (-1.2, 1.2)}
    log = arm_sweeps(pendulum, spans, EVERY_POSE, LAWS, rate=50.0, seed=2)
    _, found = _extract(log, pendulum)
    assert not any(m.startswith(CONFOUNDED) for m in found), found


def test_a_held_joint_that_creeps_is_not_taken_for_a_sweep(pendulum):
    """Joint 2 creeps at 2 mrad/s while joint 1 sweeps 2.4 rad: its steady runs are no
    sweep, so it is left out (with a note) unless asked for by name."""
    poses = {"joint1": EVERY_POSE["joint1"]}
    log = arm_sweeps(
        pendulum, {"joint1": (-1.2, 1.2)}, poses, LAWS, seed=1, companion=0.002,
        velocity_noise=1e-5,
    )  # fmt: skip
    result, _ = _extract(log, pendulum)
    assert list(result) == ["joint1"]
    note = [n for n in result.gravity.notes if n.startswith("joint2: not swept")]
    assert note and "held joint's creep" in note[0]
    asked, _ = _extract(log, pendulum, joints=["joint1", "joint2"])
    assert list(asked) == ["joint1", "joint2"]


def test_the_samples_rows_are_the_levels_the_fit_reports(pendulum):
    """Each per-direction row holds its level's friction and count (one to one), so the
    printed table (``setpoints``), the samples file and the shared gravity error agree."""
    spans = {"joint1": (-1.2, 1.2), "joint2": (-1.2, 1.2)}
    log = arm_sweeps(pendulum, spans, EVERY_POSE, LAWS, rate=50.0, seed=2)
    result, _ = _extract(log, pendulum)
    for joint in result:
        bd = result[joint].by_direction
        levels = result.gravity.joint_levels(joint)
        written = sorted(zip(bd.friction.tolist(), bd.count.tolist(), strict=True))
        fitted = sorted((lv["friction"], lv["count"]) for lv in levels)
        assert written == fitted
        rows = result.setpoints(joint)
        assert all(np.isfinite(r["friction_se"]) and r["passes"] >= 1 for r in rows)
        assert sorted(r["friction"] for r in rows) == sorted(bd.friction.tolist())


def _coarse(log: RobotLog, counts: int) -> RobotLog:
    """``log`` as a drive with an encoder of ``counts`` per turn logs it: quantised position,
    velocity by backward differences."""
    step = 2 * np.pi / counts
    q = np.round(log.position / step) * step
    v = np.vstack([np.zeros((1, q.shape[1])), np.diff(q, axis=0) / np.diff(log.time)[:, None]])
    return RobotLog(
        time=log.time, joints=log.joints, position=q, velocity=v, torque=log.torque,
        temperature=25.0 * np.ones_like(q),
    )  # fmt: skip


def test_a_coarse_encoder_s_sweeps_are_read_at_their_speed(pendulum):
    """2^17 counts at 1 kHz: 0.05 rad/s is about one count per sample, and the finite
    difference reads 0, 1 or 2 counts. The arm fit reads the position's slope, as each
    joint's samples do, so its levels sit at the swept speeds (with the finite difference
    a 0.05 rad/s sweep's levels read 0.096) and agree with the samples written."""
    poses = {"joint1": EVERY_POSE["joint1"][:2]}
    clean = arm_sweeps(
        pendulum, {"joint1": (-0.3, 0.3)}, poses, LAWS, speeds=(0.05, 0.1), repeats=1,
        rate=1000.0, velocity_noise=0.0, seed=4,
    )  # fmt: skip
    result, found = _extract(_coarse(clean, 2**17), pendulum, joints=["joint1"])
    assert any("coarse encoder" in m and "joint1" in m for m in found), found
    speeds = np.array([abs(lv["velocity"]) for lv in result.gravity.levels])
    assert np.all(np.min(np.abs(speeds[:, None] / [0.05, 0.1] - 1), axis=1) < 0.02), speeds
    rows = result.setpoints("joint1")
    v, f, se = (np.array([r[k] for r in rows]) for k in ("velocity", "friction", "friction_se"))
    assert np.all(np.abs(f - LAWS["joint1"](v)) < 3 * se)


def test_directions_the_sweeps_barely_vary_keep_the_urdf(pendulum):
    """Joint 1 swept with joint 2 held within 0.02 rad: two combinations of the gravity
    parameters move the torque along the sweeps by under 1 % of the strongest (relative
    eigenvalues near 1e-5): they keep the URDF's values and are reported undetermined, and
    the set-point frictions stay within their errors of the law."""
    poses = {"joint1": [np.array([0.0, q]) for q in (0.0, 0.01, 0.02)]}
    log = arm_sweeps(pendulum, {"joint1": (-1.2, 1.2)}, poses, LAWS, seed=1)
    result, _ = _extract(log, pendulum)
    g = result.gravity
    assert not g.identified or not np.isfinite(g.beta_se).all()
    assert any("do not determine the base gravity" in n for n in g.notes)
    rows = result.setpoints("joint1")
    v, f, se = (np.array([r[k] for r in rows]) for k in ("velocity", "friction", "friction_se"))
    assert np.all(np.abs(f - LAWS["joint1"](v)) < 3 * se)


def test_a_swept_joint_s_creep_while_another_sweeps_is_left_out(pendulum):
    """Both joints swept in one log, each creeping at 2 mrad/s while the other sweeps: those
    creeping runs are no set-points (their torque holds the joint; it does not slide), so
    each joint keeps its swept speeds only, in the fit and in its samples, with a note."""
    spans = {"joint1": (-1.2, 1.2), "joint2": (-1.2, 1.2)}
    log = arm_sweeps(
        pendulum, spans, EVERY_POSE, LAWS, rate=50.0, seed=2, companion=0.002,
        velocity_noise=1e-5,
    )  # fmt: skip
    result, _ = _extract(log, pendulum)
    assert list(result) == ["joint1", "joint2"]
    for joint in result:
        speeds = {round(abs(lv["velocity"]), 2) for lv in result.gravity.joint_levels(joint)}
        assert speeds == {0.2, 0.4, 0.8}, (joint, speeds)
        assert np.all(np.abs(result[joint].by_direction.velocity) > 0.1)
        assert any(
            n.startswith(f"{joint}: ") and "left out of its set-points" in n
            for n in result.gravity.notes
        )
