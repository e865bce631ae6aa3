"""The robot MJCF export (fricid.export.robot_mjcf), loaded and run in MuJoCo, and MuJoCo as a
second truth of the whole-arm simulator (benchmarks/_robot_truth.py)."""

from __future__ import annotations

import math
import sys
from functools import cache

import numpy as np
import pytest

pytest.importorskip("pinocchio")
mujoco = pytest.importorskip("mujoco")

from _paths import REPO  # noqa: E402
from fricid.export import ExportError  # noqa: E402
from fricid.export.robot_mjcf import (  # noqa: E402
    joint_friction,
    robot_mjcf_text,
    write_robot_mjcf,
)
from fricid.robot import RigidBodyModel, example_urdf  # noqa: E402
from fricid.sim.robot_friction import example_friction  # noqa: E402
from fricid.sim.robot_reference import FourierTrajectory  # noqa: E402

sys.path.insert(0, str(REPO / "benchmarks"))
from _robot_truth import simulate_robot_mujoco  # noqa: E402


@cache
def arm(name: str) -> RigidBodyModel:
    path, joints = example_urdf(name)
    return RigidBodyModel.from_urdf(path, joints)


def states(model: RigidBodyModel, count: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    lo = np.where(np.isfinite(model.lower), model.lower, -math.pi)
    hi = np.where(np.isfinite(model.upper), model.upper, math.pi)
    margin = 0.02 * (hi - lo)  # inside the ranges: no limit constraint acts
    q = rng.uniform(lo + margin, hi - margin, (count, model.n))
    v, a = rng.uniform(-2, 2, (2, count, model.n))
    return q, v, a


def mj_inverse(text: str, q, v, a) -> np.ndarray:
    m = mujoco.MjModel.from_xml_string(text)
    d = mujoco.MjData(m)
    out = np.empty_like(q)
    for k in range(q.shape[0]):
        d.qpos[:], d.qvel[:], d.qacc[:] = q[k], v[k], a[k]
        mujoco.mj_inverse(m, d)
        out[k] = d.qfrc_inverse
    return out


@pytest.mark.parametrize("name", ["panda", "ur5", "double_pendulum"])
def test_mjcf_inverse_dynamics_and_gravity_match_the_model(name):
    model = arm(name)
    text, notes = robot_mjcf_text(model)
    assert notes == []
    q, v, a = states(model, 20)
    expected = model.inverse_dynamics(q, v, a)
    scale = np.abs(expected).max()
    assert np.abs(mj_inverse(text, q, v, a) - expected).max() < 1e-9 * scale
    gravity = mj_inverse(text, q, np.zeros_like(v), np.zeros_like(a))
    assert np.allclose(gravity, model.gravity_torque(q), rtol=1e-9, atol=1e-9 * scale)


def test_mjcf_holds_changed_inertial_parameters():
    model = arm("double_pendulum")
    pi = model.parameters()
    pi[:10] *= 1.5  # first body 1.5 times denser: still physical
    changed = model.with_parameters(pi)
    q, v, a = states(model, 5, 1)
    text, _ = robot_mjcf_text(changed)
    assert np.allclose(mj_inverse(text, q, v, a), changed.inverse_dynamics(q, v, a), atol=1e-12)
    assert not np.allclose(mj_inverse(text, q, v, a), model.inverse_dynamics(q, v, a))


def test_mjcf_friction_damping_and_notes():
    model = arm("panda")
    friction = example_friction(model.effort_limit)
    text, notes = robot_mjcf_text(model, friction)
    m = mujoco.MjModel.from_xml_string(text)
    for i, joint in enumerate(model.joints):
        p = friction.parameters(i)
        jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, joint)
        assert m.dof_frictionloss[jid] == pytest.approx(0.5 * (p["tau_c_pos"] + p["tau_c_neg"]))
        assert m.dof_damping[jid] == pytest.approx(0.5 * (p["tau_v_pos"] + p["tau_v_neg"]))
        assert m.jnt_range[jid].tolist() == pytest.approx([model.lower[i], model.upper[i]])
    assert sum("differ by direction" in n for n in notes) == 7
    assert sum("Stribeck" in n for n in notes) == 7
    assert all(n.replace("'", "") in text.replace("'", "") for n in notes)
    # damping is a passive force: mj_inverse adds it to the rigid-body torque
    q, v, a = states(model, 5, 2)
    damping = np.linspace(0.1, 0.7, 7)
    per_joint = {j: {"tau_v": d} for j, d in zip(model.joints, damping, strict=True)}
    text, notes = robot_mjcf_text(model, per_joint)
    assert notes == []
    assert np.allclose(mj_inverse(text, q, v, a), model.inverse_dynamics(q, v, a) + damping * v)


