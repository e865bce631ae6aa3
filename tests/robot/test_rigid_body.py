"""The whole arm's rigid-body dynamics (fricid.robot): built from the checked URDF tree, it
must equal Pinocchio's own URDF parser; the regressor, base parameters and log-Cholesky
parametrisation must hold their identities."""

from __future__ import annotations

import math

import numpy as np
import pytest

pin = pytest.importorskip("pinocchio")

from fricid.errors import ConfigError, DataError  # noqa: E402
from fricid.io.urdf import read_urdf  # noqa: E402
from fricid.robot import (  # noqa: E402
    RigidBodyModel,
    base_parameters,
    example_urdf,
    from_log_cholesky,
    is_consistent,
    to_log_cholesky,
)


@pytest.fixture(scope="module")
def panda() -> RigidBodyModel:
    path, joints = example_urdf("panda")
    return RigidBodyModel.from_urdf(path, joints)


@pytest.mark.parametrize("name", ["panda", "ur5", "double_pendulum"])
def test_dynamics_equal_pinocchios_own_urdf_parser(name):
    path, joints = example_urdf(name)
    ours = RigidBodyModel.from_urdf(path, joints, gravity=9.81)  # Pinocchio's default g
    ref = pin.buildModelFromUrdf(str(path))
    locked = [ref.getJointId(n) for n in ref.names[1:] if n not in ours.joints]
    if locked:
        ref = pin.buildReducedModel(ref, locked, pin.neutral(ref))
    assert tuple(ref.names[1:]) == ours.joints
    data = ref.createData()
    rng = np.random.default_rng(1)
    q, dq, ddq = rng.normal(size=(3, 5, ours.n))
    tau = ours.inverse_dynamics(q, dq, ddq)
    for k in range(5):
        np.testing.assert_allclose(tau[k], pin.rnea(ref, data, q[k], dq[k], ddq[k]), atol=1e-9)
        np.testing.assert_allclose(ours.mass_matrix(q[k])[0], pin.crba(ref, data, q[k]), atol=1e-9)


def test_regressor_times_parameters_is_the_inverse_dynamics(panda):
    rng = np.random.default_rng(2)
    q, dq, ddq = rng.normal(size=(3, 6, 7))
    Y = panda.regressor(q, dq, ddq)
    assert Y.shape == (6, 7, 70)
    tau = panda.inverse_dynamics(q, dq, ddq)
    np.testing.assert_allclose(Y @ panda.parameters(), tau, atol=1e-9)
    Yg = panda.gravity_regressor(q)
    np.testing.assert_allclose(Yg @ panda.parameters(), panda.gravity_torque(q), atol=1e-9)
    # forward dynamics inverts the inverse dynamics
    tau = panda.inverse_dynamics(q, dq, ddq)
    np.testing.assert_allclose(panda.forward_dynamics(q, dq, tau), ddq, atol=1e-7)


def test_with_parameters_changes_the_dynamics_and_nothing_else(panda):
    pi = panda.parameters()
    heavier = pi.copy()
    heavier[60] *= 2.0  # the last body's mass
    other = panda.with_parameters(heavier)
    np.testing.assert_allclose(other.parameters(), heavier)
    np.testing.assert_allclose(panda.parameters(), pi)
    q = np.full(7, 0.3)
    assert not np.allclose(other.gravity_torque(q), panda.gravity_torque(q))


def test_the_pandas_base_parameters_are_its_43(panda):
    """43 base inertial parameters: the Panda's published count (friction apart)."""
    base = base_parameters(panda)
    assert base.rank == 43
    rng = np.random.default_rng(3)
    q, dq, ddq = rng.normal(size=(3, 4, 7))
    Y = panda.regressor(q, dq, ddq)
    for pi in (panda.parameters(), rng.normal(size=70)):  # any pi: a structural identity
        np.testing.assert_allclose(base.columns(Y) @ base.project(pi), Y @ pi, atol=1e-8)
    gravity = base_parameters(panda, gravity_only=True)
    assert gravity.kind == "gravity" and gravity.rank < base.rank
    Yg = panda.gravity_regressor(q)
    pi = rng.normal(size=70)
    np.testing.assert_allclose(gravity.columns(Yg) @ gravity.project(pi), Yg @ pi, atol=1e-8)


