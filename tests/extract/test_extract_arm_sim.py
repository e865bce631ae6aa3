"""Sweeps on arms against the whole-arm simulator (fricid.sim.robot): a PD drive tracking
constant-velocity sweeps with the other joint drifting, a 2^17-count encoder, the velocity as
the drive logs it (backward differences), per-direction Stribeck friction, torque noise."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

pytest.importorskip("pinocchio")

from fricid.extract import extract, extract_arm
from fricid.robot import RigidBodyModel, base_parameters, example_urdf
from fricid.samples import RobotLog
from fricid.sim.robot import simulate_robot
from fricid.sim.robot_friction import ArmFriction
from fricid.sim.robot_reference import sweep_reference

FRICTION = ArmFriction(
    pos={
        "tau_c": [0.10, 0.06],
        "tau_s": [0.12, 0.08],
        "w_s": [0.05, 0.05],
        "tau_v": [0.05, 0.03],
        "delta": [1.0, 1.0],
    },
    neg={
        "tau_c": [0.08, 0.07],
        "tau_s": [0.10, 0.09],
        "w_s": [0.05, 0.05],
        "tau_v": [0.04, 0.035],
        "delta": [1.0, 1.0],
    },
)


def _friction(j: int, v) -> np.ndarray:
    """Joint ``j``'s true friction at velocities ``v`` (the other joint at rest)."""
    vv = np.zeros((np.size(v), 2))
    vv[:, j] = v
    return FRICTION(vv)[:, j]


def _campaign(truth) -> RobotLog:
    """Each joint swept at 0.3, 0.6 and 1 rad/s over [-1, 1] rad, the other drifting
    (0.8 rad amplitude, 20 s period); the two runs joined end to end."""
    logs = []
    for j, hold, drift in ((0, [0.0, 0.4], [0.0, 0.8]), (1, [-0.3, 0.0], [0.8, 0.0])):
        ref = sweep_reference(hold, j, [0.3, 0.6, 1.0], -1.0, 1.0, drift=drift, drift_period=20.0)
        logs.append(
            simulate_robot(
                truth,
                ref,
                FRICTION,
                rate=500.0,
                torque_noise=0.01,
                seed=j,
                feedforward=True,
                bandwidth=20.0,
            )
        )
    second = logs[1].time - logs[1].time[0] + logs[0].time[-1] + 1.0 / 500.0
    return RobotLog(
        time=np.concatenate([logs[0].time, second]),
        joints=truth.joints,
        position=np.vstack([g.position for g in logs]),
        velocity=np.vstack([g.velocity for g in logs]),
        torque=np.vstack([g.torque for g in logs]),
        temperature=25.0,
        source="simulated sweeps",
    )


@pytest.mark.slow  # about 25 s: the simulation of 59 s of sweeps at 500 Hz
def test_arm_sweeps_on_the_arm_simulator():
    path, joints = example_urdf("double_pendulum")
    truth = RigidBodyModel.from_urdf(path, joints)
    log = _campaign(truth)
    pi = truth.parameters().reshape(2, 10)
    ident = truth.with_parameters((pi * np.array([1.15, 0.85])[:, None]).ravel())
    res = extract_arm(log, ident)
    g = res.gravity
    beta_true = base_parameters(ident, gravity_only=True).project(truth.parameters())
    assert np.all(np.abs(g.beta - beta_true) < 4 * g.beta_se)
    for lv in g.levels:
        j = truth.joints.index(lv["joint"])
        err = lv["friction"] - _friction(j, lv["velocity"])[0]
        assert abs(err) < 4 * lv["friction_se"], lv
    # measured: arm path 0.0015 / 0.0013 N m RMS, eq. 7 path 0.13 / 0.16 N m,
    # friction 0.12 / 0.085 N m RMS
    for j, joint in enumerate(truth.joints):
        bd = res[joint].by_direction
        arm = np.sqrt(np.mean((bd.friction - _friction(j, bd.velocity)) ** 2))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            e7 = extract(log.joint(joint), gravity="joint").by_direction
        eq7 = np.sqrt(np.mean((e7.friction - _friction(j, e7.velocity)) ** 2))
        size = np.sqrt(np.mean(_friction(j, bd.velocity) ** 2))
        assert arm < 0.05 * size < eq7, (joint, arm, eq7, size)
