"""Issue 25, the readers: limits before allocation, regular files only, one line per failure,
no silent coercion, per-channel patterns that cannot mix runs, directions that agree with
velocities, and checksums on Parquet and MCAP.

One regression test per defect; the fuzz suite (``test_fuzz_readers.py``) covers the same
ground at large.
"""

from __future__ import annotations

import contextlib
import io
import os
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

import h5py
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import scipy.io
import scipy.sparse
from typer.testing import CliRunner

import fricid
from fricid.cli import app
from fricid.errors import ConfigError, DataError, FricidError
from fricid.io import matlab as matlab_module
from fricid.io import (
    read_channels,
    read_epos,
    read_mat,
    read_rawlog,
    read_rosbag,
    read_samples,
    read_table_log,
    write_rawlog,
    write_samples,
)
from fricid.io._files import read_capped
from fricid.samples import FrictionSamples, RawLog
from fuzzing import (
    EPOS,
    GENERIC_MAP,
    MAT_TABLE,
    MAT_UNITS,
    MAT_VARS,
    _mat73,
    _mcap,
    _rawlog,
    _samples,
    mat_array,
    mat_compressed,
    mat_header,
    mcap_with_crcs,
)

runner = CliRunner()


def one_line_error(call: Callable[[], object], path: Path, *words: str) -> str:
    """The message of the FricidError ``call`` raises: one line, naming ``path`` and ``words``."""
    with pytest.raises(FricidError) as info:
        call()
    message = str(info.value)
    assert "\n" not in message and path.name in message, message
    for word in words:
        assert word in message, (word, message)
    return message


def cli(*args: object) -> tuple[int, str]:
    res = runner.invoke(app, [str(a) for a in args])
    return res.exit_code, res.stderr


def v5_file(path: Path, *elements: bytes) -> Path:
    path.write_bytes(mat_header() + b"".join(elements))
    return path


def doubles(values) -> bytes:
    return np.asarray(values, dtype="<f8").tobytes()


V = MAT_TABLE["v"]
F = MAT_TABLE["f"]


# ------------------------------------------------------------------------ limits before allocation


def test_v73_dataset_declaring_74_gib_is_refused_before_reading(tmp_path):
    """A few kilobytes declaring a 100000 x 100000 double dataset (74.5 GiB): refused from
    its declared shape, nothing allocated."""
    path = tmp_path / "huge.mat"
    with h5py.File(path, "w") as f:
        f.create_dataset("v", shape=(100_000, 100_000), dtype="f8", chunks=(100, 100))
        f.create_dataset("f", data=np.atleast_2d(F))
    assert path.stat().st_size < 10_000
    one_line_error(
        lambda: read_mat(path, MAT_VARS, MAT_UNITS), path, "variable 'v'", "74.5 GiB", "2 GiB"
    )


def test_v73_chunk_larger_than_the_cap_is_refused(tmp_path):
    path = tmp_path / "chunk.mat"
    with h5py.File(path, "w") as f:
        chunks = (1, 2**28 + 2**20)  # 2 GiB and 8 MiB per chunk
        f.create_dataset("v", shape=(1, 6), dtype="f8", maxshape=(None, None), chunks=chunks)
        f.create_dataset("f", data=np.atleast_2d(F))
    one_line_error(lambda: read_mat(path, MAT_VARS, MAT_UNITS), path, "declares chunks", "2 GiB")


def test_v5_array_declaring_more_than_the_cap_is_refused(tmp_path):
    """Dimensions 100000 x 100000 in an array header of a few bytes."""
    path = v5_file(
        tmp_path / "dims.mat",
        mat_array("v", (100_000, 100_000), parts=[doubles(V)]),
        mat_array("f", (1, 6), parts=[doubles(F)]),
    )
    one_line_error(
        lambda: read_mat(path, MAT_VARS, MAT_UNITS), path, "'v'", "100000x100000 double", "74.5 GiB"
    )