def test_joint_friction_of_symmetric_coulomb_viscous_has_no_notes():
    assert joint_friction("j", {"tau_c": 0.3, "tau_v": 0.1}) == (0.3, 0.1, [])
    with pytest.raises(ExportError):
        joint_friction("j", {"w_s": 0.1})
    lugre = {"sigma_0": 1e4, "sigma_1": 0.3, "sigma_2": 0.05, "tau_c": 0.12, "tau_s": 0.18}
    fl, damping, notes = joint_friction("j", {**lugre, "w_s": 0.05, "delta": 2.0})
    assert (fl, damping) == (0.12, 0.05)
    assert any("LuGre" in n for n in notes) and any("Stribeck" in n for n in notes)


def test_write_robot_mjcf_is_atomic_and_refuses_bad_friction(tmp_path):
    model = arm("double_pendulum")
    path, _ = write_robot_mjcf(model, tmp_path / "arm.xml", {"joint1": {"tau_c": 0.2}})
    assert mujoco.MjModel.from_xml_path(str(path)).dof_frictionloss.tolist() == [0.2, 0.0]
    target = tmp_path / "bad.xml"
    with pytest.raises(ExportError):
        write_robot_mjcf(model, target, {"elbow": {"tau_c": 0.2}})
    with pytest.raises(ExportError):
        write_robot_mjcf(model, target, example_friction([1.0, 1.0, 1.0]))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.xml"]


def test_mujoco_truth_torque_is_inverse_dynamics_plus_friction_within_noise():
    """MuJoCo steps the exported Panda under the simulator's drive: the logged torque minus the
    model's inverse dynamics of MuJoCo's motion minus MuJoCo's friction is the sensor noise."""
    model = arm("panda")
    rng = np.random.default_rng(1)
    lo, hi = model.lower, model.upper
    a, b = rng.uniform(-0.4, 0.4, (2, 7, 4))
    ref = FourierTrajectory(model.joints, 2 * math.pi * 0.2, 0.5 * (lo + hi), a, b)
    noise = 0.05
    run = simulate_robot_mujoco(
        model,
        ref,
        example_friction(model.effort_limit),
        duration=1.5,
        torque_noise=noise,
        seed=2,
        feedforward=True,
    )
    t = run.truth
    q = 0.5 * (t.position[1:] + t.position[:-1])
    v = 0.5 * (t.velocity[1:] + t.velocity[:-1])
    acc = np.diff(t.velocity, axis=0) * 1000.0
    residual = run.log.torque[:-1] - model.inverse_dynamics(q, v, acc) - t.friction(v)
    moving = np.abs(v) > 0.05
    assert moving.mean() > 0.7
    for j in range(7):
        r = residual[moving[:, j], j]
        assert abs(r.mean()) < 0.2 * noise
        assert r.std() == pytest.approx(noise, rel=0.1)
    assert run.log.meta["simulated"] == "mujoco"
    assert np.abs(t.position - t.reference[0]).max() < 0.05


