"""Robot logs from ROS 2 bags: every joint of a JointState topic, written with the rosbags
writer and read back."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from fricid.errors import ConfigError, DataError
from fricid.io import read_robot_log, read_rosbag, write_robot_log

TS = get_typestore(Stores.ROS2_HUMBLE)
JointState = TS.types["sensor_msgs/msg/JointState"]
Temperature = TS.types["sensor_msgs/msg/Temperature"]
Header = TS.types["std_msgs/msg/Header"]
Time = TS.types["builtin_interfaces/msg/Time"]

T0 = 1_700_000_000_000_000_000
N = 120
DT = 2_000_000  # 500 Hz
NAMES = ["panda_joint1", "panda_joint2", "panda_joint3"]


def header(ns: int) -> object:
    return Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id="")


def truth() -> dict[str, np.ndarray]:
    t = np.arange(N) * DT * 1e-9
    j = np.arange(1, 4)
    return {
        "time": t,
        "position": np.sin(t)[:, None] * j,
        "velocity": np.cos(t)[:, None] * j,
        "effort": 0.3 * np.sign(np.cos(t))[:, None] + 0.1 * j,
    }


def write_bag(
    path: Path,
    *,
    velocity: bool = True,
    effort: bool = True,
    nan_at: tuple[int, int] | None = None,
    shuffle: bool = False,
    storage: StoragePlugin = StoragePlugin.MCAP,
    t0: int = T0,
) -> Path:
    """/joint_states naming the three arm joints (order reversed in odd messages when
    ``shuffle``), a gripper publisher on the same topic, /temperature at 10 Hz."""
    x = truth()
    with Writer(path, version=9, storage_plugin=storage) as w:
        js = w.add_connection("/joint_states", JointState.__msgtype__, typestore=TS)
        tc = w.add_connection("/temperature", Temperature.__msgtype__, typestore=TS)
        for i in range(N):
            ns = t0 + i * DT
            order = [2, 1, 0] if shuffle and i % 2 else [0, 1, 2]
            eff = x["effort"][i].copy()
            if nan_at is not None and nan_at[0] == i:
                eff[nan_at[1]] = np.nan
            msg = JointState(
                header=header(ns),
                name=[NAMES[k] for k in order],
                position=x["position"][i, order],
                velocity=x["velocity"][i, order] if velocity else np.array([], dtype=float),
                effort=eff[order] if effort else np.array([], dtype=float),
            )
            w.write(js, ns + 100_000, TS.serialize_cdr(msg, JointState.__msgtype__))
            if i % 40 == 3:
                grip = JointState(
                    header=header(ns),
                    name=["finger"],
                    position=np.array([0.01]),
                    velocity=np.array([0.0]),
                    effort=np.array([0.0]),
                )
                w.write(js, ns + 200_000, TS.serialize_cdr(grip, JointState.__msgtype__))
            if i % 50 == 0:
                temp = Temperature(header=header(ns), temperature=30.0 + i / 50, variance=0.0)
                w.write(tc, ns + 300_000, TS.serialize_cdr(temp, Temperature.__msgtype__))
    return path


@pytest.fixture(scope="module")
def bag(tmp_path_factory) -> Path:
    return write_bag(tmp_path_factory.mktemp("robot") / "run1", shuffle=True)


def test_every_joint_of_the_topic(bag):
    log = read_robot_log(bag, temperature_topic="/temperature")
    x = truth()
    assert log.joints == tuple(NAMES) and len(log) == N  # the gripper's messages skipped
    np.testing.assert_allclose(log.time, x["time"], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(log.position, x["position"])  # shuffled order undone
    np.testing.assert_array_equal(log.velocity, x["velocity"])
    np.testing.assert_array_equal(log.torque, x["effort"])
    assert log.meta["time_origin_ns"] == T0 and log.meta["time_source"] == "header"
    assert log.temperature.shape == (N, 3) and log.temperature[25, 2] == pytest.approx(30.5)
    # one joint of it is today's single-joint log
    one = read_rosbag(bag, "panda_joint2", temperature_topic="/temperature")
    raw = log.joint("panda_joint2")
    np.testing.assert_array_equal(raw.torque, one.torque)
    np.testing.assert_array_equal(raw.position, one.position)


def test_joints_mapped_and_selected_by_name(bag):
    log = read_robot_log(bag, joints=["Panda_Joint3", "panda_joint1"], temperature=20.0)
    assert log.joints == ("Panda_Joint3", "panda_joint1")
    np.testing.assert_array_equal(log.torque, truth()["effort"][:, [2, 0]])
    assert log.meta["joints_left_out"] == ["panda_joint2"]
    # the gripper's publisher alone matches by name too
    assert read_robot_log(bag, joints=["finger"], temperature=20.0).joints == ("finger",)
    with pytest.raises(
        DataError, match=r"messages name: \[panda_joint1, panda_joint2, panda_joint3\]"
    ):
        read_robot_log(bag, joints=["panda_joint1", "wrist"])


def test_current_with_a_torque_constant_per_joint(bag):
    k = {"panda_joint1": 0.1, "panda_joint2": 0.2, "panda_joint3": 0.4}
    log = read_robot_log(bag, effort="current", effort_unit="mA", torque_constants=k)
    np.testing.assert_allclose(log.current, 1e-3 * truth()["effort"])
    np.testing.assert_allclose(log.motor_torque, 1e-3 * truth()["effort"] * [0.1, 0.2, 0.4])
    with pytest.raises(DataError, match="torque constant K"):
        read_robot_log(bag, effort="current")
    with pytest.raises(ConfigError, match="missing: panda_joint3"):
        read_robot_log(
            bag, effort="current", torque_constants={"panda_joint1": 1, "panda_joint2": 1}
        )
    with pytest.raises(ConfigError, match="'A' is not a torque unit"):
        read_robot_log(bag, effort_unit="A")


def test_velocity_from_positions_when_the_topic_has_none(tmp_path):
    log = read_robot_log(write_bag(tmp_path / "b", velocity=False))
    assert log.meta["velocity_from"] == "position (central difference)"
    np.testing.assert_allclose(log.velocity[1:-1], truth()["velocity"][1:-1], atol=1e-5)


def test_a_joint_without_torque_is_named(tmp_path):
    bag = write_bag(tmp_path / "nan", nan_at=(7, 1))
    with pytest.raises(DataError, match="non-finite") as info:
        read_robot_log(bag)
    err = info.value
    assert err.file == str(bag) and err.column == "panda_joint2.torque"
    assert err.row == 8  # the message index on the topic: the gripper published number 4
    empty = write_bag(tmp_path / "empty", effort=False)
    with pytest.raises(DataError, match="no effort for joint 'panda_joint1'") as info:
        read_robot_log(empty)
    assert info.value.row == 0


def test_round_trip_through_a_table_and_sqlite_storage(tmp_path):
    bag = write_bag(tmp_path / "db", storage=StoragePlugin.SQLITE3)
    log = read_robot_log(bag, temperature=25.0)
    back = read_robot_log(write_robot_log(log, tmp_path / "arm.parquet"))
    np.testing.assert_array_equal(back.torque, log.torque)
    np.testing.assert_array_equal(back.time, log.time)
    assert back.meta["time_origin_ns"] == T0


def test_two_bags_join_on_their_absolute_time(tmp_path):
    first = write_bag(tmp_path / "a")
    second = write_bag(tmp_path / "b", t0=T0 + 10 * 10**9)  # 10 s later
    log = read_robot_log([first, second])
    assert len(log) == 2 * N and log.meta["files"] == [str(first), str(second)]
    np.testing.assert_allclose(log.time[N:], 10.0 + truth()["time"], rtol=0, atol=1e-9)
    with pytest.raises(DataError, match="time does not go on increasing") as info:
        read_robot_log([second, first])
    assert info.value.file == str(first)
