"""Robot logs from wide tables and per-channel folders: every joint at once, units from the
headers, joints mapped to the names asked for, hostile input named by file, row and column.
(Bags: tests/io/test_robot_bag.py.)"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fricid.errors import ConfigError, DataError
from fricid.io import read_robot_log, write_robot_log
from fricid.samples import ROBOT_COLUMNS, RobotLog
from fricid.units import DEG

N = 40
T = np.arange(N) * 0.01


def table(path, header: list[str], columns: list[np.ndarray], comments: str = ""):
    """A CSV of ``columns`` under ``header``, written as a user's tool would."""
    rows = np.column_stack(columns)
    lines = [",".join(header)] + [",".join(repr(float(v)) for v in row) for row in rows]
    path.write_text(comments + "\n".join(lines) + "\n", encoding="utf-8")
    return path


def arm(k: int = 2) -> dict[str, np.ndarray]:
    """Positions, velocities and torques of ``k`` joints (joint j moves j times as fast)."""
    j = np.arange(1, k + 1)
    return {
        "q": np.sin(T)[:, None] * j,
        "dq": np.cos(T)[:, None] * j,
        "tau": 0.2 * np.sign(np.cos(T))[:, None] + 0.1 * j,
    }


def indexed(path, k=2, *, forms=("q{}", "dq{}", "tau{}"), units=("rad", "rad/s", "N m")):
    x = arm(k)
    header = ["time [s]"]
    cols = [T]
    for form, unit, key in zip(forms, units, ("q", "dq", "tau"), strict=True):
        for j in range(k):
            header.append(f"{form.format(j + 1)} [{unit}]")
            cols.append(x[key][:, j])
    return table(path, header, cols), x


def test_indexed_columns_map_to_the_names_in_order(tmp_path):
    path, x = indexed(tmp_path / "arm.csv")
    log = read_robot_log(path, joints=["shoulder", "elbow"], temperature=25.0)
    assert log.joints == ("shoulder", "elbow") and len(log) == N
    np.testing.assert_array_equal(log.position, x["q"])
    np.testing.assert_array_equal(log.velocity, x["dq"])
    np.testing.assert_array_equal(log.torque, x["tau"])
    assert log.meta["joint_map"] == {"1": "shoulder", "2": "elbow"}
    assert log.source == str(path) and np.all(log.temperature == 25.0)
    # without joints= the file's own numbers are the names
    assert read_robot_log(path).joints == ("1", "2")


