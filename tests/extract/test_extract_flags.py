"""``fricid extract``: flags a format does not use are errors, the help lists every format,
the EPOS folder's output is what the help says, bad rows skipped on request (issue 13)."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.cli.extract import EXTRACT_FLAGS, READER_FLAGS
from fricid.io import READER_EXAMPLES, READER_OPTIONS, READERS, read_samples

runner = CliRunner()


def run(*args):
    return runner.invoke(app, [str(a) for a in args])


def test_help_lists_every_format_with_an_example():
    res = run("extract", "--help")
    assert res.exit_code == 0
    for name in READERS:
        assert f"  {name}: fricid extract " in res.output
    assert set(READER_EXAMPLES) == set(READERS)
    assert "+1 and -1 rows" in " ".join(res.output.split())  # what -o holds for EPOS


def test_every_reader_flag_names_a_reader_option():
    options = {o for opts in READER_OPTIONS.values() for o in opts}
    assert {option for _, option in READER_FLAGS.values()} <= options
    assert set(EXTRACT_FLAGS) == {
        "--positions",
        "--position-unit",
        "--bin-halfwidth",
        "--median-window",
        "--gravity",
    }


@pytest.mark.parametrize(
    ("flag", "value"),
    [("--median-window", "7"), ("--gravity", "none"), ("--positions", "-60:60:20")],
)
def test_extraction_flags_on_an_epos_folder_are_refused(leadscrew_dir, tmp_path, flag, value):
    out = tmp_path / "s.csv"
    res = run("extract", leadscrew_dir, "--format", "epos", flag, value, "-o", out)
    assert res.exit_code == 2
    assert f"{flag} does not apply to --format epos here" in res.output
    assert "one operating point per file" in res.output
    assert not out.exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--joint", "elbow"], "--joint does not apply to --format epos: it is an option of"),
        (
            ["--map", "time=t"],
            "--map does not apply to --format epos: it is an option of --format generic",
        ),
        (["--topic", "/js"], "--topic does not apply to --format epos"),
        (["--channels", "torque=a.t:Nm"], "--channels does not apply to --format epos"),
    ],
)
def test_reader_flags_of_another_format_are_refused(leadscrew_dir, tmp_path, args, message):
    res = run("extract", leadscrew_dir, "--format", "epos", *args, "-o", tmp_path / "s.csv")
    assert res.exit_code == 2 and message in res.output


def test_flip_sign_with_a_table_log_is_refused(tmp_path):
    log = tmp_path / "log.csv"
    log.write_text("time [s],position [rad],velocity [rad/s],torque [N m],temperature [degC]\n")
    res = run("extract", log, "--flip-sign", "-o", tmp_path / "s.csv")
    assert res.exit_code == 2
    assert "--flip-sign does not apply to --format table: it is an option of --format epos" in (
        res.output
    )


def test_epos_folder_output_holds_both_directions_as_the_help_says(leadscrew_dir, tmp_path):
    out = tmp_path / "s.csv"
    res = run("extract", leadscrew_dir, "--format", "epos", "-o", out)
    assert res.exit_code == 0, res.output
    samples = read_samples(out)
    assert samples.directions() == (-1, 1) and len(samples) == 32


def test_one_epos_recording_records_no_temperature_unless_given(leadscrew_dir, tmp_path):
    out = tmp_path / "s.csv"
    res = run("extract", leadscrew_dir / "10.csv", "--format", "epos", "-o", out)
    assert res.exit_code == 0, res.output
    assert "degC" not in res.output
    samples = read_samples(out)
    assert "temperature" not in samples.measured  # 25 degC was written, made up
    header = next(line for line in out.read_text().splitlines() if line.startswith("velocity"))
    assert "temperature" not in header
    res = run(
        "extract", leadscrew_dir / "10.csv", "--format", "epos", "--temperature", "30", "-o", out
    )
    assert res.exit_code == 0, res.output
    assert np.all(read_samples(out).temperature == 30.0)


def test_skip_bad_rows_on_a_resaved_real_folder(leadscrew_dir, tmp_path):
    folder = tmp_path / "resaved"
    shutil.copytree(leadscrew_dir, folder)
    for path in folder.glob("*.csv"):  # as a spreadsheet re-saves them
        lines = path.read_bytes().decode().split("\r\n")
        path.write_bytes("\r\n".join(line + ",," if line else line for line in lines).encode())
    note = folder / "40.csv"
    lines = note.read_bytes().decode().split("\r\n")
    lines[20] = "192.000;-40;bumped,,"
    note.write_bytes("\r\n".join(lines).encode())
    out = tmp_path / "s.csv"
    res = run("extract", folder, "--format", "epos", "-o", out)
    assert res.exit_code == 2
    assert "40.csv, row 21, column 'Torque actual value averaged'" in res.output
    assert not out.exists()
    res = run("extract", folder, "--format", "epos", "--skip-bad-rows", "-o", out)
    assert res.exit_code == 0, res.output
    assert "skipped 1 bad row" in res.output and "line 21" in res.output
    assert "1 bad rows skipped in 1 files" in res.output
    samples = read_samples(out)
    original = run("extract", leadscrew_dir, "--format", "epos", "-o", tmp_path / "o.csv")
    assert original.exit_code == 0
    reference = read_samples(tmp_path / "o.csv")
    assert samples.count.sum() == reference.count.sum() - 1
    same = samples.count == reference.count
    np.testing.assert_array_equal(samples.friction[same], reference.friction[same])


def test_generic_map_finds_column_with_unit_in_header_from_the_cli(tmp_path):
    log = tmp_path / "lab.csv"
    t = np.arange(0, 4, 0.01)
    v = np.where(t < 2, 0.5, -0.5)
    rows = "".join(f"{a:.3f},{b},{0.2 * np.sign(b) + 0.1 * b}\n" for a, b in zip(t, v, strict=True))
    log.write_text("t [s],dq [rad/s],tau [Nm]\n" + rows)
    out = tmp_path / "s.csv"
    res = run(
        "extract",
        log,
        "--format",
        "generic",
        "--map",
        "time=t",
        "--map",
        "velocity=dq",
        "--map",
        "torque=tau",
        "-o",
        out,
    )
    assert res.exit_code == 0, res.output
    np.testing.assert_allclose(read_samples(out).friction, [0.25], rtol=1e-6)
    res = run(
        "extract",
        log,
        "--format",
        "generic",
        "--map",
        "time=t:ms",
        "--map",
        "velocity=dq",
        "--map",
        "torque=tau",
        "-o",
        out,
    )
    assert res.exit_code == 2 and "'s'" in res.output and "'ms'" in res.output


def test_chunk_rows_with_a_reader_that_does_not_chunk_is_refused(leadscrew_dir, tmp_path):
    res = run(
        "extract", leadscrew_dir, "--format", "epos", "--chunk-rows", "10", "-o", tmp_path / "s.csv"
    )
    assert res.exit_code == 2
    assert "--chunk-rows does not apply to --format epos" in res.output
