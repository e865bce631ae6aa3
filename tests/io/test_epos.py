"""fricid.io.epos: the Maxon EPOS Studio data-recorder CSV, on real and synthetic files."""

from __future__ import annotations

import hashlib
import logging
import math
import re
from pathlib import Path

import numpy as np
import pytest

from fricid.errors import ConfigError, DataError, DataQualityWarning
from fricid.io import (
    DEFAULT_NOMINAL_TORQUE,
    epos_steady_samples,
    read_epos,
    read_epos_dir,
)
from fricid.workflow import load_joint

RPM = 2 * math.pi / 60

HEADER = (
    "Date:;2020-07-08 21:28:28\r\n"
    "Firmware Version:;0x0120;0x6150;0x0000;0x0000\r\n"
    "EPOS Studio Version:;3.6.1.0\r\n"
    "Max. samples:;500\r\n"
    "Sampling period:;10.000\r\n"
    "Scale:;0;True;2.000;6.000;-14.000;2.000\r\n"
    "Scale:;1;True;5.000;27.550;-47.550;-7.550\r\n"
)
CHANNELS = ";Velocity actual value averaged;Torque actual value averaged\r\n"


def _epos(path: Path, rows: list[str], units: str = "ms;rpm;%", channels: str = CHANNELS):
    path.write_bytes((HEADER + channels + units + "\r\n" + "\r\n".join(rows) + "\r\n").encode())
    return path


def _rows(n: int = 5, v: float = -10.0, tau: float = -30.0) -> list[str]:
    return [f"{10.0 * i:.3f};{v:g};{tau:.1f}" for i in range(n)]


def _digest(folder: Path) -> str:
    h = hashlib.sha256()
    for p in sorted(folder.iterdir()):
        h.update(p.name.encode() + p.read_bytes())
    return h.hexdigest()


# --------------------------------------------------------------------------- real data


def test_real_file_header_units_and_position(leadscrew_dir):
    log = read_epos(leadscrew_dir / "2.csv")
    assert len(log) == 500
    assert log.meta["header"]["Sampling period"] == "128.000"
    assert log.meta["header"]["Recorded samples"] == "500"
    assert len(log.meta["header"]["Scale"]) == 2  # repeated key kept as a list
    assert log.meta["channels"] == {
        "velocity": "Velocity actual value averaged",
        "torque": "Torque actual value averaged",
    }
    np.testing.assert_allclose(np.diff(log.time), 0.128)  # ms -> s
    # first row: 0.000;-1;-32.8  (rpm, % of 9.84 mNm)
    assert log.velocity[0] == pytest.approx(-RPM)
    assert log.torque[0] == pytest.approx(-0.328 * DEFAULT_NOMINAL_TORQUE)
    assert log.current is None
    assert log.position[0] == 0.0 and log.meta["position_source"] == "integrated velocity"
    np.testing.assert_allclose(log.position[-1], np.trapezoid(log.velocity, log.time))


def test_real_file_given_no_temperature_says_so_and_its_samples_record_none(leadscrew_dir):
    log = read_epos(leadscrew_dir / "10.csv")
    # the recorder logs no temperature: the log's column is a placeholder, and says so
    assert not log.temperature_measured
    assert log.meta["temperature_source"].startswith("none")
    samples = load_joint(leadscrew_dir / "10.csv", "epos").samples
    assert "temperature" not in samples.measured and np.isnan(samples.temperature).all()
    assert samples.meta["temperature_source"].startswith("none")
    assert all(row["temperature"] is None for row in samples.meta["quality"])
    assert not any("degC" in row["label"] for row in samples.meta["quality"])
    given = read_epos(leadscrew_dir / "10.csv", temperature=30.0)
    assert given.temperature_measured and np.all(given.temperature == 30.0)
    samples = load_joint(leadscrew_dir / "10.csv", "epos", reader_options={"temperature": 30.0})
    assert "temperature" in samples.samples.measured and np.all(samples.samples.temperature == 30)


