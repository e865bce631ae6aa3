"""ROS 2 bags and MCAP: real bags written with the rosbags writer, read back as raw logs."""

from __future__ import annotations

import contextlib
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from fricid.errors import ConfigError, DataError
from fricid.io import iter_rosbag, read_rosbag, rosbag_joints, rosbag_topics
from fricid.samples import RawLog

TS = get_typestore(Stores.ROS2_HUMBLE)
JointState = TS.types["sensor_msgs/msg/JointState"]
Temperature = TS.types["sensor_msgs/msg/Temperature"]
Header = TS.types["std_msgs/msg/Header"]
Time = TS.types["builtin_interfaces/msg/Time"]

T0 = 1_700_000_000_000_000_000  # ns since the epoch: a realistic, large stamp
N = 500
DT = 2_000_000  # 500 Hz


def header(ns: int) -> object:
    return Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id="")


def truth(i: np.ndarray) -> dict[str, np.ndarray]:
    t = i * DT * 1e-9
    return {
        "time": t,
        "position": 0.3 * np.sin(t),
        "velocity": 0.3 * np.cos(t),
        "effort": 0.1 * np.sign(np.cos(t)) + 0.05 * np.cos(t),
    }


def write_bag(
    path: Path,
    storage: StoragePlugin = StoragePlugin.MCAP,
    *,
    effort: bool = True,
    stamps: bool = True,
    temperature: bool = True,
    other_publisher: bool = True,
) -> Path:
    """A bag with /joint_states (joints 'shoulder' and 'elbow'), an unrelated publisher on
    the same topic naming 'gripper' only, and /elbow/temperature at 10 Hz."""
    with Writer(path, version=9, storage_plugin=storage) as w:
        js = w.add_connection("/joint_states", JointState.__msgtype__, typestore=TS)
        tc = w.add_connection("/elbow/temperature", Temperature.__msgtype__, typestore=TS)
        for i in range(N):
            ns = T0 + i * DT
            x = truth(np.array(i))
            msg = JointState(
                header=header(ns if stamps else 0),
                name=["shoulder", "elbow"],
                position=np.array([1.0, x["position"]]),
                velocity=np.array([0.0, x["velocity"]]),
                effort=np.array([2.0, x["effort"]]) if effort else np.array([], dtype=float),
            )
            w.write(js, ns + 100_000, TS.serialize_cdr(msg, JointState.__msgtype__))
            if other_publisher and i % 50 == 7:
                other = JointState(
                    header=header(ns),
                    name=["gripper"],
                    position=np.array([0.01]),
                    velocity=np.array([0.0]),
                    effort=np.array([0.0]),
                )
                w.write(js, ns + 200_000, TS.serialize_cdr(other, JointState.__msgtype__))
            if temperature and i % 50 == 0:
                temp = Temperature(header=header(ns), temperature=30.0 + i / 50, variance=0.0)
                w.write(tc, ns + 300_000, TS.serialize_cdr(temp, Temperature.__msgtype__))
    return path


@pytest.fixture(scope="module")
def mcap_bag(tmp_path_factory) -> Path:
    return write_bag(tmp_path_factory.mktemp("bags") / "run1")


