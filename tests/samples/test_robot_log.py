"""RobotLog: all joints of a robot in one validated table; one joint as today's RawLog."""

from __future__ import annotations

import numpy as np
import pytest

from fricid.errors import DataError
from fricid.samples import RawLog, RobotLog

N = 50


def columns(k: int = 3, n: int = N) -> dict:
    t = np.arange(n) * 0.01
    j = np.arange(1, k + 1)
    return {
        "time": t,
        "joints": tuple(f"j{i}" for i in j),
        "position": np.sin(t)[:, None] * j,
        "velocity": np.cos(t)[:, None] * j,
        "torque": 0.1 * np.sign(np.cos(t))[:, None] + 0.01 * j,
    }


def test_columns_are_checked_and_frozen():
    log = RobotLog(**columns(), temperature=30.0, source="arm.csv")
    assert log.n_joints == 3 and len(log) == N
    assert log.position.shape == (N, 3) and log.temperature.shape == (N, 3)
    assert np.all(log.temperature == 30.0)
    np.testing.assert_array_equal(log.motor_torque, log.torque)
    with pytest.raises(AttributeError):
        log.time = log.time  # frozen


def test_one_joint_is_a_rawlog_for_single_joint_tools():
    log = RobotLog(**columns(), temperature=30.0, source="arm.csv", meta={"robot": "r"})
    raw = log.joint("j2")
    assert isinstance(raw, RawLog) and raw.joint == "j2" and raw.source == "arm.csv"
    np.testing.assert_array_equal(raw.position, log.position[:, 1])
    np.testing.assert_array_equal(raw.motor_torque, log.torque[:, 1])
    assert raw.meta["robot_joints"] == ["j1", "j2", "j3"] and raw.meta["robot"] == "r"
    # without a temperature in the log, one must be given
    bare = RobotLog(**columns())
    with pytest.raises(DataError, match=r"j1\.temperature.*no temperature"):
        bare.joint("j1")
    assert np.all(bare.joint("j1", temperature=20.0).temperature == 20.0)
    with pytest.raises(DataError, match=r"no joint 'elbow'.*j1, j2, j3"):
        bare.joint("elbow")


def test_current_needs_a_torque_constant_per_joint():
    cols = columns()
    current = cols.pop("torque") * 10.0
    with pytest.raises(DataError, match="torque constant K"):
        RobotLog(**cols, current=current)
    with pytest.raises(DataError, match=r"shape \(2,\)"):
        RobotLog(**cols, current=current, torque_constants=[0.1, 0.1])
    with pytest.raises(DataError, match=r"column 'j2\.torque_constant'"):
        RobotLog(**cols, current=current, torque_constants=[0.1, -0.1, 0.1])
    log = RobotLog(**cols, current=current, torque_constants=[0.1, 0.2, 0.3])
    np.testing.assert_allclose(log.motor_torque, current * [0.1, 0.2, 0.3])
    raw = log.joint("j3", temperature=25.0)
    assert raw.torque_constant == 0.3 and raw.torque is None


def test_a_nan_names_its_row_and_joint_column():
    cols = columns()
    cols["torque"][5, 1] = np.nan
    with pytest.raises(DataError) as info:
        RobotLog(**cols)
    assert info.value.row == 5 and info.value.column == "j2.torque"


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"joints": ("a", "b", "a")}, "joint 'a' is named twice"),
        ({"joints": ("a", "", "c")}, "non-empty string"),
        ({"joints": ()}, "at least one joint"),
        ({"joints": "abc"}, "sequence of joint names"),
        ({"velocity": np.zeros((N - 1, 3))}, r"velocity has shape \(49, 3\), expected \(50, 3\)"),
        ({"position": np.zeros((N, 2))}, r"expected \(50, 3\)"),
        ({"torque": None}, "neither torque nor current"),
        ({"acceleration": np.full((N, 3), 1e20)}, "impossible value"),
    ],
)
def test_bad_columns_are_refused(change, message):
    with pytest.raises(DataError, match=message):
        RobotLog(**{**columns(), **change})


def test_time_must_increase():
    cols = columns()
    cols["time"][7] = cols["time"][6]
    with pytest.raises(DataError, match="not strictly increasing") as info:
        RobotLog(**cols)
    assert info.value.row == 7 and info.value.column == "time"


def test_select_rename_slice():
    log = RobotLog(**columns(), acceleration=np.zeros((N, 3)), load=np.ones((N, 3)))
    two = log.select(["j3", "j1"])
    assert two.joints == ("j3", "j1")
    np.testing.assert_array_equal(two.torque, log.torque[:, [2, 0]])
    np.testing.assert_array_equal(two.load, log.load[:, [2, 0]])
    with pytest.raises(DataError, match="no joint 'j9'"):
        log.select(["j9"])
    with pytest.raises(DataError, match="named twice"):
        log.select(["j1", "j1"])
    renamed = log.rename({"j1": "shoulder"})
    assert renamed.joints == ("shoulder", "j2", "j3") and log.joints[0] == "j1"
    with pytest.raises(DataError, match="named twice"):
        log.rename({"j1": "j2"})
    with pytest.raises(DataError, match="no joint 'x'"):
        log.rename({"x": "y"})
    part = log.slice(10, 20)
    assert len(part) == 10 and part.acceleration.shape == (10, 3)
    np.testing.assert_array_equal(part.time, log.time[10:20])
    np.testing.assert_array_equal(part.velocity, log.velocity[10:20])


def test_one_joint_accepts_plain_columns():
    cols = columns(k=1)
    log = RobotLog(
        time=cols["time"],
        joints=["only"],
        position=cols["position"][:, 0],
        velocity=cols["velocity"][:, 0],
        current=cols["torque"][:, 0],
        torque_constants=0.5,
    )
    assert log.position.shape == (N, 1) and log.torque_constants.tolist() == [0.5]
