"""fricid.io.channels and ``fricid extract --format channels`` (issue 13: one file per channel)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import ConfigError, DataError, DataQualityWarning
from fricid.io import read_channels, read_samples
from fricid.io.channels import compile_pattern

SPEEDS = (20, 40, 80)  # deg/s set-points, in the file names
TAU_C, VISCOUS = 0.4, 0.3  # N m, N m s/rad: the friction the fixture is written with


def _friction(v):
    return np.sign(v) * TAU_C + VISCOUS * v


def _write(path: Path, t, v) -> None:
    path.write_text("".join(f"{a:.6f} {b:.9g}\n" for a, b in zip(t, v, strict=True)))


def _folder(tmp_path: Path, *, shift: float = 0.0, joints=(1,)) -> Path:
    """Runs as a lab writes them: run_{pos,vel,tau}{joint}_{speed}.t, one set per run, each
    run a move forward then back at the set-point; torque sampled ``shift`` s later."""
    folder = tmp_path / "runs"
    folder.mkdir()
    dt = 0.002
    for joint in joints:
        for speed in SPEEDS:
            w = np.deg2rad(speed)
            n = 1500
            t = np.arange(2 * n) * dt
            v = np.where(np.arange(2 * n) < n, w, -w)
            q = np.concatenate([[0.0], np.cumsum(v[:-1] * dt)])
            _write(folder / f"run_pos{joint}_{speed}.t", t, q)
            _write(folder / f"run_vel{joint}_{speed}.t", t, v)
            _write(folder / f"run_tau{joint}_{speed}.t", t + shift, _friction(v))
    return folder


PATTERNS = {
    "torque": "{name}_tau{joint}_{speed}.t",
    "velocity": "{name}_vel{joint}_{speed}.t",
    "position": "{name}_pos{joint}_{speed}.t",
}
UNITS = {"torque": "N m", "velocity": "rad/s", "position": "rad"}


def test_pattern_fields_and_globs():
    rx, fields = compile_pattern("{name}_tau{joint}_{speed}.*")
    assert fields == ("name", "joint", "speed")
    assert rx.fullmatch("my_run_tau1_40.txt").groupdict() == {
        "name": "my_run",
        "joint": "1",
        "speed": "40",
    }
    assert rx.fullmatch("run_pos1_40.t") is None
    with pytest.raises(ConfigError, match="twice"):
        compile_pattern("{a}_{a}.t")


def test_one_log_per_run_sorted_by_set_point(tmp_path):
    logs = read_channels(_folder(tmp_path), PATTERNS, UNITS, temperature=25.0)
    assert [log.meta["run"]["speed"] for log in logs] == ["20", "40", "80"]
    for log, speed in zip(logs, SPEEDS, strict=True):
        assert len(log) == 3000 and log.meta["rows_dropped"] == 0
        assert np.abs(log.velocity).max() == pytest.approx(np.deg2rad(speed))
        np.testing.assert_allclose(log.torque, _friction(log.velocity))
    assert "nearest sample within 0.001 s" in logs[0].meta["join"]


def test_join_exact_nearest_and_linear(tmp_path):
    folder = _folder(tmp_path, shift=0.0004)  # torque stamped 0.4 ms after velocity
    with pytest.raises(DataError, match="join='exact'") as err:
        read_channels(folder, PATTERNS, UNITS, join="exact", temperature=25.0)
    assert err.value.file.endswith("run_tau1_20.t") and err.value.row == 1
    near = read_channels(folder, PATTERNS, UNITS, join="nearest", temperature=25.0)[0]
    np.testing.assert_allclose(near.torque, _friction(near.velocity))
    with pytest.warns(DataQualityWarning, match="1 of 3000 velocity time stamps"):
        lin = read_channels(folder, PATTERNS, UNITS, join="linear", temperature=25.0)[0]
    assert lin.meta["rows_dropped"] == 1  # the first time stamp precedes every torque sample
    assert "linear interpolation" in lin.meta["join"]
    with pytest.raises(DataError, match="fewer than two"):
        read_channels(folder, PATTERNS, UNITS, tolerance=1e-5, temperature=25.0)


def test_joint_field_selects_a_joint(tmp_path):
    folder = _folder(tmp_path, joints=(1, 2))
    with pytest.raises(ConfigError, match="joints 1, 2; choose one with --joint"):
        read_channels(folder, PATTERNS, UNITS, temperature=25.0)
    logs = read_channels(folder, PATTERNS, UNITS, joint="2", temperature=25.0)
    assert {log.meta["run"]["joint"] for log in logs} == {"2"} and len(logs) == 3


def test_bad_cell_missing_channel_and_units(tmp_path):
    folder = _folder(tmp_path)
    path = folder / "run_tau1_40.t"
    original = path.read_text()
    lines = original.splitlines()
    lines[6] = "0.012000 spike?"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(DataError) as err:
        read_channels(folder, PATTERNS, UNITS, temperature=25.0)
    assert (err.value.file, err.value.row, err.value.column) == (str(path), 7, "torque")
    (folder / "run_vel1_80.t").unlink()
    path.write_text(original)
    with pytest.raises(DataError, match=r"run \{.*'80'\} has no velocity file"):
        read_channels(folder, PATTERNS, UNITS, temperature=25.0)
    with pytest.raises(ConfigError, match="no unit for the torque channel"):
        read_channels(folder, PATTERNS, {"velocity": "rad/s", "position": "rad"}, temperature=25)
    with pytest.raises(ConfigError, match="same fields"):
        read_channels(
            folder, {**PATTERNS, "torque": "{name}_tau1_{speed}.t"}, UNITS, temperature=25.0
        )


def test_cli_extracts_a_folder_of_channel_files(tmp_path):
    folder = _folder(tmp_path)
    out = tmp_path / "samples.csv"
    res = CliRunner().invoke(
        app,
        [
            "extract",
            str(folder),
            "--format",
            "channels",
            "--channels",
            "torque={name}_tau{joint}_{speed}.t:Nm",
            "--channels",
            "velocity={name}_vel{joint}_{speed}.t:rad/s",
            "--channels",
            "position={name}_pos{joint}_{speed}.t:rad",
            "-o",
            str(out),
        ],
    )
    assert res.exit_code == 0, res.output
    assert "channels joined by the nearest sample" in res.output
    samples = read_samples(out)
    assert sorted(np.round(np.rad2deg(samples.velocity)).astype(int)) == list(SPEEDS)
    np.testing.assert_allclose(samples.friction, _friction(samples.velocity), rtol=1e-6)
    # no temperature channel and none given: the samples record none (not a made-up 25 degC)
    assert "temperature" not in samples.measured, samples.measured
    (log, *_) = read_channels(folder, PATTERNS, UNITS)
    assert not log.temperature_measured
    (log, *_) = read_channels(folder, PATTERNS, UNITS, temperature=31.0)
    assert log.temperature_measured and float(log.temperature[0]) == 31.0


def test_open_log_without_patterns_says_what_is_needed(tmp_path):
    from fricid.io import open_log

    with pytest.raises(ConfigError, match="needs a pattern per quantity"):
        open_log(_folder(tmp_path), "channels")


def test_real_recordings_split_into_channel_files_read_as_recorded(leadscrew_dir, tmp_path):
    """Two lead-screw recordings written as a lab's per-channel files (time in ms, velocity in
    rpm, torque in mNm, the set-point in the name) read back as the EPOS reader reads them."""
    from fricid.io import read_epos

    folder = tmp_path / "split"
    folder.mkdir()
    refs = {}
    for name in ("20", "n20"):
        ref = read_epos(leadscrew_dir / f"{name}.csv")
        refs[name] = ref
        t_ms = ref.time * 1e3
        _write(folder / f"ls_vel1_{name}.t", t_ms, ref.velocity * 60 / (2 * np.pi))
        _write(folder / f"ls_tau1_{name}.t", t_ms, ref.torque * 1e3)
    logs = read_channels(
        folder,
        {"velocity": "{name}_vel{joint}_{speed}.t", "torque": "{name}_tau{joint}_{speed}.t"},
        {"velocity": "rpm", "torque": "mNm"},
        time_unit="ms",
        join="exact",
        temperature=25.0,
    )
    assert [log.meta["run"]["speed"] for log in logs] == ["20", "n20"]
    for log in logs:
        ref = refs[log.meta["run"]["speed"]]
        np.testing.assert_allclose(log.time, ref.time, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(log.velocity, ref.velocity, rtol=1e-8)
        np.testing.assert_allclose(log.torque, ref.torque, rtol=1e-8)