@pytest.mark.parametrize("storage", [StoragePlugin.MCAP, StoragePlugin.SQLITE3])
def test_reads_the_joint_in_si(tmp_path, storage):
    bag = write_bag(tmp_path / "bag", storage)
    log = read_rosbag(bag, "elbow", temperature_topic="/elbow/temperature")
    assert isinstance(log, RawLog) and len(log) == N
    x = truth(np.arange(N))
    np.testing.assert_allclose(log.time, x["time"], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(log.position, x["position"])
    np.testing.assert_array_equal(log.velocity, x["velocity"])
    np.testing.assert_array_equal(log.torque, x["effort"])
    assert log.joint == "elbow" and log.source == str(bag)
    assert log.meta["time_origin_ns"] == T0 and log.meta["time_source"] == "header"
    # temperature: linear between the 10 Hz readings, held after the last one
    assert log.temperature[0] == 30.0 and log.temperature[25] == pytest.approx(30.5)
    assert log.temperature[-1] == 39.0


def test_bare_mcap_file_and_topics(mcap_bag):
    mcap = next(mcap_bag.glob("*.mcap"))
    log = read_rosbag(mcap, "elbow", temperature=25.0)
    assert len(log) == N and np.all(log.temperature == 25.0)
    assert rosbag_topics(mcap) == {
        "/joint_states": "sensor_msgs/msg/JointState",
        "/elbow/temperature": "sensor_msgs/msg/Temperature",
    }
    assert rosbag_joints(mcap_bag) == ["shoulder", "elbow", "gripper"]


def test_effort_as_current_with_torque_constant(mcap_bag):
    log = read_rosbag(
        mcap_bag, "elbow", temperature=25.0, effort="current", effort_unit="mA", torque_constant=0.5
    )
    x = truth(np.arange(N))
    assert log.torque is None
    np.testing.assert_allclose(log.current, x["effort"] * 1e-3)
    np.testing.assert_allclose(log.motor_torque, x["effort"] * 0.5e-3)


def test_chunks_concatenate_to_the_whole(mcap_bag):
    whole = read_rosbag(mcap_bag, "elbow", temperature_topic="/elbow/temperature")
    chunks = list(
        iter_rosbag(mcap_bag, "elbow", temperature_topic="/elbow/temperature", chunk_rows=128)
    )
    assert [len(c) for c in chunks] == [128, 128, 128, 116]
    joined = RawLog.concatenate(chunks)
    for name in ("time", "position", "velocity", "torque", "temperature"):
        np.testing.assert_array_equal(getattr(joined, name), getattr(whole, name))


def test_receive_time_when_stamps_are_missing(tmp_path):
    bag = write_bag(tmp_path / "nostamp", stamps=False, temperature=False)
    log = read_rosbag(bag, "elbow", temperature=20.0)
    assert log.meta["time_source"] == "receive"
    np.testing.assert_allclose(log.time, truth(np.arange(N))["time"], atol=1e-12)
    with pytest.raises(DataError, match="time is not strictly increasing at JointState message 1"):
        read_rosbag(bag, "elbow", temperature=20.0, time_source="header")


def test_unknown_joint_lists_the_names_present(mcap_bag):
    with pytest.raises(DataError) as info:
        read_rosbag(mcap_bag, "wrist", temperature=25.0)
    assert str(info.value) == (
        f"{mcap_bag}: no joint 'wrist' on topic '/joint_states'; the joints there are: "
        "'shoulder', 'elbow', 'gripper'"
    )


def test_missing_topic_lists_the_topics(mcap_bag):
    with pytest.raises(DataError, match=r"no joint-state topic '/joints'.*/joint_states \("):
        read_rosbag(mcap_bag, "elbow", topic="/joints", temperature=25.0)
    with pytest.raises(DataError, match=r"carries sensor_msgs/msg/JointState, not .*Temperature"):
        read_rosbag(mcap_bag, "elbow", temperature_topic="/joint_states")


def test_missing_effort_is_an_error(tmp_path):
    bag = write_bag(tmp_path / "noeffort", effort=False, temperature=False)
    with pytest.raises(DataError, match=r"message 0 has no effort \(torque or current\)"):
        read_rosbag(bag, "elbow", temperature=25.0)


@pytest.mark.parametrize("fraction", [0.05, 0.5, 0.99])
@pytest.mark.parametrize("storage", [StoragePlugin.MCAP, StoragePlugin.SQLITE3])
def test_truncated_bag_is_a_clear_error(tmp_path, storage, fraction):
    bag = write_bag(tmp_path / "cut", storage)
    data = next(f for f in bag.iterdir() if f.suffix in (".mcap", ".db3"))
    os.truncate(data, int(data.stat().st_size * fraction))
    with pytest.raises(DataError, match="unreadable or truncated bag"):
        read_rosbag(bag, "elbow", temperature=25.0)


def test_unreadable_inputs(tmp_path):
    garbage = tmp_path / "junk.mcap"
    garbage.write_bytes(b"not a bag at all" * 8)
    with pytest.raises(DataError, match=r"junk.mcap: unreadable or truncated bag \(File magic"):
        read_rosbag(garbage, "elbow", temperature=25.0)
    with pytest.raises(DataError, match="no such bag"):
        read_rosbag(tmp_path / "missing", "elbow", temperature=25.0)
    broken = tmp_path / "broken"
    broken.mkdir()
    (broken / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    with pytest.raises(DataError, match="unreadable or truncated bag"):
        read_rosbag(broken, "elbow", temperature=25.0)


def test_corrupt_bytes_never_escape_as_tracebacks(tmp_path, mcap_bag):
    data = next(mcap_bag.glob("*.mcap")).read_bytes()
    rng = np.random.default_rng(0)
    for k in range(12):
        b = bytearray(data)
        for i in rng.integers(8, len(b) - 8, 20):
            b[i] = int(rng.integers(256))
        path = tmp_path / f"c{k}.mcap"
        path.write_bytes(bytes(b))
        # any clear error is fine; an exception of another kind fails the test
        with contextlib.suppress(DataError):
            read_rosbag(path, "elbow", temperature=25.0)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (
            {"effort": "current", "effort_unit": "N m", "torque_constant": 0.5},
            r"effort unit 'N m' is not a current unit \(it is a torque unit: pass "
            r"effort='torque'\)",
        ),
        ({"effort": "torque", "effort_unit": "A"}, "not a torque unit"),
        ({"effort": "current"}, "needs a positive torque constant"),
        ({"effort": "force"}, "effort must be one of: torque, current"),
        ({"velocity_unit": "m/s"}, "unknown velocity unit 'm/s'"),
        ({"time_source": "gps"}, "time_source must be one of"),
    ],
)
def test_bad_options(mcap_bag, options, message):
    with pytest.raises(ConfigError, match=message):
        read_rosbag(mcap_bag, "elbow", temperature=25.0, **options)


def test_temperature_is_given_at_most_once(mcap_bag):
    # neither: the log records none (its column a placeholder, not a made-up 25 degC)
    assert not read_rosbag(mcap_bag, "elbow").temperature_measured
    assert read_rosbag(mcap_bag, "elbow", temperature=25.0).temperature_measured
    with pytest.raises(ConfigError, match="not both"):
        read_rosbag(mcap_bag, "elbow", temperature=25.0, temperature_topic="/elbow/temperature")


def test_degrees_are_converted(tmp_path, mcap_bag):
    copy = tmp_path / "deg"
    shutil.copytree(mcap_bag, copy)
    log = read_rosbag(copy, "elbow", temperature=25.0, position_unit="deg", velocity_unit="deg/s")
    np.testing.assert_allclose(log.velocity, np.deg2rad(truth(np.arange(N))["velocity"]))


def test_registry_opens_a_bag_and_asks_for_the_joint(mcap_bag):
    from fricid.io import open_log

    with pytest.raises(ConfigError, match=r"joint.s name; .* has joints: shoulder, elbow"):
        open_log(mcap_bag, "rosbag", {})
    options = {"joint": "elbow", "temperature": 25.0}
    chunks = list(open_log(mcap_bag, "rosbag", options, chunk_rows=100))
    whole = read_rosbag(mcap_bag, **options)
    np.testing.assert_array_equal(np.concatenate([c.velocity for c in chunks]), whole.velocity)