def test_real_folder_steady_samples_and_asymmetry(leadscrew_dir):
    before = _digest(leadscrew_dir)
    s = epos_steady_samples(leadscrew_dir)
    assert _digest(leadscrew_dir) == before  # inputs never modified
    assert len(s) == 32
    assert (s.direction == 1).sum() == 16 and (s.direction == -1).sum() == 16
    assert np.all(np.diff(s.velocity) > 0)  # sorted by set-point
    assert np.all(s.count == 500) and np.all(s.load == 0)
    # the recorder logs no temperature: none is made up (25 degC was, and printed as data)
    assert "temperature" not in s.measured and np.isnan(s.temperature).all()
    assert s.meta["temperature_source"].startswith("none")
    assert "temperature" in epos_steady_samples(leadscrew_dir, temperature=30.0).measured
    rpm, mnm = s.velocity / RPM, s.friction * 1e3
    slow_pos = np.argmin(np.abs(rpm - 2))
    slow_neg = np.argmin(np.abs(rpm + 2))
    # as recorded (drive's sign convention): about +3.6 mNm at +2 rpm, -2.8 mNm at -2 rpm
    assert rpm[slow_pos] == pytest.approx(2.14, abs=0.01)
    assert mnm[slow_pos] == pytest.approx(3.555, abs=0.01)
    assert rpm[slow_neg] == pytest.approx(-2.074, abs=0.01)
    assert mnm[slow_neg] == pytest.approx(-2.771, abs=0.01)
    assert s.meta["files"][slow_pos] == "n2.csv" and s.meta["files"][slow_neg] == "2.csv"
    # friction opposes motion everywhere; Stribeck dip then viscous rise on the + side
    assert np.all(np.sign(s.friction) == s.direction)
    pos = s.direction == 1
    assert mnm[pos].min() < mnm[pos][0] and mnm[pos][-1] > mnm[pos].min() + 0.5


def test_real_folder_flipped_matches_file_names(leadscrew_dir):
    s = epos_steady_samples(leadscrew_dir, flip_sign=True)
    for name, v in zip(s.meta["files"], s.velocity / RPM, strict=True):
        setpoint = -float(name[1:-4]) if name.startswith("n") else float(name[:-4])
        assert v == pytest.approx(setpoint, rel=0.01, abs=0.15), name  # N.csv is +N rpm
    two = s.meta["files"].index("2.csv")
    n_two = s.meta["files"].index("n2.csv")
    assert s.friction[two] * 1e3 == pytest.approx(2.771, abs=0.01)
    assert s.friction[n_two] * 1e3 == pytest.approx(-3.555, abs=0.01)


def test_read_epos_dir_sorted_and_options_passed(leadscrew_dir):
    logs = read_epos_dir(leadscrew_dir, nominal_torque=0.01, temperature=30.0)
    assert len(logs) == 32
    means = [float(np.mean(log.velocity)) for log in logs]
    assert means == sorted(means)
    assert all(log.temperature[0] == 30.0 for log in logs)
    assert logs[0].meta["nominal_torque [N m]"] == 0.01


# --------------------------------------------------------------------------- synthetic files


def test_synthetic_conversion_and_flip(tmp_path):
    path = _epos(tmp_path / "a.csv", _rows(4, v=-60, tau=-50.0))
    log = read_epos(path, nominal_torque=0.02)
    np.testing.assert_allclose(log.time, [0.0, 0.01, 0.02, 0.03])
    np.testing.assert_allclose(log.velocity, -2 * math.pi)
    np.testing.assert_allclose(log.torque, -0.01)
    np.testing.assert_allclose(log.position, -2 * math.pi * log.time)
    flipped = read_epos(path, nominal_torque=0.02, flip_sign=True)
    np.testing.assert_allclose(flipped.velocity, 2 * math.pi)
    np.testing.assert_allclose(flipped.torque, 0.01)
    assert flipped.meta["flip_sign"] is True


def test_stray_annotation_lines_are_skipped_with_warning(tmp_path, caplog):
    rows = _rows(6)
    rows.insert(3, "operator: bumped the table here")
    rows.append("Recording stopped by user")
    path = _epos(tmp_path / "a.csv", rows)
    with caplog.at_level(logging.WARNING, logger="fricid.io.epos"):
        log = read_epos(path)
    assert len(log) == 6
    messages = [r.getMessage() for r in caplog.records]
    assert len(messages) == 1  # one summary line per file (issue 12)
    assert "skipped 2 non-numeric lines" in messages[0]
    assert "line 13" in messages[0] and "bumped the table" in messages[0]
    assert "line 17" in messages[0]


@pytest.mark.parametrize("bad", ["-3x.5", "1.2.3", "12,5", "-"])
def test_malformed_number_names_line_and_column(tmp_path, bad):
    rows = _rows(6)
    rows[2] = f"20.000;-10;{bad}"
    path = _epos(tmp_path / "a.csv", rows)
    with pytest.raises(DataError) as err:
        read_epos(path)
    # header 7 lines, channels 8, units 9, data from line 10
    assert (err.value.file, err.value.row) == (str(path), 12)
    assert err.value.column == "Torque actual value averaged"
    assert repr(bad) in str(err.value)


