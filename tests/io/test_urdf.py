"""Eq. 7's gravity coefficients from a URDF (issue 13, current to torque): a hand computation
on a two-link arm written by the test, the virtual joint's p_x, p_y written as a URDF, and
bad files refused in one line naming the file and the element."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fricid.errors import ConfigError, DataError
from fricid.io.urdf import MAX_BYTES, STANDARD_GRAVITY, read_urdf, urdf_gravity
from fricid.sim import preset, true_gravity

G = STANDARD_GRAVITY

TWO_LINK = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/>
  <link name="upper">
    <inertial><origin xyz="0.15 0 0" rpy="0.3 0.2 0.1"/><mass value="2"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
  </link>
  <link name="fore">
    <inertial><origin xyz="{com}"/><mass value="1"/></inertial>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="fore"/>
    <origin xyz="0.3 0 0" rpy="{rpy}"/><axis xyz="{axis}"/>
  </joint>
</robot>
"""


def _write(tmp_path, text, name="robot.urdf"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.fixture(
    params=[("0 0 0", "0 1 0", "0.1 0 0.02"), ("0 0 1.5707963267948966", "1 0 0", "0 -0.1 0.02")]
)
def arm(tmp_path, request):
    """The same arm twice: the elbow's axis along y, or along x in a frame yawed by 90 deg
    (the forearm's centre of mass written in that frame)."""
    rpy, axis, com = request.param
    return _write(tmp_path, TWO_LINK.format(rpy=rpy, axis=axis, com=com))


def test_two_links_by_hand(arm):
    # shoulder, elbow at 0: centres of mass at x = 0.15 (2 kg) and 0.4, z = +0.02 (1 kg) from
    # the axis; p_x = g sum m x, p_y = -g sum m z (module docstring: axis +y, x is +x)
    got = urdf_gravity(arm, "shoulder")
    assert got.p_x == pytest.approx(G * (2 * 0.15 + 1 * 0.4), abs=1e-12)
    assert got.p_y == pytest.approx(-G * 0.02, abs=1e-12)
    assert got.mass == 3 and set(got.links) == {"upper", "fore"}
    # elbow at +90 deg turns the forearm's centre to (0.02, -0.1) from the elbow
    bent = urdf_gravity(arm, "shoulder", {"elbow": math.pi / 2})
    assert bent.p_x == pytest.approx(G * (0.3 + 0.32), abs=1e-12)
    assert bent.p_y == pytest.approx(G * 0.1, abs=1e-12)
    # the elbow alone, with the shoulder at 0 and at +90 deg
    assert urdf_gravity(arm, "elbow").p_x == pytest.approx(G * 0.1, abs=1e-12)
    assert urdf_gravity(arm, "elbow").p_y == pytest.approx(-G * 0.02, abs=1e-12)
    up = urdf_gravity(arm, "elbow", {"shoulder": math.pi / 2})
    assert (up.p_x, up.p_y) == pytest.approx((G * 0.02, G * 0.1), abs=1e-12)


def test_eq7_is_the_torque_about_the_axis(arm):
    """p_x cos - p_y sin equals the torque computed from the kinematics at any angle."""
    from fricid.io.urdf import _link_frames

    robot = read_urdf(arm)
    load = urdf_gravity(arm, "shoulder", {"elbow": 0.7})
    for theta in np.linspace(-3, 3, 7):
        frames, joints = _link_frames(robot, {"elbow": 0.7, "shoulder": theta})
        rot, origin = joints["shoulder"]
        tau = 0.0
        for name in ("upper", "fore"):
            r, p = frames[name]
            c = p + r @ robot.links[name].com - origin
            m = robot.links[name].mass
            tau += float((rot @ np.array([0, 1.0, 0])) @ np.cross(c, [0, 0, -m * G]))
        assert load.torque(theta) == pytest.approx(tau, abs=1e-12)


def virtual_joint_urdf(tmp_path, p_x, p_y, mass=1.5):
    """A URDF whose joint 'elbow' has eq. 7's p_x, p_y: one link of ``mass`` on a y axis,
    its centre at x = p_x / (m g), z = -p_y / (m g) from the axis (module docstring)."""
    x, z = p_x / (mass * G), -p_y / (mass * G)
    return _write(
        tmp_path,
        f"""<robot name="virtual">
  <link name="world"/><link name="base"/>
  <link name="arm"><inertial><origin xyz="{x!r} 0.05 {z!r}"/>
    <mass value="{mass!r}"/></inertial></link>
  <joint name="fix" type="fixed"><parent link="world"/><child link="base"/>
    <origin xyz="0 0 0.8"/></joint>
  <joint name="elbow" type="continuous"><parent link="base"/><child link="arm"/>
    <origin xyz="0.1 0 0.2"/><axis xyz="0 1 0"/></joint>
</robot>""",
        "virtual.urdf",
    )


def test_the_virtual_joint_written_as_urdf(tmp_path):
    p = true_gravity(preset("paper1", "quick"))
    got = urdf_gravity(virtual_joint_urdf(tmp_path, *p), "elbow")
    assert (got.p_x, got.p_y) == pytest.approx(p, rel=1e-12)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("<robot><link name='a'/>", "not XML"),
        ("<!DOCTYPE r [<!ENTITY x 'y'>]><robot/>", "DOCTYPE"),
        ("<robot xmlns:xacro='http://ros.org/wiki/xacro'><xacro:macro name='m'/></robot>", "xacro"),
        ("<model/>", "not <robot>"),
        (
            "<robot><link name='a'><inertial><mass value='heavy'/></inertial></link></robot>",
            r"<link name='a'> <inertial><mass>: value='heavy' is not 1 plain decimal numbers",
        ),
        (
            "<robot><link name='a'/><joint name='j' type='revolute'><parent link='a'/>"
            "<child link='b'/></joint></robot>",
            r"<joint name='j'>: names link 'b', which is not defined",
        ),
        (
            "<robot><link name='a'/><link name='b'/><joint name='j' type='revolute'>"
            "<parent link='a'/><child link='b'/><origin xyz='0 0 nan'/></joint></robot>",
            r"<joint name='j'> <origin>: xyz='0 0 nan' is not 3 plain decimal numbers",
        ),
        ("<robot><link name='a'/><link name='b'/></robot>", "one tree"),
    ],
)
def test_bad_files_one_line(tmp_path, text, match):
    path = _write(tmp_path, text)
    with pytest.raises(DataError, match=match) as info:
        read_urdf(path)
    assert str(info.value).startswith(str(path)) and "\n" not in str(info.value)


