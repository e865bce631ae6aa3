"""Issue 12, "Bad input": one line, never a traceback, never a silent wrong answer.

One regression test per class of defect, through the API and through the CLI (exit 2, one
line on stderr, no partial output). The fuzz suite (``test_fuzz_readers.py``) covers the
readers at large.
"""

from __future__ import annotations

import logging
import warnings
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import ConfigError, DataError, IdentifiabilityWarning
from fricid.fleet import read_manifest
from fricid.identify import fit
from fricid.identify.static.checks import check_identifiable
from fricid.io import (
    read_epos,
    read_rawlog,
    read_rosbag,
    read_samples,
    read_table_log,
    write_samples,
)
from fricid.samples import FrictionSamples, RawLog
from fricid.workflow import select_direction
from fuzzing import EPOS, _mcap, mutate

SAMPLES_HEADER = (
    "velocity [rad/s],load [N m],temperature [degC],friction [N m],direction,count,std [N m]\n"
)
RAW_HEADER = "time [s],position [rad],velocity [rad/s],temperature [degC],torque [N m]\n"
runner = CliRunner()


def cli(*args) -> tuple[int, str]:
    res = runner.invoke(app, [str(a) for a in args])
    return res.exit_code, res.stderr


def assert_one_line_exit_2(code: int, stderr: str, *words: str) -> None:
    assert code == 2, stderr
    assert len(stderr.strip().splitlines()) == 1, stderr
    assert "Traceback" not in stderr and "Usage" not in stderr
    for word in words:
        assert word in stderr, (word, stderr)


def sweep(n: int = 8, **kw) -> FrictionSamples:
    v = np.r_[np.linspace(0.05, 1.0, n), -np.linspace(0.05, 1.0, n)]
    f = np.sign(v) * (0.1 + 0.1 * np.exp(-np.abs(v) / 0.1)) + 0.05 * v
    return FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=f, **kw)


# --------------------------------------------------------------------------- impossible values