def test_a_light_joint_slides_at_its_frictionloss():
    """The Panda's wrist joint (frictionloss 0.6 N m, a few 1e-3 kg m^2 about its axis)
    moving alone at 0.3 and 1 rad/s holds its frictionloss in MuJoCo with the exported
    solreffriction; with MuJoCo's default time constant it held 0.19 and 0.70 of it."""
    model = arm("panda")
    fl = 0.6
    friction = {j: {"f_c": fl, "beta": 0.2} for j in model.joints}
    text, _ = robot_mjcf_text(model, friction)
    assert 'solreffriction="0.002 1"' in text
    m = mujoco.MjModel.from_xml_string(text)
    d = mujoco.MjData(m)

    def held(v: float) -> float:
        mujoco.mj_resetData(m, d)
        d.qpos[:] = 0.5 * (model.lower + model.upper)
        d.qvel[6] = v
        mujoco.mj_forward(m, d)
        return -float(d.qfrc_constraint[6])

    assert held(0.3) == pytest.approx(fl, rel=0.02)
    assert held(1.0) == pytest.approx(fl, rel=0.02)
    m.dof_solref[6] = (0.02, 1.0)  # MuJoCo's default
    assert held(0.3) < 0.5 * fl


def breakaway_share(text: str, joint: int, model: RigidBodyModel, level: float) -> float:
    """The motor torque, as a share of ``level``, at which ``joint`` of the MJCF ``text``
    (gravity off, the others at rest mid-range) first moves faster than 1 % of its speed at
    the end of a 0.5 s ramp to 1.5 ``level`` (the export check's break-away test)."""
    m = mujoco.MjModel.from_xml_string(text)
    d = mujoco.MjData(m)
    m.opt.gravity[:] = 0.0
    d.qpos[:] = 0.5 * (model.lower + model.upper)
    n = round(0.5 / m.opt.timestep)
    u = 1.5 * level * np.arange(n) / n
    v = np.empty(n)
    for k in range(n):
        d.ctrl[:] = 0.0
        d.ctrl[joint] = u[k]
        mujoco.mj_step(m, d)
        v[k] = d.qvel[joint]
    return float(u[np.argmax(np.abs(v) > 0.01 * abs(v[-1]))] / level)


def test_a_heavy_joint_breaks_away_at_its_frictionloss():
    """The Panda's shoulder (joint 1, the whole arm about its axis) under a slow torque ramp
    breaks away at its frictionloss with the exported solimpfriction; with MuJoCo's default
    (0.9 0.95) the soft constraint let it creep and slide at 0.13 of it, the elbow (joint 4)
    at 0.55."""
    model = arm("panda")
    fl = 0.6
    text, _ = robot_mjcf_text(model, {j: {"f_c": fl, "beta": 0.2} for j in model.joints})
    assert text.count('solimpfriction="0.99 0.999 0.001"') == model.n
    for joint in (0, 3, 6):
        assert 0.98 <= breakaway_share(text, joint, model, fl) <= 1.06
    default = text.replace('solimpfriction="0.99 0.999 0.001"', "")
    assert breakaway_share(default, 0, model, fl) < 0.5


def test_non_physical_inertia_is_refused():
    model = arm("double_pendulum")
    pi = model.parameters()
    pi[9] = 10 * (pi[4] + pi[6])  # Izz far above Ixx + Iyy: no body has that
    with pytest.raises(ExportError, match="joint1"):
        robot_mjcf_text(model.with_parameters(pi))


def test_fitted_models_and_coulomb_viscous_names_are_exported():
    """A joint's friction as a fitted model (any family: its Coulomb-viscous projection per
    direction) or in the Coulomb-viscous families' names f_c, beta."""
    from fricid.fitted import FittedModel

    model = arm("double_pendulum")
    cv = FittedModel.from_values(
        "coulomb_viscous", {"f_c": 0.3, "beta": 0.1}, operating_range={"velocity": [-2, 2]}
    )
    text, notes = robot_mjcf_text(model, {"joint1": cv, "joint2": {"f_c": 0.2, "beta": 0.05}})
    m = mujoco.MjModel.from_xml_string(text)
    for joint, (fl, damping) in (("joint1", (0.3, 0.1)), ("joint2", (0.2, 0.05))):
        jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, joint)
        assert m.dof_frictionloss[jid] == pytest.approx(fl)
        assert m.dof_damping[jid] == pytest.approx(damping)
    assert notes == []