def test_an_expanded_xacro_with_its_namespace_loads(tmp_path):
    text = TWO_LINK.format(rpy="0 0 0", axis="0 1 0", com="0.1 0 0.02").replace(
        '<robot name="arm">', '<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">'
    )
    got = urdf_gravity(_write(tmp_path, text), "shoulder")
    assert got.p_x == pytest.approx(G * 0.7, abs=1e-12)


def test_size_cap(tmp_path, monkeypatch):
    import fricid.io._urdf_text as urdf_text

    monkeypatch.setattr(urdf_text, "MAX_BYTES", 100)
    path = _write(tmp_path, "<robot>" + " " * 200 + "</robot>")
    with pytest.raises(DataError, match="over the 100"):
        read_urdf(path)
    assert MAX_BYTES >= 1 << 20


def test_bad_joint_choices(arm, tmp_path):
    with pytest.raises(ConfigError, match="no joint 'wrist'; its rotating joints: shoulder, elbow"):
        urdf_gravity(arm, "wrist")
    with pytest.raises(ConfigError, match="'knee', which is not a moving joint"):
        urdf_gravity(arm, "shoulder", {"knee": 1.0})
    vertical = _write(tmp_path, TWO_LINK.format(rpy="0 0 0", axis="0 0 1", com="0.1 0 0"), "v.urdf")
    with pytest.raises(DataError, match="elbow'>: its axis is vertical"):
        urdf_gravity(vertical, "elbow")