@pytest.mark.parametrize(
    ("row", "words"),
    [
        ("0.1,0,-300,0.2,1,1,0", ["below absolute zero", "-300.0 degC", "temperature"]),
        ("0.1,0,20,0.2,1,1e30,0", ["column 'count'", "1e+30"]),
        ("1e300,0,20,0.2,1,1,0", ["velocity [rad/s]", "1e+300 rad/s"]),
        ("0.1,1e300,20,0.2,1,1,0", ["load [N m]", "N m"]),
    ],
)
def test_impossible_sample_values_are_refused_with_the_unit(tmp_path, row, words):
    path = tmp_path / "s.csv"
    path.write_text(SAMPLES_HEADER + row + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # count=1e30 used to warn on the cast
        with pytest.raises(DataError) as info:
            read_samples(path)
    assert str(path) in str(info.value) and "row 2" in str(info.value)
    for word in words:
        assert word in str(info.value)


def test_impossible_values_in_a_raw_log_and_in_kelvin(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text(RAW_HEADER.replace("[degC]", "[K]") + "0,0,0.1,-5,0.1\n1,0,0.1,300,0.1\n")
    with pytest.raises(DataError, match=r"below absolute zero value -278.15 degC"):
        read_rawlog(path)
    with pytest.raises(DataError, match="torque constant K"):
        RawLog(
            time=[0.0],
            position=0,
            velocity=0,
            temperature=20,
            current=[1.0],
            torque_constant=float("nan"),
        )
    with pytest.raises(DataError, match=r"velocity must lie in \[-1e\+06, 1e\+06\] rad/s"):
        FrictionSamples(velocity=[1e300], load=0, temperature=20, friction=[0.1])


def test_identify_never_sees_absurd_velocities(tmp_path):
    path = tmp_path / "s.csv"
    path.write_text(SAMPLES_HEADER + "".join(f"{v},0,20,0.2,1,1,0\n" for v in (1e300, 2e300)))
    code, err = cli("fit", path, "--out", tmp_path / "m.json")
    assert_one_line_exit_2(code, err, "s.csv", "rad/s")
    assert not (tmp_path / "m.json").exists()


# --------------------------------------------------------------------------- metadata


@pytest.mark.parametrize("value", ["abc", "nan", "-1", "[1, 2]"])
def test_csv_meta_line_torque_constant(tmp_path, value):
    path = tmp_path / "r.csv"
    path.write_text(f"# torque_constant [N m/A]: {value}\n" + RAW_HEADER + "0,0,1,20,0.1\n")
    with pytest.raises(DataError, match="'torque_constant' must be a positive number"):
        read_rawlog(path)


def test_malformed_header_line_and_header_only_generic_log(tmp_path):
    columns = {"time": "t [s]", "velocity": "dq [rad/s]", "torque": "tau [N m]"}
    path = tmp_path / "g.csv"
    path.write_bytes(b"t [s],dq\r [rad/s],tau [N m]\n0,1,2\n")
    with pytest.raises(DataError, match=r"g.csv, row 1: malformed header line"):
        read_table_log(path, columns, temperature=20.0)
    path.write_text("t [s],dq [rad/s],tau [N m]\n")
    with pytest.raises(DataError, match="no data rows"):
        read_table_log(path, columns, temperature=20.0)


def test_messages_are_one_line_whatever_the_file_holds(tmp_path):
    err = DataError("unknown unit '%\r\nx'", file=tmp_path / "a.csv", row=3)
    assert "\n" not in str(err) and "\r" not in str(err)
    path = tmp_path / "e.csv"
    path.write_bytes(EPOS.replace("ms;rpm;%", "ms;rpm;%\rjunk").encode())
    with pytest.raises(DataError) as info:
        read_epos(path)
    assert "\r" not in str(info.value) and "e.csv" in str(info.value)


# --------------------------------------------------------------------------- MCAP lengths


def test_corrupt_mcap_length_field_is_a_clean_error(tmp_path):
    base = tmp_path / "ok.mcap"
    _mcap(base)
    data = base.read_bytes()
    for huge in (2**40, 2**63 - 1):
        bad = bytearray(data)
        bad[9:17] = huge.to_bytes(8, "little")  # the header record's length
        path = tmp_path / f"bad{huge}.mcap"
        path.write_bytes(bytes(bad))
        with pytest.raises(DataError, match=r"bad\d+\.mcap: unreadable or truncated bag \(MCAP"):
            read_rosbag(path, "elbow", temperature=25.0)
    bad = bytearray(data)
    at = len(data) - 37 + 9  # the footer's summary_start, pointed into the middle of a record
    bad[at : at + 8] = (20).to_bytes(8, "little")
    (tmp_path / "footer.mcap").write_bytes(bytes(bad))
    with pytest.raises(DataError, match=r"footer.mcap: .*footer points outside"):
        read_rosbag(tmp_path / "footer.mcap", "elbow", temperature=25.0)
    code, err = cli(
        "extract", path, "--format", "rosbag", "--joint", "elbow", "--out", tmp_path / "s.csv"
    )
    assert_one_line_exit_2(code, err, path.name)


# --------------------------------------------------------------------------- EPOS warnings


def test_epos_bad_lines_give_one_summary_line(tmp_path, caplog):
    rows = EPOS.split("\r\n")
    junk = [f"operator note {i}" for i in range(515)]
    path = tmp_path / "e.csv"
    path.write_bytes("\r\n".join(rows[:8] + junk + rows[8:]).encode())
    with caplog.at_level(logging.WARNING, logger="fricid.io.epos"):
        log = read_epos(path)
    assert len(log) == 20
    assert len(caplog.records) == 1
    message = caplog.records[0].getMessage()
    assert "skipped 515 non-numeric lines" in message and "and 512 more" in message
    assert "line 9: 'operator note 0'" in message


# --------------------------------------------------------------------------- file names


def test_messages_name_the_file_given_not_the_recorded_source(tmp_path):
    path = tmp_path / "mine.csv"
    write_samples(sweep(source="/elsewhere/original.parquet").subset(np.arange(8, 16)), path)
    samples = read_samples(path)
    assert samples.source == str(path)
    assert samples.meta["recorded_source"] == "/elsewhere/original.parquet"
    with pytest.raises(DataError, match=r"mine\.csv: no samples with direction pos"):
        select_direction(samples, "pos")


# --------------------------------------------------------------------------- identifiability


def test_a_single_velocity_level_is_refused():
    one = FrictionSamples(
        velocity=[0.5] * 6 + [-0.5] * 6,
        load=0,
        temperature=25,
        friction=[0.2] * 6 + [-0.2] * 6,
        source="one.csv",
    )
    with pytest.raises(DataError, match=r"one.csv: a single velocity level cannot determine the 5"):
        check_identifiable(one, "stribeck")
    with pytest.raises(DataError, match="all 12 samples have zero velocity"):
        check_identifiable(
            one.subset(np.arange(12)).__class__(
                velocity=np.zeros(12), load=0, temperature=25, friction=one.friction
            ),
            "stribeck",
        )


def test_few_levels_warn_naming_the_parameters():
    three = sweep(3)
    with pytest.warns(IdentifiabilityWarning, match="tau_c, tau_s, w_s, tau_v, delta"):
        assert "w_s" in check_identifiable(three, "stribeck")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert check_identifiable(three, "stribeck", fixed={"w_s": 0.1, "delta": 1.0}) == ()
        assert check_identifiable(sweep(8), "stribeck") == ()


def test_load_and_temperature_coefficients_need_variation():
    with pytest.warns(IdentifiabilityWarning, match=r"f_ck, f_sk of 'msk'.*zero in every sample"):
        check_identifiable(sweep(8), "msk")
    loaded = sweep(8)
    loaded = FrictionSamples(
        velocity=loaded.velocity,
        load=np.tile([0.0, 2.0], 8),
        temperature=40.0,
        friction=loaded.friction,
    )
    with pytest.warns(IdentifiabilityWarning, match=r"f_vT, v_vT of 'vlt'.*\(40 degC\)"):
        assert check_identifiable(loaded, "vlt") == ("f_vT", "v_vT")


def test_per_direction_models_are_checked_per_direction():
    s = sweep(8)
    one_side = FrictionSamples(
        velocity=np.r_[s.velocity[:8], np.full(8, -0.5)],
        load=0,
        temperature=25,
        friction=s.friction,
    )
    with pytest.raises(DataError, match=r"negative direction.*tau_c_neg"):
        check_identifiable(one_side, "stribeck_asym")


def test_the_check_agrees_with_what_a_fit_can_do():
    """Data the check passes give a determined fit; the refused data fit to nonsense."""
    good = sweep(8)
    assert check_identifiable(good, "stribeck") == ()
    assert fit(good, "stribeck").metrics["fitness"] > 0.99


# --------------------------------------------------------------------------- positions


def test_unbounded_position_ranges_are_refused(tmp_path):
    path = tmp_path / "m.csv"
    path.write_text("robot,joint,log,positions [deg]\nr,j,x.csv,-60:1e300:1\n")
    with pytest.raises(DataError, match="points; at most 100000"):
        read_manifest(path)
    path.write_text("robot,joint,log,positions [deg]\nr,j,x.csv,-60:inf:1\n")
    with pytest.raises(DataError, match="not a finite number"):
        read_manifest(path)
    from fricid.cli.extract import parse_positions

    with pytest.raises(ConfigError, match="points; at most 100000"):
        parse_positions("-60:1e300:1", "deg")


def test_yaml_manifest_errors_are_one_line(tmp_path):
    path = tmp_path / "m.yaml"
    path.write_bytes(b"\x00joints: []\n")
    with pytest.raises(DataError) as info:
        read_manifest(path)
    assert "\n" not in str(info.value) and "m.yaml" in str(info.value)


# --------------------------------------------------------------------------- CLI paths


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cli")
    samples = write_samples(sweep(8), folder / "s.csv")
    fit(read_samples(samples), "coulomb_viscous").save(folder / "m.json")
    (folder / "a_folder").mkdir()
    (folder / "empty").mkdir()
    log = folder / "log.csv"
    log.write_text(RAW_HEADER + "".join(f"{0.01 * i},{0.001 * i},0.1,25,0.2\n" for i in range(50)))
    return folder


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["fit", "{f}/missing.csv"], ["SAMPLES: no such file", "missing.csv"]),
        (["fit", "{f}/a_folder"], ["SAMPLES", "is a folder"]),
        (["fit", "{f}/s.csv", "--out", "{f}/a_folder"], ["--out", "existing folder"]),
        (["fit", "{f}/s.csv", "--out", "{f}/s.csv/m.json"], ["is a file, not a folder"]),
        (["predict", "{f}/m.json", "-v", "1", "--out", "{f}/a_folder"], ["--out", "folder"]),
        (["predict", "{f}/missing.json", "-v", "1"], ["MODEL: no such file"]),
        (["export", "{f}/m.json", "--to", "urdf", "--out", "{f}/a_folder"], ["existing folder"]),
        (["export", "{f}/m.json", "--to", "c", "--out", "{f}/s.csv"], ["existing file"]),
        # a trailing separator means a folder (it used to write a file named new_folder)
        (["export", "{f}/m.json", "--to", "mjcf", "--out", "{f}/new_folder/"], ["--out", "folder"]),
        (["fit", "{f}/s.csv", "--out", "{f}/new_folder/"], ["--out", "folder"]),
        (["predict", "{f}/m.json", "-v", "1", "--out", "{f}/new_folder/"], ["--out", "folder"]),
        # a raw log where samples go, and samples where a log goes: the commands that take them
        (["fit", "{f}/log.csv"], ["fit LOG --trajectory", "fricid extract LOG"]),
        (["fit", "{f}/s.csv", "--trajectory"], ["friction-samples", "without --trajectory"]),
        (["extract", "{f}/log.csv", "--out", "{f}/a_folder"], ["--out", "existing folder"]),
        (["extract", "{f}/a_folder"], ["LOG", "is a folder"]),
        (["extract", "{f}/empty", "--format", "rosbag", "--joint", "j"], ["metadata.yaml"]),
        (["fleet", "{f}/s.csv", "--out", "{f}/s.csv"], ["--out", "existing file"]),
        (["evaluate", "{f}/m.json", "{f}/missing.csv"], ["SAMPLES: no such file"]),
        (["report", "{f}/missing.json", "{f}/s.csv"], ["MODEL: no such file"]),
    ],
)
def test_cli_path_checks_are_one_line_exit_2(files, args, words):
    before = sorted(p.name for p in files.rglob("*"))
    code, err = cli(*(a.format(f=files) for a in args))
    assert_one_line_exit_2(code, err, *words)
    assert sorted(p.name for p in files.rglob("*")) == before  # nothing written