def test_malformed_time_and_short_row(tmp_path):
    rows = _rows(4)
    rows[1] = "1O.000;-10;-30.0"  # letter O
    with pytest.raises(DataError) as err:
        read_epos(_epos(tmp_path / "a.csv", rows))
    assert (err.value.row, err.value.column) == (11, "time")
    rows = _rows(4)
    rows[3] = "30.000;-10"
    with pytest.raises(DataError, match="2 fields, expected 3") as err:
        read_epos(_epos(tmp_path / "b.csv", rows))
    assert err.value.row == 13


def test_unknown_unit_names_file_and_column(tmp_path):
    path = _epos(tmp_path / "a.csv", _rows(), units="ms;furlong/fortnight;%")
    with pytest.raises(DataError) as err:
        read_epos(path)
    assert err.value.file == str(path)
    assert err.value.column == "Velocity actual value averaged"
    assert err.value.row == 9 and "furlong/fortnight" in str(err.value) and "rpm" in str(err.value)
    with pytest.raises(DataError, match="unknown unit 'bar'"):
        read_epos(_epos(tmp_path / "b.csv", _rows(), units="ms;rpm;bar"))


def test_structure_errors(tmp_path):
    with pytest.raises(DataError, match="empty file"):
        read_epos(_write(tmp_path / "e.csv", ""))
    with pytest.raises(DataError, match="no channel line"):
        read_epos(_write(tmp_path / "h.csv", HEADER))
    with pytest.raises(DataError, match="no units line"):
        read_epos(_write(tmp_path / "u.csv", HEADER + CHANNELS + "0.000;1;2\r\n"))
    with pytest.raises(DataError, match="no data rows"):
        read_epos(_epos(tmp_path / "d.csv", []))
    rows = _rows(4)
    rows[2] = "10.000;-10;-30.0"  # time repeats
    with pytest.raises(DataError, match="strictly increasing") as err:
        read_epos(_epos(tmp_path / "t.csv", rows))
    assert (err.value.row, err.value.column) == (12, "time")
    with pytest.raises(DataError, match="no velocity channel"):
        read_epos(_epos(tmp_path / "v.csv", _rows(), channels=";Position actual value;Torque\r\n"))


def _write(path: Path, text: str) -> Path:
    path.write_bytes(text.encode())
    return path


def test_current_and_position_channels(tmp_path):
    channels = ";Position actual value;Velocity actual value;Current actual value averaged\r\n"
    rows = ["0.000;0;60;500", "1.000;4096;60;1500"]
    path = _epos(tmp_path / "a.csv", rows, units="ms;qc;rpm;mA", channels=channels)
    with pytest.raises(ConfigError, match="counts_per_turn"):
        read_epos(path, torque_constant=0.02)
    log = read_epos(path, torque_constant=0.02, counts_per_turn=4096)
    np.testing.assert_allclose(log.position, [0.0, 2 * math.pi])
    np.testing.assert_allclose(log.current, [0.5, 1.5])
    np.testing.assert_allclose(log.motor_torque, [0.01, 0.03])
    assert log.torque is None and log.meta["position_source"] == "channel"
    with pytest.raises(DataError, match="torque constant"):
        read_epos(path, counts_per_turn=4096)


def test_channel_choice_prefers_actual_averaged(tmp_path):
    channels = (
        ";Velocity demand value;Velocity actual value;Velocity actual value averaged;"
        "Torque actual value averaged\r\n"
    )
    rows = ["0.000;100;7;6;10", "1.000;100;7;6;10"]
    log = read_epos(_epos(tmp_path / "a.csv", rows, units="ms;rpm;rpm;rpm;%", channels=channels))
    np.testing.assert_allclose(log.velocity, 6 * RPM)


def test_steady_samples_synthetic(tmp_path):
    _epos(tmp_path / "p.csv", _rows(5, v=10, tau=40.0))
    _epos(tmp_path / "m.csv", _rows(3, v=-20, tau=-30.0))
    s = epos_steady_samples(tmp_path, nominal_torque=0.01, temperature=40.0, load=0.5)
    np.testing.assert_allclose(s.velocity, [-20 * RPM, 10 * RPM])
    np.testing.assert_allclose(s.friction, [-0.003, 0.004])
    np.testing.assert_array_equal(s.direction, [-1, 1])
    np.testing.assert_array_equal(s.count, [3, 5])
    np.testing.assert_allclose(s.std, 0.0, atol=1e-15)
    assert np.all(s.load == 0.5) and np.all(s.temperature == 40.0)
    _epos(tmp_path / "z.csv", _rows(3, v=0, tau=1.0))
    with pytest.raises(DataError, match="mean velocity is zero") as err:
        epos_steady_samples(tmp_path)
    assert err.value.file.endswith("z.csv")
    with pytest.raises(DataError, match="no files"):
        epos_steady_samples(tmp_path, pattern="*.dat")


