"""ROS 2 bags in the fleet (issue 13): a bag folder and a bare .mcap file as manifest rows, the
joint, topic and effort kind per row, and the manifest's reader columns against the registry."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import DataError
from fricid.fleet import FIELDS, SerialExecutor, read_manifest, run_fleet
from fricid.fleet.hashing import input_hash
from fricid.fleet.manifest import SCHEMA
from fricid.io import READER_OPTIONS, READERS
from fricid.sim import preset, simulate_log
from fricid.workflow import EXTRACT_OPTIONS

TS = get_typestore(Stores.ROS2_HUMBLE)
JointState = TS.types["sensor_msgs/msg/JointState"]
Header = TS.types["std_msgs/msg/Header"]
Time = TS.types["builtin_interfaces/msg/Time"]
T0 = 1_700_000_000_000_000_000


def bag_of_simulated_joint(path: Path, joint: str, *, effort: str) -> tuple[Path, float, float]:
    """A bag whose /joint_states carry the horizontal virtual joint ``joint`` (and a second
    joint at rest), effort as motor current [A] or torque [N m]. Returns the path, K and the
    log's temperature."""
    s = preset("paper2", "quick")
    log = simulate_log(s, seed=5)
    k = float(log.torque_constant)
    values = log.current if effort == "current" else log.current * k
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        conn = w.add_connection("/joint_states", JointState.__msgtype__, typestore=TS)
        for t, q, dq, e in zip(log.time, log.position, log.velocity, values, strict=True):
            ns = T0 + round(t * 1e9)
            stamp = Time(sec=ns // 10**9, nanosec=ns % 10**9)
            msg = JointState(
                header=Header(stamp=stamp, frame_id=""),
                name=["base", joint],
                position=np.array([0.0, q]),
                velocity=np.array([0.0, dq]),
                effort=np.array([0.0, e]),
            )
            w.write(conn, ns, TS.serialize_cdr(msg, JointState.__msgtype__))
    return path, k, float(np.mean(log.temperature))


@pytest.fixture(scope="module")
def bag_fleet(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bagfleet")
    (folder / "bags").mkdir()
    _, k, temp = bag_of_simulated_joint(folder / "bags" / "run1", "elbow", effort="current")
    other, _, _ = bag_of_simulated_joint(folder / "tmp2", "axis_3", effort="torque")
    mcap = folder / "bags" / "run2.mcap"
    shutil.copyfile(next(other.glob("*.mcap")), mcap)
    manifest = folder / "fleet.csv"
    manifest.write_text(
        "robot,joint,log,reader,log_joint,topic,effort,torque_constant [N m/A],"
        "temperature [degC],model\n"
        f"r1,elbow,bags/run1,rosbag,,/joint_states,current,{k!r},{temp!r},stribeck\n"
        f"r2,j3,bags/run2.mcap,rosbag,axis_3,,torque,,{temp!r},stribeck\n",
        encoding="utf-8",
    )
    return manifest


def test_manifest_rows_carry_the_bag_options(bag_fleet):
    a, b = read_manifest(bag_fleet).joints
    assert a.reader_options["joint"] == "elbow"  # the joint column, by default
    assert a.reader_options["effort"] == "current" and a.reader_options["topic"] == "/joint_states"
    assert b.reader_options["joint"] == "axis_3"  # log_joint names the bag's joint
    assert b.reader_options["effort"] == "torque" and "torque_constant" not in b.reader_options
    # a bag folder is hashed whole (its metadata and storage files), not refused as a folder
    assert input_hash(a.log, a.reader, a.reader_options) != input_hash(
        b.log, b.reader, b.reader_options
    )


@pytest.mark.slow  # 2 s measured under load (default run kept short)
def test_fleet_runs_a_bag_folder_and_an_mcap_file(bag_fleet, tmp_path):
    run = run_fleet(bag_fleet, tmp_path / "out", executor=SerialExecutor(), date="2026-03-01")
    assert run.failed == 0, run.failures
    table = run.table.sort_values("robot").reset_index(drop=True)
    assert list(table["joint"]) == ["elbow", "j3"]
    # the same simulated joint, read as current times K and as torque: the same fit
    params = [c for c in table.columns if c.startswith("param_")]
    assert "param_tau_c" in params
    for c in params:
        assert table[c][0] == pytest.approx(table[c][1], rel=1e-6), c


def test_a_bag_option_under_another_reader_is_refused(tmp_path):
    path = tmp_path / "m.csv"
    path.write_text("robot,joint,log,topic\nr,j,x.parquet,/joint_states\n", encoding="utf-8")
    with pytest.raises(DataError, match="'topic' is an option of reader rosbag") as info:
        read_manifest(path)
    assert info.value.row == 2 and info.value.column == "topic"


def test_every_reader_option_has_a_manifest_column():
    """The schema's reader columns and the registry's reader options agree both ways, and so
    do the readers and the extraction options."""
    props = SCHEMA["$defs"]["fields"]["properties"]
    assert props["reader"]["enum"] == list(READERS)
    columns = {f.option for f in FIELDS.values() if f.group == "reader"}
    columns.add("joint")  # the joint column fills the rosbag reader's 'joint' by default
    assert columns == {o for opts in READER_OPTIONS.values() for o in opts}
    assert {n for n, f in FIELDS.items() if f.group == "extract"} == set(EXTRACT_OPTIONS)
    from fricid.extract import GRAVITY_MODES

    assert props["gravity"]["enum"] == list(GRAVITY_MODES)


def test_fleet_help_lists_every_column_from_the_schema():
    res = CliRunner().invoke(app, ["fleet", "--help"], terminal_width=400)
    assert res.exit_code == 0
    text = " ".join(res.output.split())
    for name in FIELDS:
        assert f"{name}" in text, name
    assert "log_joint: rosbag: the joint's name in JointState.name" in text