def test_cli_no_partial_output_when_the_second_output_is_bad(files, tmp_path):
    out = tmp_path / "samples.csv"
    code, err = cli(
        "extract", files / "log.csv", "--out", out, "--by-direction", files / "a_folder"
    )
    assert_one_line_exit_2(code, err, "--by-direction")
    assert not out.exists()


def test_damaged_samples_through_the_cli(files, tmp_path):
    from fuzzing import RngChooser

    text = (files / "s.csv").read_bytes()
    path = tmp_path / "bad.csv"
    path.write_bytes(mutate(text, "binary_junk", RngChooser(np.random.default_rng(1))))
    code, err = cli("fit", path, "--out", tmp_path / "m.json")
    assert_one_line_exit_2(code, err, "bad.csv")
    assert not (tmp_path / "m.json").exists()
    assert Path(files / "s.csv").exists()


@pytest.mark.parametrize(
    ("column", "value", "said"),
    [("direction", "-3", "got -3.0"), ("std", "-3", "got -3.0"), ("count", "0.5", "got 0.5")],
)
def test_a_bad_cell_is_quoted_as_a_number_not_a_numpy_repr(files, tmp_path, column, value, said):
    """A new user's trial: 'direction must be -1, 0 or +1, got np.float64(-3.0)'."""
    lines = (files / "s.csv").read_text().splitlines()
    h = next(k for k, line in enumerate(lines) if not line.startswith("#"))  # after the meta
    header = lines[h].split(",")
    (i,) = [k for k, name in enumerate(header) if name.split(" [")[0] == column]
    row = lines[h + 1].split(",")
    row[i] = value
    lines[h + 1] = ",".join(row)
    path = tmp_path / "bad.csv"
    path.write_text("\n".join(lines) + "\n")
    code, err = cli("fit", path)
    assert_one_line_exit_2(code, err, said, column)
    assert "np." not in err, err


def test_a_samples_file_given_to_extract_names_the_commands_that_take_it(files):
    """A new user's trial: 'this is a fricid-samples/1 file ...; read it with read_samples' (a
    Python function) to a command-line user."""
    code, err = cli("extract", files / "s.csv")
    assert_one_line_exit_2(code, err, "fricid fit", "s.csv")


def test_an_export_target_typo_is_told_the_nearest(files):
    code, err = cli("export", files / "m.json", "--to", "mujoco")
    assert_one_line_exit_2(code, err, "did you mean 'mjcf'")