# --------------------------------------------------------------------------- spreadsheet re-saves


def _resaved(path: Path, rows: list[str], pad: str = ",,") -> Path:
    """An EPOS export as a spreadsheet re-saves it: every line ends in empty fields."""
    text = HEADER + CHANNELS + "ms;rpm;%\r\n" + "\r\n".join(rows) + "\r\n"
    lines = [line + pad for line in text.split("\r\n") if line]
    path.write_bytes(("\r\n".join(lines) + "\r\n").encode())
    return path


def test_spreadsheet_resave_with_trailing_empty_fields_reads_as_the_original(tmp_path):
    rows = _rows(6, v=-10.0, tau=-1200.0)
    original = read_epos(_epos(tmp_path / "a.csv", rows))
    resaved = read_epos(_resaved(tmp_path / "b.csv", rows))
    np.testing.assert_array_equal(resaved.torque, original.torque)
    np.testing.assert_array_equal(resaved.velocity, original.velocity)
    assert resaved.meta["channels"]["torque"] == "Torque actual value averaged"
    # a re-save with ',' as the separator too
    comma = tmp_path / "c.csv"
    comma.write_bytes(_resaved(tmp_path / "c0.csv", rows).read_bytes().replace(b";", b","))
    np.testing.assert_array_equal(read_epos(comma).torque, original.torque)


def test_stray_note_in_a_cell_names_file_line_and_column_and_can_be_skipped(tmp_path):
    rows = _rows(6, tau=-1200.0)
    rows[2] = "20.000;-10;see lab book"
    rows[4] = "40.000;-10"
    path = _resaved(tmp_path / "a.csv", rows)
    with pytest.raises(DataError) as err:
        read_epos(path)
    assert (err.value.file, err.value.row) == (str(path), 14)  # the short row comes first
    rows[4] = "40.000;-10;-1200.0"
    path = _resaved(tmp_path / "b.csv", rows)
    with pytest.raises(DataError) as err:
        read_epos(path)
    assert (err.value.row, err.value.column) == (12, "Torque actual value averaged")
    assert "'see lab book'" in str(err.value)
    rows[4] = "40.000;-10"
    path = _resaved(tmp_path / "c.csv", rows)
    with pytest.warns(DataQualityWarning, match=r"skipped 2 bad rows.*line 12.*see lab book"):
        log = read_epos(path, skip_bad_rows=True)
    assert len(log) == 4
    assert [s["line"] for s in log.meta["skipped_rows"]] == [12, 14]


def test_skip_bad_rows_in_a_folder_lists_the_rows_per_file(tmp_path):
    folder = tmp_path / "runs"
    folder.mkdir()
    rows = _rows(6, v=-10.0, tau=-30.0)
    rows[1] = "10.000;-10;n/a"
    _resaved(folder / "n10.csv", rows)
    _resaved(folder / "10.csv", _rows(6, v=10.0, tau=30.0))
    with pytest.warns(DataQualityWarning, match="skipped 1 bad row"):
        samples = epos_steady_samples(folder, skip_bad_rows=True)
    assert samples.meta["skipped_rows"] == {
        "n10.csv": [{"line": 11, "column": "Torque actual value averaged", "text": "n/a"}]
    }
    np.testing.assert_array_equal(samples.count, [5, 6])


def test_real_recording_resaved_by_a_spreadsheet_reads_as_recorded(leadscrew_dir, tmp_path):
    src = leadscrew_dir / "20.csv"
    lines = src.read_bytes().decode().split("\r\n")
    copy = tmp_path / "20.csv"
    copy.write_bytes("\r\n".join(line + ",," if line else line for line in lines).encode())
    np.testing.assert_array_equal(read_epos(copy).torque, read_epos(src).torque)


def test_a_recording_resaved_with_decimal_commas_reads_as_recorded(leadscrew_dir, tmp_path):
    """A new user's trial: the folder re-saved by a spreadsheet in a European locale (decimal
    commas, the fields still ';'-separated) failed on every file ("malformed number '0,000'"),
    with or without ``--decimal ,``."""
    src = leadscrew_dir / "10.csv"
    text = src.read_bytes().decode("latin-1")
    comma = re.sub(r"(\d)\.(\d)", r"\1,\2", text).replace("\n", "\r\n")
    assert "0,000" in comma
    path = tmp_path / "10.csv"
    path.write_bytes(comma.encode("latin-1"))
    a, b = read_epos(src), read_epos(path)
    np.testing.assert_array_equal(a.time, b.time)
    np.testing.assert_array_equal(a.velocity, b.velocity)
    np.testing.assert_array_equal(a.torque, b.torque)