def test_v5_decompression_bomb_stops_at_the_cap(tmp_path, monkeypatch):
    """A compressed element whose array is followed by 64 MiB of zeros (65 kB compressed):
    inflated a block at a time and refused at the cap, which tests set small."""
    monkeypatch.setattr(matlab_module, "MAX_BYTES", 8 * 2**20)
    path = v5_file(
        tmp_path / "bomb.mat",
        mat_compressed(mat_array("v", (1, 6), parts=[doubles(V)]), bytes(64 * 2**20), level=9),
        mat_array("f", (1, 6), parts=[doubles(F)]),
    )
    assert path.stat().st_size < 100_000
    start = time.perf_counter()
    one_line_error(
        lambda: read_mat(path, MAT_VARS, MAT_UNITS), path, "inflating to more than 8 MiB"
    )
    assert time.perf_counter() - start < 2.0


def test_v5_compressed_array_larger_than_the_cap(tmp_path, monkeypatch):
    monkeypatch.setattr(matlab_module, "MAX_BYTES", 2**20)
    table = {"v": np.zeros(2**18), "f": np.zeros(2**18)}  # 2 MiB each, compressed to kB
    path = tmp_path / "zeros.mat"
    scipy.io.savemat(path, table, do_compression=True)
    one_line_error(
        lambda: read_mat(path, MAT_VARS, MAT_UNITS), path, "'v'", "1x262144 double", "1 MiB"
    )


def test_v5_data_element_of_the_wrong_type_never_reaches_scipy(tmp_path):
    """An array whose values are an miMATRIX element (type 14) crashes scipy's reader with a
    segmentation fault; the structural check refuses it first (run in a child process so a
    crash would be seen as one)."""
    path = tmp_path / "crash.mat"
    buf = io.BytesIO()
    scipy.io.savemat(buf, MAT_TABLE, do_compression=False)
    data = bytearray(buf.getvalue())
    at = data.index(struct.pack("<II", 9, 48))  # the first real part: 6 doubles
    data[at : at + 4] = struct.pack("<I", 14)
    path.write_bytes(bytes(data))
    code = (
        "import sys; from fricid.io import read_mat; from fricid.errors import DataError\n"
        f"try: read_mat({str(path)!r}, {MAT_VARS!r}, {MAT_UNITS!r})\n"
        "except DataError as e: print(e); sys.exit(0)\n"
        "sys.exit(3)"
    )
    env = {**os.environ, "PYTHONPATH": str(Path(fricid.__file__).parents[1])}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert done.returncode == 0, (done.returncode, done.stderr[-500:])
    assert "crash.mat" in done.stdout and "data type 14" in done.stdout


# ------------------------------------------------------------------------------ regular files only


def _no_hang(call: Callable[[], object], fifos: list[Path] = (), seconds: float = 10) -> None:
    """``call()`` must end in a FricidError naming a FIFO or a device within ``seconds``.

    It runs in a thread: a reader that blocks opening a FIFO is released by opening the FIFO
    for writing (then the test fails), never left to hang the suite.
    """
    outcome: list[BaseException | None] = []

    def run() -> None:
        try:
            call()
        except BaseException as exc:  # judged below, in the test's thread
            outcome.append(exc)
        else:
            outcome.append(None)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        for fifo in fifos:
            with contextlib.suppress(OSError):
                os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
        thread.join(seconds)
        pytest.fail(f"the reader blocked for {seconds} s")
    error = outcome[0]
    assert isinstance(error, FricidError), repr(error)
    message = str(error)
    assert "\n" not in message and ("FIFO" in message or "device" in message), message