def test_the_double_pendulums_gravity_is_coupled():
    """The second joint's gravity goes as sin(q1 + q2) terms: it changes with q1, which the
    single-joint eq. 7 (BAS-RBFNN paper) cannot represent."""
    path, joints = example_urdf("double_pendulum")
    model = RigidBodyModel.from_urdf(path, joints)
    q = np.array([[0.0, 0.5], [0.7, 0.5]])
    g = model.gravity_torque(q)
    assert abs(g[0, 1] - g[1, 1]) > 0.05 * abs(g[0, 1])


def test_log_cholesky_round_trip_and_always_physical(panda):
    pi = panda.parameters()
    theta = to_log_cholesky(pi)
    np.testing.assert_allclose(from_log_cholesky(theta), pi, atol=1e-12)
    rng = np.random.default_rng(4)
    assert is_consistent(from_log_cholesky(rng.normal(size=70) * 2)).all()
    bad = pi[:10].copy()
    bad[0] = -1.0  # a negative mass
    assert not is_consistent(bad)[0]
    with pytest.raises(ConfigError, match="not physically consistent"):
        to_log_cholesky(bad)


URDF = """<robot name="r">
  <link name="base"/>
  <link name="a"><inertial><mass value="1"/><origin xyz="0.1 0 0"/>
    <inertia ixx="{ixx}" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="b"><inertial><mass value="1"/><origin xyz="0.1 0 0"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j1" type="{kind}"><parent link="base"/><child link="a"/><axis xyz="0 1 0"/>
    {limit}</joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.2 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="5" velocity="2"/>{mimic}</joint>
</robot>"""


def _write(tmp_path, **kw):
    values = {"ixx": "0.01", "kind": "revolute", "limit": "", "mimic": ""} | kw
    path = tmp_path / "r.urdf"
    path.write_text(URDF.format(**values))
    return path


def test_limits_are_read_and_continuous_joints_have_none(tmp_path):
    model = RigidBodyModel.from_urdf(_write(tmp_path, kind="continuous"))
    assert model.joints == ("j1", "j2")
    assert model.lower[0] == -math.inf and model.upper[1] == 1.0
    assert model.velocity_limit[1] == 2.0 and model.effort_limit[1] == 5.0
    assert model.effort_limit[0] == math.inf
    bad = _write(tmp_path, limit='<limit lower="1" upper="-1" effort="1" velocity="1"/>')
    with pytest.raises(DataError, match=r"lower=1\.0 is above upper=-1\.0"):
        read_urdf(bad)


def test_a_non_physical_inertia_is_noted_not_refused(tmp_path):
    model = RigidBodyModel.from_urdf(_write(tmp_path, ixx="0.05"))
    assert len(model.notes) == 1 and "triangle inequality" in model.notes[0]
    assert "link name='a'" in model.notes[0]


def test_mimic_joints_are_locked_by_default_and_names_are_checked(tmp_path):
    model = RigidBodyModel.from_urdf(_write(tmp_path, mimic='<mimic joint="j1"/>'))
    assert model.joints == ("j1",) and model.locked == {"j2": 0.0}
    path = _write(tmp_path)
    with pytest.raises(ConfigError, match="no revolute, continuous or prismatic joint 'nope'"):
        RigidBodyModel.from_urdf(path, ["j1", "nope"])
    with pytest.raises(ConfigError, match="must be finite"):
        RigidBodyModel.from_urdf(path, ["j1"], locked={"j2": float("nan")})
    # a locked joint moves the body it carries: the gravity of j1 depends on where j2 is
    down = RigidBodyModel.from_urdf(path, ["j1"], locked={"j2": 0.0}).gravity_torque([0.0])
    up = RigidBodyModel.from_urdf(path, ["j1"], locked={"j2": 1.0}).gravity_torque([0.0])
    assert abs(down[0, 0] - up[0, 0]) > 0.1


def test_a_floating_base_is_refused(tmp_path):
    text = URDF.format(ixx="0.01", kind="floating", limit="", mimic="")
    path = tmp_path / "f.urdf"
    path.write_text(text)
    with pytest.raises(DataError, match="only fixed-base robots"):
        RigidBodyModel.from_urdf(path)


def test_one_joint_regressor_keeps_its_joint_axis():
    """A one-joint robot's regressor is (N, 1, 10) like any other's (Pinocchio returns its
    1 x 10 matrix as a vector)."""
    path, _ = example_urdf("double_pendulum")
    model = RigidBodyModel.from_urdf(path, ["joint1"])
    q = np.array([[0.1], [0.7], [-1.2]])
    Y = model.gravity_regressor(q)
    assert Y.shape == (3, 1, 10)
    np.testing.assert_allclose(Y @ model.parameters(), model.gravity_torque(q), atol=1e-12)