def test_units_from_the_headers_are_converted(tmp_path):
    x = arm(2)
    header = ["t [ms]", "q_1 [deg]", "q_2 [deg]", "dq_1 [deg/s]", "dq_2 [rpm]"]
    header += ["tau_1 [mN m]", "tau_2 [Nm]"]
    cols = [1e3 * T, x["q"][:, 0] / DEG, x["q"][:, 1] / DEG, x["dq"][:, 0] / DEG]
    cols += [x["dq"][:, 1] * 60 / (2 * np.pi), 1e3 * x["tau"][:, 0], x["tau"][:, 1]]
    path = table(tmp_path / "deg.csv", header, cols)
    log = read_robot_log(path)
    np.testing.assert_allclose(log.time, T, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(log.position, x["q"], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(log.velocity, x["dq"], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(log.torque, x["tau"], rtol=1e-12)


@pytest.mark.parametrize(
    "forms",
    [
        ("position_{}", "velocity_{}", "effort_{}"),
        ("{}_pos", "{}_vel", "{}_torque"),
        ("{}.position", "{}.velocity", "{}.tau"),
    ],
)
def test_named_columns_in_every_spelling(tmp_path, forms):
    x = arm(2)
    header, cols = ["time [s]"], [T]
    for form, unit, key in zip(forms, ("rad", "rad/s", "N m"), ("q", "dq", "tau"), strict=True):
        for j, name in enumerate(("Elbow_Joint", "shoulder")):
            header.append(f"{form.format(name)} [{unit}]")
            cols.append(x[key][:, j])
    path = table(tmp_path / "named.csv", header, cols)
    # exact names, then case-insensitive; order from joints=
    log = read_robot_log(path, joints=["shoulder", "elbow_joint"])
    assert log.joints == ("shoulder", "elbow_joint")
    np.testing.assert_array_equal(log.position, x["q"][:, [1, 0]])
    np.testing.assert_array_equal(log.torque, x["tau"][:, [1, 0]])


def test_zero_based_numbers_and_a_subset_by_name(tmp_path):
    path, x = indexed(tmp_path / "zero.csv", 3, forms=("q{}", "qd{}", "tau{}"))
    text = path.read_text().replace("q1 ", "q0 ").replace("q2 ", "q1 ").replace("q3 ", "q2 ")
    text = text.replace("qd1", "qd0").replace("qd2", "qd1").replace("qd3", "qd2")
    path.write_text(text.replace("tau1", "tau0").replace("tau2", "tau1").replace("tau3", "tau2"))
    log = read_robot_log(path, joints=["a", "b", "c"])
    np.testing.assert_array_equal(log.position, x["q"])
    # numbers are never a subset: two names asked of three joints is an error
    with pytest.raises(DataError, match=r"has 3 joints \('0', '1', '2'\) but 2 were asked"):
        read_robot_log(path, joints=["a", "b"])
    # names are: the joints named are taken, the rest left out
    named = table(
        tmp_path / "named.csv",
        ["time [s]", "a.q [rad]", "b.q [rad]", "a.tau [N m]", "b.tau [N m]"],
        [T, x["q"][:, 0], x["q"][:, 1], x["tau"][:, 0], x["tau"][:, 1]],
    )
    only = read_robot_log(named, joints=["B"])
    assert only.joints == ("B",)
    np.testing.assert_array_equal(only.position[:, 0], x["q"][:, 1])


def test_unknown_joint_lists_both_sides(tmp_path):
    path, _ = indexed(tmp_path / "arm.csv", forms=("{}_q", "{}_dq", "{}_tau"))
    path.write_text(path.read_text().replace("1_", "shoulder_").replace("2_", "elbow_"))
    with pytest.raises(DataError) as info:
        read_robot_log(path, joints=["shoulder", "wrist"])
    msg = str(info.value)
    assert str(path) in msg and "'shoulder', 'elbow'" in msg and "'shoulder', 'wrist'" in msg
    assert "'elbow' matches no name" in msg and "no joint of the file maps to 'wrist'" in msg
    with pytest.raises(DataError, match=r"2 joints .* but 3 were asked"):
        read_robot_log(path, joints=["shoulder", "elbow", "wrist"])
    with pytest.raises(ConfigError, match="more than once"):
        read_robot_log(path, joints=["shoulder", "shoulder"])


def test_velocity_from_the_positions_when_the_file_has_none(tmp_path):
    x = arm(2)
    path = table(
        tmp_path / "nov.csv",
        ["time [s]", "q1 [rad]", "q2 [rad]", "tau1 [N m]", "tau2 [N m]"],
        [T, x["q"][:, 0], x["q"][:, 1], x["tau"][:, 0], x["tau"][:, 1]],
    )
    log = read_robot_log(path)
    assert log.meta["velocity_from"] == "position (central difference)"
    # central differences of sin(t) j: cos(t) j to O(dt^2) inside
    np.testing.assert_allclose(log.velocity[1:-1], x["dq"][1:-1], atol=2e-5 * 2)


def test_one_joint_tables_still_work(tmp_path):
    x = arm(1)
    plain = table(
        tmp_path / "one.csv",
        ["time [s]", "position [deg]", "velocity [rad/s]", "current [mA]", "temperature [degC]"],
        [T, x["q"][:, 0] / DEG, x["dq"][:, 0], 1e3 * x["tau"][:, 0], np.full(N, 31.0)],
    )
    log = read_robot_log(plain, joints=["wrist"], torque_constants={"wrist": 0.5})
    assert log.joints == ("wrist",) and log.n_joints == 1
    np.testing.assert_allclose(log.position[:, 0], x["q"][:, 0], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(log.motor_torque[:, 0], 0.5 * x["tau"][:, 0], rtol=1e-12)
    raw = log.joint("wrist")
    assert raw.torque_constant == 0.5 and np.all(raw.temperature == 31.0)
    assert read_robot_log(plain, torque_constants=[0.5]).joints == ("joint",)
    numbered, _ = indexed(tmp_path / "q1.csv", 1)
    assert read_robot_log(numbered, joints=["wrist"]).joints == ("wrist",)


def test_nan_in_row_5_of_tau2_names_file_line_and_column(tmp_path):
    path, _ = indexed(tmp_path / "nan.csv")
    lines = path.read_text().splitlines()
    fields = lines[1 + 5].split(",")
    fields[6] = "nan"  # time, q1, q2, dq1, dq2, tau1, tau2
    lines[1 + 5] = ",".join(fields)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(DataError) as info:
        read_robot_log(path)
    err = info.value
    assert err.file == str(path) and err.row == 7 and err.column == "tau2 [N m]"  # line 7


def test_nan_in_a_parquet_table_names_the_record(tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    x = arm(2)
    tau2 = x["tau"][:, 1].copy()
    tau2[5] = np.nan
    cols = {"time [s]": T, "q1 [rad]": x["q"][:, 0], "q2 [rad]": x["q"][:, 1]}
    cols |= {"tau1 [N m]": x["tau"][:, 0], "tau2 [N m]": tau2}
    pq.write_table(pa.table(cols), tmp_path / "nan.parquet")
    with pytest.raises(DataError) as info:
        read_robot_log(tmp_path / "nan.parquet")
    assert info.value.row == 5 and info.value.column == "tau2 [N m]"


@pytest.mark.parametrize(
    ("header", "message"),
    [
        (
            ["time [s]", "q1 [rad]", "tau1 [N m]", "torque_1 [N m]"],
            r"torque of joint '1' is given twice",
        ),
        (["time [s]", "q1 [rad]", "tau1 [N m]", "tau1 [N m]"], "given twice"),
        (["time [s]", "q1 [rad]", "q2 [rad]", "tau1 [N m]"], r"joint '2' has no torque column"),
        (["time [s]", "q1 [rad]", "q2 [rad]", "tau1 [N m]", "i2 [A]"], r"joint '2' has no torque"),
        (["time [s]", "q1 [rad]", "dq2 [rad/s]", "tau1 [N m]", "tau2 [N m]"], "no position"),
        (
            ["time [s]", "q1 [rad]", "q2 [rad]", "dq1 [rad/s]", "tau1 [N m]", "tau2 [N m]"],
            "no velocity",
        ),
        (["time [s]", "q1", "tau1 [N m]"], r"column 'q1' has no unit; write it as 'q1 \[rad\]'"),
        (["time [s]", "q1 [furlong]", "tau1 [N m]"], "unknown position unit 'furlong'"),
        (["time [s]", "q1 [rad]", "tau1 [N m]", "q [rad]"], "'q \\[rad\\]' names no joint"),
        (["stamp [s]", "q1 [rad]", "tau1 [N m]"], "no time column"),
    ],
)
def test_hostile_headers_are_refused_by_name(tmp_path, header, message):
    path = table(tmp_path / "bad.csv", header, [np.arange(N) * 0.01] * len(header))
    with pytest.raises(DataError, match=message) as info:
        read_robot_log(path)
    assert info.value.file == str(path)


def test_time_not_increasing_and_short_rows(tmp_path):
    path, _ = indexed(tmp_path / "time.csv")
    lines = path.read_text().splitlines()
    lines[1 + 9] = ",".join(["0.05", *lines[1 + 9].split(",")[1:]])
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(DataError, match="not strictly increasing") as info:
        read_robot_log(path)
    assert info.value.row == 11 and info.value.column == "time [s]"
    assert "(0.08 then 0.05)" in str(info.value)  # the numbers, not np.float64(...)
    lines[1 + 9] = ",".join(lines[1 + 9].split(",")[:4])  # a row cut short
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(DataError, match="row has 4 fields, the header has 7") as info:
        read_robot_log(path)
    assert info.value.file == str(path) and info.value.row == 11


def test_a_single_joint_rawlog_file_is_a_one_joint_robot(tmp_path):
    from fricid.io import write_rawlog
    from fricid.samples import RawLog

    x = arm(1)
    raw = RawLog(
        time=T,
        position=x["q"][:, 0],
        velocity=x["dq"][:, 0],
        temperature=28.0,
        current=x["tau"][:, 0] / 0.2,
        torque_constant=0.2,
        joint="elbow",
    )
    log = read_robot_log(write_rawlog(raw, tmp_path / "elbow.csv"))
    assert log.joints == ("elbow",) and log.torque_constants.tolist() == [0.2]
    np.testing.assert_allclose(log.joint("elbow").motor_torque, raw.motor_torque, rtol=1e-15)
    with pytest.raises(ConfigError, match="temperature columns and temperature= was given"):
        read_robot_log(tmp_path / "elbow.csv", temperature=25.0)


def test_options_of_another_reader_are_refused(tmp_path):
    path, _ = indexed(tmp_path / "arm.csv")
    with pytest.raises(ConfigError, match="topic is not an option of the table reader"):
        read_robot_log(path, topic="/other")
    with pytest.raises(ConfigError, match="reader must be one of"):
        read_robot_log(path, reader="excel")
    with pytest.raises(ConfigError, match="cannot tell the layout"):
        read_robot_log(tmp_path / "arm.xlsx")


# --------------------------------------------------------------------------- writing


def full_log(k: int = 3) -> RobotLog:
    x = arm(k)
    return RobotLog(
        time=T + 100.0,
        joints=tuple(f"panda_joint{j + 1}" for j in range(k)),
        position=x["q"],
        velocity=x["dq"],
        torque=x["tau"],
        current=x["tau"] / np.linspace(0.1, 0.3, k),
        torque_constants=np.linspace(0.1, 0.3, k),
        acceleration=-x["q"],
        temperature=np.full((N, k), 30.5),
        load=0.5 * x["q"],
        source="sim",
        meta={"seed": 3, "robot": "panda"},
    )


def assert_same(a: RobotLog, b: RobotLog) -> None:
    assert a.joints == b.joints
    np.testing.assert_array_equal(a.time, b.time)
    for name in ROBOT_COLUMNS:
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            np.testing.assert_array_equal(x, y, err_msg=name)
    if a.torque_constants is None:
        assert b.torque_constants is None
    else:
        np.testing.assert_array_equal(a.torque_constants, b.torque_constants)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_round_trip_keeps_everything(tmp_path, suffix):
    log = full_log()
    path = write_robot_log(log, tmp_path / f"arm{suffix}")
    back = read_robot_log(path)
    assert_same(log, back)
    assert back.source == str(path)
    assert back.meta == {**log.meta, "recorded_source": "sim"}
    # mapped on reading, by name
    mapped = read_robot_log(path, joints=["PANDA_JOINT3", "panda_joint2", "panda_joint1"])
    np.testing.assert_array_equal(mapped.torque, log.torque[:, ::-1])
    np.testing.assert_array_equal(mapped.torque_constants, log.torque_constants[::-1])


def test_writing_refuses_what_cannot_be_read_back(tmp_path):
    log = full_log(1).rename({"panda_joint1": "a,b"})
    with pytest.raises(ConfigError, match="cannot be written in a table header"):
        write_robot_log(log, tmp_path / "x.csv")
    assert not (tmp_path / "x.csv").exists()
    with pytest.raises(ConfigError, match="needs a RobotLog"):
        write_robot_log(tmp_path / "x.csv", log)  # type: ignore[arg-type]


NAMES = st.text("abcXYZ_019/-", min_size=1, max_size=8).filter(lambda s: s == s.strip())


@st.composite
def robot_logs(draw):
    n = draw(st.integers(2, 12))
    names = draw(st.lists(NAMES, min_size=1, max_size=4, unique=True))
    k = len(names)
    finite = st.floats(-1e6, 1e6, allow_nan=False)

    def matrix():
        return np.array(
            draw(st.lists(st.lists(finite, min_size=k, max_size=k), min_size=n, max_size=n))
        )

    steps = draw(st.lists(st.floats(1e-6, 1e3), min_size=n, max_size=n))
    effort = draw(st.sampled_from(["torque", "current"]))
    return RobotLog(
        time=draw(st.floats(-1e6, 1e6)) + np.cumsum(steps),
        joints=names,
        position=matrix(),
        velocity=matrix(),
        torque=matrix() if effort == "torque" else None,
        current=matrix() if effort == "current" else None,
        torque_constants=None if effort == "torque" else np.full(k, 0.07),
        acceleration=matrix() if draw(st.booleans()) else None,
        temperature=draw(st.none() | st.floats(-40.0, 150.0)),
        meta={"note": draw(st.text(max_size=5))},
    )


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
@settings(
    max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(log=robot_logs())
def test_any_log_reads_back_as_written(tmp_path, suffix, log):
    back = read_robot_log(write_robot_log(log, tmp_path / f"r{suffix}"))
    assert_same(log, back)
    assert back.meta == log.meta


# --------------------------------------------------------------------------- channel files


def channel_folder(folder, *, rows=None, stamp_shift=0.0):
    """``pos_<joint>.txt``, ``vel_<joint>.txt``, ``tau_<joint>.txt`` of joints 1 and 2."""
    folder.mkdir(exist_ok=True)
    x = arm(2)
    for j in range(2):
        n = N if rows is None or j == 0 else rows
        t = T[:n] + (stamp_shift if j == 1 else 0.0)
        for name, values in (("pos", x["q"]), ("vel", x["dq"]), ("tau", x["tau"])):
            pairs = zip(t.tolist(), values[:n, j].tolist(), strict=True)
            lines = "".join(f"{a!r} {b!r}\n" for a, b in pairs)
            (folder / f"{name}_{j + 1}.txt").write_text(lines)
    return folder, x


PATTERNS = {"position": "pos_{joint}.txt", "velocity": "vel_{joint}.txt"}
PATTERNS |= {"torque": "tau_{joint}.txt"}
UNITS = {"position": "rad", "velocity": "rad/s", "torque": "N m"}


def test_channel_folder_of_two_joints(tmp_path):
    folder, x = channel_folder(tmp_path / "runs")
    log = read_robot_log(folder, joints=["shoulder", "elbow"], channels=PATTERNS, units=UNITS)
    assert log.joints == ("shoulder", "elbow") and log.temperature is None
    np.testing.assert_array_equal(log.time, T)
    np.testing.assert_array_equal(log.position, x["q"])
    np.testing.assert_array_equal(log.torque, x["tau"])
    assert log.meta["joint_map"] == {"1": "shoulder", "2": "elbow"}
    # deg files, converted
    units = {**UNITS, "position": "deg"}
    deg = read_robot_log(folder, channels=PATTERNS, units=units)
    np.testing.assert_allclose(deg.position, x["q"] * DEG)


def test_channel_joints_of_mismatched_lengths_are_refused(tmp_path):
    folder, _ = channel_folder(tmp_path / "short", rows=N - 5)
    with pytest.raises(DataError, match="joint '2' has 35 rows and joint '1' 40"):
        read_robot_log(folder, channels=PATTERNS, units=UNITS)
    with pytest.raises(ConfigError, match="position pattern"):
        read_robot_log(folder, channels={"velocity": "vel_{joint}.txt"}, units=UNITS)


def test_one_pattern_with_a_quantity_field(tmp_path):
    folder, x = channel_folder(tmp_path / "q")
    for old, new in (("pos", "position"), ("vel", "velocity"), ("tau", "torque")):
        for j in (1, 2):
            (folder / f"{old}_{j}.txt").rename(folder / f"{new}_{j}.txt")
    log = read_robot_log(folder, channels="{quantity}_{joint}.txt", units=UNITS)
    assert log.joints == ("1", "2") and "velocity_from" not in log.meta
    np.testing.assert_array_equal(log.velocity, x["dq"])
    no_velocity = {"position": "rad", "torque": "N m"}
    log = read_robot_log(folder, channels="{quantity}_{joint}.txt", units=no_velocity)
    assert log.meta["velocity_from"] == "position (central difference)"
    with pytest.raises(ConfigError, match=r"needs a \{quantity\} field"):
        read_robot_log(folder, channels="{joint}.txt", units=UNITS)


def test_more_numbered_joints_than_asked_say_how_to_name_them():
    """A file of three numbered joints read for a two-joint URDF: the error says why numbers
    cannot be matched and how to name the columns (a command-line user has no joints=)."""
    from fricid.io._robot_map import match_joints

    with pytest.raises(DataError, match="numbered columns cannot say which is which") as info:
        match_joints(["1", "2", "3"], ["shoulder", "elbow"], file="arm.csv")
    assert "'<joint>.position [rad]'" in str(info.value) and info.value.file == "arm.csv"
    with pytest.raises(DataError, match="not all by name"):
        match_joints(["shoulder", "wrist", "x"], ["shoulder", "elbow"], file="arm.csv")