def _readers(path: Path) -> dict[str, Callable[[], object]]:
    return {
        "samples": lambda: read_samples(path.with_suffix(".csv")),
        "rawlog": lambda: read_rawlog(path.with_suffix(".csv")),
        "parquet": lambda: read_samples(path.with_suffix(".parquet")),
        "generic": lambda: read_table_log(path.with_suffix(".csv"), GENERIC_MAP, temperature=None),
        "epos": lambda: read_epos(path.with_suffix(".csv")),
        "mat": lambda: read_mat(path.with_suffix(".mat"), MAT_VARS, MAT_UNITS),
        "bag": lambda: read_rosbag(path.with_suffix(".mcap"), "elbow", temperature=25.0),
        "model": lambda: __import__("fricid").fitted.FittedModel.load(path.with_suffix(".json")),
    }


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
@pytest.mark.parametrize("reader", list(_readers(Path("x"))))
def test_a_fifo_given_as_any_input_is_refused_without_blocking(tmp_path, reader):
    base = tmp_path / "pipe"
    fifos = [base.with_suffix(s) for s in (".csv", ".parquet", ".mat", ".mcap", ".json")]
    for fifo in fifos:
        os.mkfifo(fifo)
    _no_hang(_readers(base)[reader], fifos)


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero here")
@pytest.mark.parametrize("reader", list(_readers(Path("x"))))
def test_dev_zero_given_as_any_input_is_refused(tmp_path, reader):
    """``/dev/zero`` reads as size 0 and never ends: refused from its type, behind a link."""
    base = tmp_path / "zero"
    for suffix in (".csv", ".parquet", ".mat", ".mcap", ".json"):
        base.with_suffix(suffix).symlink_to("/dev/zero")
    _no_hang(_readers(base)[reader])


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_extract_on_a_fifo_is_one_line_exit_2(tmp_path):
    fifo = tmp_path / "log.parquet"
    os.mkfifo(fifo)
    got: list[tuple[int, str]] = []
    _no_hang_cli = threading.Thread(
        target=lambda: got.append(cli("extract", fifo, "-o", tmp_path / "s.csv")), daemon=True
    )
    _no_hang_cli.start()
    _no_hang_cli.join(10)
    if _no_hang_cli.is_alive():
        os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
        pytest.fail("fricid extract blocked on a FIFO")
    code, err = got[0]
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "LOG" in err and "FIFO" in err
    assert not (tmp_path / "s.csv").exists()


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_fifo_in_a_channel_folder_is_not_opened(tmp_path):
    folder = tmp_path / "runs"
    folder.mkdir()
    t = np.arange(10) * 0.01
    for name in ("run_vel1_40.t", "run_pos1_40.t"):
        (folder / name).write_text("".join(f"{a} 0.5\n" for a in t))
    os.mkfifo(folder / "run_tau1_40.t")
    patterns = {"torque": "{n}_tau1_{s}.t", "velocity": "{n}_vel1_{s}.t"}
    with pytest.raises(DataError, match="no file matches torque pattern"):
        read_channels(folder, patterns, {"torque": "N m", "velocity": "rad/s"}, temperature=25)


def test_whole_file_reads_stop_at_the_cap(tmp_path, monkeypatch):
    """A file read whole (an EPOS recording) larger than the cap: refused after reading one
    byte more than the cap, whatever size the file system reports."""
    path = tmp_path / "big.csv"
    path.write_text(EPOS * 40)
    monkeypatch.setattr("fricid.io._files.MAX_TEXT_BYTES", 4096)
    one_line_error(lambda: read_epos(path), path, "larger than 4 KiB")
    assert read_capped(path, cap=10**6) == path.read_bytes()


# --------------------------------------------------------------------- one line, never a traceback


def _truncated_v73(path: Path) -> None:
    data = _mat73()
    path.write_bytes(data[: len(data) // 2])


def _corrupt_compressed(path: Path) -> None:
    buf = io.BytesIO()
    scipy.io.savemat(buf, MAT_TABLE, do_compression=True)
    data = bytearray(buf.getvalue())
    data[150] ^= 0xFF  # inside the first zlib stream
    path.write_bytes(bytes(data))


def _link(kind: str) -> Callable[[Path], None]:
    def build(path: Path) -> None:
        with h5py.File(path, "w") as f:
            f.create_dataset("f", data=np.atleast_2d(F))
            if kind == "dangling":
                f["v"] = h5py.SoftLink("/nowhere")
            else:
                f["v"] = h5py.ExternalLink("/etc/hostname", "/v")

    return build


@pytest.mark.parametrize(
    ("build", "words"),
    [
        (lambda p: p.write_bytes(b""), ["an empty file"]),
        (lambda p: p.write_text("t,v\n0,1\n" * 40), ["no MATLAB v5/v7 header"]),
        (lambda p: p.write_bytes(bytes(256)), ["no MATLAB v5/v7 header"]),
        (_truncated_v73, ["not a readable MATLAB v7.3 (HDF5) file", "truncated"]),
        (_corrupt_compressed, ["corrupt compressed data"]),
        (_link("dangling"), ["'v' is a link that leads nowhere"]),
        (_link("external"), ["'v' is a link to another file", "reads only the file given"]),
    ],
    ids=["empty", "text", "zeros", "truncated-v73", "corrupt-zlib", "dangling", "external"],
)
def test_damaged_matlab_files_are_one_line(tmp_path, build, words):
    path = tmp_path / "bad.mat"
    build(path)
    one_line_error(lambda: read_mat(path, MAT_VARS, MAT_UNITS), path, *words)
    code, err = cli(
        "extract",
        path,
        "--format",
        "mat",
        "--var",
        "velocity=v:rad/s",
        "--var",
        "friction=f:Nm",
        "-o",
        tmp_path / "s.csv",
    )
    assert code == 2 and len(err.strip().splitlines()) == 1 and "bad.mat" in err, err
    assert not (tmp_path / "s.csv").exists()


def test_design_metadata_of_the_wrong_type_is_a_data_error(tmp_path):
    """``# meta`` with ``positions_rad: "abc"``: a DataError naming the file and the key."""
    log = _rawlog()
    path = write_rawlog(
        RawLog(**{**vars(log), "meta": {"design": {"positions_rad": "abc"}}}), tmp_path / "log.csv"
    )
    code, err = cli("extract", path, "-o", tmp_path / "s.csv")
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "log.csv" in err and "design.positions_rad" in err and "list of numbers" in err
    for design in (
        {"positions_rad": [0.1, float("nan")]},
        {"bin_halfwidth_rad": -1.0},
        {"gravity": "sideways"},
    ):
        bad = write_rawlog(RawLog(**{**vars(log), "meta": {"design": design}}), path)
        from fricid.workflow import load_joint

        with pytest.raises(DataError, match=r"log\.csv.*metadata 'design\."):
            load_joint(bad, "table")


@pytest.mark.parametrize("grid", ["-1e308:1e308:1", "0:1:1e-320", "0:1e300:1e-300"])
def test_a_grid_of_infinitely_many_points_is_a_config_error(grid):
    """Found by the fuzzer through a manifest's positions: an OverflowError before."""
    from fricid.io.options import MAX_GRID, parse_grid

    with pytest.raises(ConfigError, match=f"at most {MAX_GRID}"):
        parse_grid(grid)


# ------------------------------------------------------------------------------ no silent coercion


@pytest.mark.parametrize(
    ("value", "words"),
    [
        (V > 0, ["'v' (velocity) is logical", "store the velocity values as double"]),
        (V + 0.5j, ["'v' (velocity) is complex", "real doubles"]),
        (scipy.sparse.csc_matrix(V.reshape(1, -1)), ["is a sparse matrix", "full(x)"]),
        (np.array([V[0], "x"], dtype=object), ["is a cell array", "cell2mat"]),
        ("abc", ["is text (char)"]),
        (np.array([(1.0,), (2.0,)], dtype=[("a", "O")]), ["is an array of structs"]),
    ],
    ids=["logical", "complex", "sparse", "cell", "char", "struct-array"],
)
def test_v5_types_that_are_not_numbers_are_refused(tmp_path, value, words):
    path = tmp_path / "types.mat"
    scipy.io.savemat(path, {"v": value, "f": F})
    one_line_error(lambda: read_mat(path, MAT_VARS, MAT_UNITS), path, *words)


@pytest.mark.parametrize(
    ("variant", "words"),
    [
        ("bool", ["'v' (velocity) is logical"]),
        ("class_logical", ["'v' (velocity) is logical"]),
        ("complex", ["is complex"]),
        ("cell", ["is a cell array"]),
        ("sparse", ["is a sparse matrix"]),
        ("class_char", ["is text (char)"]),
        ("empty", ["'v' is empty"]),
        ("external_storage", ["keeps its data in other files"]),
    ],
)
def test_v73_types_that_are_not_numbers_are_refused(tmp_path, variant, words):
    path = tmp_path / "types.mat"
    path.write_bytes(_mat73(variant=variant))
    one_line_error(lambda: read_mat(path, MAT_VARS, MAT_UNITS), path, *words)


def test_integer_classes_are_numbers(tmp_path):
    path = tmp_path / "ints.mat"
    scipy.io.savemat(path, {"v": (V * 100).astype(np.int16), "f": F})
    samples = read_mat(path, MAT_VARS, MAT_UNITS)
    np.testing.assert_array_equal(samples.velocity, (V * 100).astype(np.int16).astype(float))
    path.write_bytes(_mat73(variant="int16"))
    np.testing.assert_array_equal(read_mat(path, MAT_VARS, MAT_UNITS).velocity, samples.velocity)


# ---------------------------------------------------------------------------- per-channel patterns


def _channel_folder(tmp_path: Path, speeds=(20, 40, 80)) -> Path:
    folder = tmp_path / "runs"
    folder.mkdir()
    t = np.arange(40) * 0.01
    for speed in speeds:
        v = np.where(np.arange(40) < 20, speed, -speed)
        for short, values in (("vel", v), ("tau", 0.3 * np.sign(v) + 0.001 * v)):
            text = "".join(f"{a:.2f} {b:.6g}\n" for a, b in zip(t, values, strict=True))
            (folder / f"run_{short}1_{speed}.t").write_text(text)
    return folder


UNITS = {"torque": "N m", "velocity": "deg/s"}


def test_a_pattern_without_fields_matching_several_runs_is_refused(tmp_path):
    """Three runs and no {field}: the old reader kept the last run only."""
    folder = _channel_folder(tmp_path)
    patterns = {"torque": "run_tau*.t", "velocity": "run_vel*.t"}
    message = one_line_error(
        lambda: read_channels(folder, patterns, UNITS, temperature=25.0),
        folder,
        "pattern 'run_tau*.t' matches 3 files of one run",
        "'run_tau1_20.t'",
        "{field}",
    )
    assert isinstance(message, str)
    with pytest.raises(ConfigError, match=r"matches 3 files of one run \{speed='1'\}"):
        read_channels(
            folder,
            {"torque": "run_tau{speed}_*.t", "velocity": "run_vel{speed}_*.t"},
            UNITS,
            temperature=25.0,
        )
    logs = read_channels(
        folder, {"torque": "run_tau1_{s}.t", "velocity": "run_vel1_{s}.t"}, UNITS, temperature=25
    )
    assert [log.meta["run"]["s"] for log in logs] == ["20", "40", "80"]


def test_one_file_for_two_channels_is_refused(tmp_path):
    """``*`` for torque and velocity read one file as both (friction equal to velocity)."""
    folder = _channel_folder(tmp_path, speeds=(40,))
    for name in list(folder.iterdir()):
        if "tau" in name.name:
            name.unlink()
    one_line_error(
        lambda: read_channels(folder, {"torque": "*", "velocity": "*"}, UNITS, temperature=25.0),
        folder,
        "matches both the torque pattern '*' and the velocity pattern '*'",
    )


# ----------------------------------------------------------------------- directions and velocities


def test_directions_that_contradict_the_velocities_are_refused(tmp_path):
    """Rows labelled +1 with negative velocities: file, line and column named."""
    path = tmp_path / "s.csv"
    rows = ["0.1,0,25,0.3,1", "0.2,0,25,0.32,1", "-0.1,0,25,-0.3,1"]
    path.write_text(
        "velocity [rad/s],load [N m],temperature [degC],friction [N m],direction\n"
        + "\n".join(rows)
        + "\n"
    )
    message = one_line_error(lambda: read_samples(path), path, "row 4", "column 'direction'")
    assert "direction +1 contradicts the velocity -0.1 rad/s" in message
    code, err = cli("fit", path, "--out", tmp_path / "m.json")
    assert code == 2 and "contradicts" in err and not (tmp_path / "m.json").exists()


def test_zero_and_tiny_velocities_do_not_contradict_a_direction():
    s = FrictionSamples(
        velocity=[0.0, -1e-12, 0.1, -0.1, 0.2],
        load=0.0,
        temperature=25.0,
        friction=[0.1, 0.1, 0.3, -0.3, 0.3],
        direction=[1, 1, 1, -1, 0],
    )
    assert s.directions() == (-1, 0, 1)
    with pytest.raises(DataError, match=r"row 0.*direction -1 contradicts"):
        FrictionSamples(velocity=[0.1], load=0, temperature=25, friction=[0.3], direction=[-1])


# ---------------------------------------------------------------------- Parquet and MCAP integrity


def _flips(data: bytes, step: int) -> list[bytes]:
    out = []
    for i in range(0, len(data), step):
        b = bytearray(data)
        b[i] ^= 0x01 if i % 2 else 0x10
        out.append(bytes(b))
    return out


@pytest.mark.slow  # 2 s measured under load (default run kept short)
@pytest.mark.parametrize("kind", ["samples", "rawlog"])
def test_parquet_byte_flips_give_an_error_or_the_very_values(tmp_path, kind):
    """Every 7th byte flipped in turn (the old files changed values silently for 5 % of
    them: data pages, column names in the footer, the metadata document)."""
    path = tmp_path / "t.parquet"
    if kind == "samples":
        write_samples(_samples(), path)
        read, names = read_samples, ["velocity", "load", "temperature", "friction", "count"]
    else:
        write_rawlog(_rawlog(True), path)
        read, names = read_rawlog, ["time", "position", "velocity", "temperature", "current"]
    expected = read(path)
    case = tmp_path / "flip.parquet"
    errors = 0
    for data in _flips(path.read_bytes(), 7):
        case.write_bytes(data)
        try:
            got = read(case)
        except DataError as exc:
            assert "\n" not in str(exc) and "flip.parquet" in str(exc)
            errors += 1
            continue
        assert got.meta == expected.meta
        for name in names:
            np.testing.assert_array_equal(getattr(got, name), getattr(expected, name))
    assert errors > 0


def test_parquet_is_written_with_page_checksums_and_the_record(tmp_path):
    path = write_samples(_samples(), tmp_path / "s.parquet")
    pf = pq.ParquetFile(path)
    assert b"fricid-check" in pf.metadata.metadata
    chunk = pf.metadata.row_group(0).column(0)
    start = chunk.dictionary_page_offset or chunk.data_page_offset
    end = start + chunk.total_compressed_size
    data = bytearray(path.read_bytes())
    data[end - 1] ^= 0x40  # the last byte of the first column's pages: their checksum fails
    (tmp_path / "bad.parquet").write_bytes(bytes(data))
    message = one_line_error(
        lambda: read_samples(tmp_path / "bad.parquet"), tmp_path / "bad.parquet"
    )
    assert "CRC" in message, message


def test_parquet_without_checksums_from_an_older_fricid_still_reads(tmp_path):
    """A file as fricid wrote it before: no page checksums, no integrity record."""
    samples = _samples()
    table = pa.table({n: np.asarray(getattr(samples, n)) for n in ("velocity", "friction")})
    doc = b'{"format": "fricid-samples/1", "units": {"velocity": "rad/s", "friction": "N m"}}'
    path = tmp_path / "old.parquet"
    pq.write_table(table.replace_schema_metadata({b"fricid": doc}), path)
    got = read_samples(path)
    np.testing.assert_array_equal(got.velocity, samples.velocity)
    # a new file whose record was stripped is refused: its metadata promises one
    new = write_samples(samples, tmp_path / "new.parquet")
    stripped = pq.read_table(new)
    pq.write_table(stripped, tmp_path / "stripped.parquet")
    with pytest.raises(DataError, match="the record is missing"):
        read_samples(tmp_path / "stripped.parquet")


def test_zstd_compressed_mcap_reads_and_its_checksums_are_verified(tmp_path):
    """Chunks compressed with zstd (the MCAP library writer's default compression): the
    structural check used to read the compression name from the wrong offset and refused
    every such bag; now it reads, and a flipped byte of its compressed records is refused."""
    path = tmp_path / "z.mcap"
    _mcap(path, zstd=True)
    path.write_bytes(mcap_with_crcs(path.read_bytes()))
    log = read_rosbag(path, "elbow", temperature=25.0)
    assert len(log) == 40
    np.testing.assert_allclose(log.torque, 0.1 + 0.001 * np.arange(40))
    b = bytearray(path.read_bytes())
    at = b.index(b"zstd") + 4 + 8 + 20  # inside the first chunk's compressed records
    b[at] ^= 0x01
    path.write_bytes(bytes(b))
    one_line_error(lambda: read_rosbag(path, "elbow", temperature=25.0), path, "chunk")


@pytest.fixture(scope="module")
def mcap_files(tmp_path_factory) -> tuple[bytes, bytes]:
    path = tmp_path_factory.mktemp("mcap") / "run.mcap"
    _mcap(path)
    raw = path.read_bytes()
    return raw, mcap_with_crcs(raw)


def test_mcap_checksums_are_verified(tmp_path, mcap_files):
    raw, with_crcs = mcap_files
    path = tmp_path / "crc.mcap"
    path.write_bytes(with_crcs)
    expected = read_rosbag(path, "elbow", temperature=25.0)
    chunk = with_crcs.index(b"elbow")  # inside the first chunk's records
    summary = with_crcs.rindex(b"sensor_msgs/msg/JointState")  # the schema in the summary
    for at, words in ((chunk, "chunk checksum mismatch"), (summary, "summary checksum")):
        b = bytearray(with_crcs)
        b[at] ^= 0x01
        path.write_bytes(bytes(b))
        one_line_error(lambda: read_rosbag(path, "elbow", temperature=25.0), path, words)
    # a file without checksums (as rosbags writes) still reads, to the same values
    path.write_bytes(raw)
    np.testing.assert_array_equal(
        read_rosbag(path, "elbow", temperature=25.0).torque, expected.torque
    )


def test_mcap_data_section_checksum_is_verified(tmp_path, mcap_files):
    _, with_crcs = mcap_files
    b = bytearray(with_crcs)
    at = b.index(b"\x07", 8)  # a byte of the data section outside any chunk: the checksum of
    # the data section covers it; find a MessageIndex record (opcode 7) after a chunk
    pos = 8
    while pos + 9 <= len(b):
        op, length = struct.unpack_from("<BQ", b, pos)
        if op == 0x07:
            at = pos + 9 + 2
            break
        pos += 9 + length
    b[at] ^= 0x01
    path = tmp_path / "data.mcap"
    path.write_bytes(bytes(b))
    one_line_error(lambda: read_rosbag(path, "elbow", temperature=25.0), path, "data section")


def test_mcap_zstd_chunk_inflating_past_its_size_is_refused(tmp_path, mcap_files):
    """A chunk whose zstd frame inflates far past the size it declares: refused while
    inflating, a block at a time."""
    from backports import zstd

    raw, _ = mcap_files
    b = bytearray(raw)
    pos = 8
    while struct.unpack_from("<B", b, pos)[0] != 0x06:
        pos += 9 + struct.unpack_from("<Q", b, pos + 1)[0]
    length = struct.unpack_from("<Q", b, pos + 1)[0]
    start, end, size = struct.unpack_from("<QQQ", b, pos + 9)
    bomb = zstd.compress(bytes(64 * 2**20))
    # a non-zero CRC: the chunk is inflated to check it
    rec = struct.pack("<QQQI", start, end, size, 1) + struct.pack("<I", 4) + b"zstd"
    rec += struct.pack("<Q", len(bomb)) + bomb
    data = bytes(b[:pos]) + struct.pack("<BQ", 0x06, len(rec)) + rec + bytes(b[pos + 9 + length :])
    path = tmp_path / "bomb.mcap"
    path.write_bytes(data)
    start_time = time.perf_counter()
    one_line_error(
        lambda: read_rosbag(path, "elbow", temperature=25.0), path, "inflates past its declared"
    )
    assert time.perf_counter() - start_time < 2.0
