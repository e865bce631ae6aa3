"""Damaged input files for every reader and the oracle that judges a reader's outcome.

Shared by ``tests/test_fuzz_readers.py`` (hypothesis draws the damage) and
``benchmarks/fuzz_readers.py`` (a seeded generator draws it, longer, and counts outcomes).
A reader given a damaged file must end in a :class:`~fricid.errors.FricidError` on one line
naming the file, or a valid result (finite SI values within :data:`fricid.samples.LIMITS`,
consistent row counts, time increasing; after a change that keeps the data, the very values
of the undamaged file). :func:`classify` raises for anything else.

The module is over 500 lines on purpose: the mutations, the oracle and the table of readers
with their undamaged files are one fixture, used whole by the test and by the benchmark.
"""

from __future__ import annotations

import logging
import re
import shutil
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import strategies as st

from fricid.errors import FricidError
from fricid.fleet import read_manifest
from fricid.io import (
    iter_rawlog,
    read_epos,
    read_rawlog,
    read_rosbag,
    read_samples,
    read_table_log,
    write_rawlog,
    write_samples,
)
from fricid.samples import LIMITS, SAMPLE_COLUMNS, FrictionSamples, RawLog

# --------------------------------------------------------------------------- choosers


class RngChooser:
    """Random choices from a numpy generator (the benchmark script)."""

    def __init__(self, rng: np.random.Generator) -> None:
        self.rng = rng

    def integer(self, low: int, high: int) -> int:
        return int(self.rng.integers(low, high + 1))

    def choice(self, options: Sequence[Any]) -> Any:
        return options[self.integer(0, len(options) - 1)]

    def raw(self, n: int) -> bytes:
        return self.rng.integers(0, 256, n, dtype=np.uint8).tobytes()


class HypothesisChooser(RngChooser):
    """The same choices drawn by hypothesis (shrinkable, reproducible)."""

    def __init__(self, data: Any) -> None:
        self.data = data

    def integer(self, low: int, high: int) -> int:
        return self.data.draw(st.integers(low, high))

    def raw(self, n: int) -> bytes:
        return self.data.draw(st.binary(min_size=n, max_size=n))


# --------------------------------------------------------------------------- mutations

HUGE = ["1e300", "-1e300", "1e30", "1e308", "4e9", "-0", "1e-320", "-300", "99999999999999999999"]
NONFINITE = ["nan", "NaN", "inf", "-inf", "Infinity", "-", "", "1,5", "0x10", "1e", "\u0661"]
META_KEYS = [
    "torque_constant [N m/A]",
    "torque_constant [garbage]",
    "torque_constant",
    "meta",
    "source",
    "format",
    "joint",
]
META_VALUES = [
    "abc",
    "[1, 2]",
    "1e400",
    "nan",
    "-1",
    "0",
    '"unterminated',
    '{"a": 1}',
    "[]",
    "fricid-samples/1",
    "fricid-rawlog/9",
    "[" * 5000,
    '"\\ud800"',
    "1e300",
]
_NUMBER = re.compile(rb"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")
#: Changes that keep a file's data: a reader that accepts the result must read the same values.
BENIGN = {"bom", "crlf", "trailing_empty"}


def _lines(data: bytes) -> list[bytes]:
    return data.split(b"\n")


def _header_end(lines: list[bytes]) -> int:
    """Index of the first data line (starting with a digit or a sign)."""
    for i, line in enumerate(lines):
        if re.match(rb"\s*[-+]?\.?\d", line):
            return i
    return len(lines)


def mutate(data: bytes, kind: str, ch: RngChooser) -> bytes:
    """One damage of ``kind`` to a file's bytes."""
    n = len(data)
    lines = _lines(data)
    if kind == "truncate":
        return data[: ch.integer(0, max(n - 1, 0))]
    if kind == "flip":
        b = bytearray(data)
        for _ in range(ch.integer(1, 8)):
            if b:
                b[ch.integer(0, len(b) - 1)] = ch.integer(0, 255)
        return bytes(b)
    if kind == "insert_random":
        at = ch.integer(0, n)
        return data[:at] + ch.raw(ch.integer(1, 16)) + data[at:]
    if kind == "random_bytes":
        return ch.raw(ch.integer(0, 200))
    if kind == "binary_junk":
        at = ch.integer(0, n)
        return data[:at] + bytes(range(256)) + data[at:]
    if kind == "not_utf8":
        at = ch.integer(0, n)
        return data[:at] + ch.choice([b"\xff\xfe", b"\xc3\x28", b"\xe9", b"\x80\x80"]) + data[at:]
    if kind in ("huge_number", "nan_inf"):
        spans = [m.span() for m in _NUMBER.finditer(data)]
        if not spans:
            return data
        a, b = ch.choice(spans)
        word = ch.choice(HUGE if kind == "huge_number" else NONFINITE).encode()
        return data[:a] + word + data[b:]
    if kind == "empty":
        return b""
    if kind == "header_only":
        return b"\n".join(lines[: _header_end(lines)]) + b"\n"
    if kind == "wrong_field_count":
        sep = b";" if b";" in data else b","
        i = ch.integer(0, len(lines) - 1)
        parts = lines[i].split(sep)
        if ch.integer(0, 1) and len(parts) > 1:
            parts.pop(ch.integer(0, len(parts) - 1))
        else:
            parts.insert(ch.integer(0, len(parts)), b"1")
        lines[i] = sep.join(parts)
        return b"\n".join(lines)
    if kind == "trailing_empty":
        sep = b";" if b";" in data else b","
        extra = sep * ch.integer(1, 3)
        return b"\n".join(line + extra if line.strip() else line for line in lines)
    if kind == "bom":
        return b"\xef\xbb\xbf" + data
    if kind == "crlf":
        return data.replace(b"\r\n", b"\n").replace(b"\n", b"\r\n")
    if kind == "meta_line":
        key, value = ch.choice(META_KEYS), ch.choice(META_VALUES)
        return f"# {key}: {value}\n".encode() + data
    if kind == "swap_lines":
        i, j = ch.integer(0, len(lines) - 1), ch.integer(0, len(lines) - 1)
        lines[i], lines[j] = lines[j], lines[i]
        return b"\n".join(lines)
    if kind == "delete_line":
        lines.pop(ch.integer(0, len(lines) - 1))
        return b"\n".join(lines)
    if kind == "parquet_meta":
        return _parquet_meta(data, ch)
    if kind == "mcap_length":
        return _mcap_length(data, ch)
    raise AssertionError(kind)


#: Values put into fricid's Parquet schema metadata: wrong types, absurd numbers, bad units.
META_DOC_VALUES = [
    "abc",
    [1, 2],
    "garbage",
    1e300,
    -1,
    0,
    None,
    True,
    0.05,
    float("nan"),
    {"a": 1},
    {"velocity": "garbage"},
    {"velocity": 5},
    {"torque_constant": "mNm/A"},
    {"time": "ms"},
    "fricid-rawlog/1",
    "fricid-samples/1",
    "fricid-samples/2",
    [[[[]]]],
]


def _mcap_length(data: bytes, ch: RngChooser) -> bytes:
    """An MCAP record's uint64 length field set to a wrong value (huge, off by one, zero)."""
    import struct

    starts, pos = [], 8
    while pos + 9 <= len(data) and len(starts) < 10_000:
        starts.append(pos)
        pos += 9 + struct.unpack_from("<Q", data, pos + 1)[0]
    if not starts:
        return data
    at = ch.choice(starts)
    old = struct.unpack_from("<Q", data, at + 1)[0]
    new = ch.choice([2**63 - 1, 2**40, 2**32, old + 1, max(old - 1, 0), 0])
    b = bytearray(data)
    struct.pack_into("<Q", b, at + 1, new)
    return bytes(b)


def _parquet_meta(data: bytes, ch: RngChooser) -> bytes:
    """The file with its schema metadata document replaced by a random one."""
    import json

    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(pa.BufferReader(data))
    except (pa.ArrowException, OSError):
        return data  # damaged already: nothing to rewrite
    keys = ["format", "source", "joint", "torque_constant", "units", "meta"]
    try:
        doc = json.loads((table.schema.metadata or {}).get(b"fricid", b"{}"))
    except ValueError:  # damaged by an earlier mutation
        doc = {}
    doc = doc if isinstance(doc, dict) else {}
    for _ in range(ch.integer(1, 3)):
        key, value = ch.choice(keys), ch.choice(META_DOC_VALUES)
        if key == "units" and isinstance(value, dict) and ch.integer(0, 1):
            units = doc.get("units")
            doc["units"] = {**(units if isinstance(units, dict) else {}), **value}
        else:
            doc[key] = value
    raw = json.dumps(doc).encode() if ch.integer(0, 9) else b"\xff{" + ch.raw(4)
    sink = pa.BufferOutputStream()
    pq.write_table(table.replace_schema_metadata({b"fricid": raw}), sink)
    return sink.getvalue().to_pybytes()


TEXT_KINDS = [
    "truncate",
    "flip",
    "insert_random",
    "random_bytes",
    "binary_junk",
    "not_utf8",
    "huge_number",
    "nan_inf",
    "empty",
    "header_only",
    "wrong_field_count",
    "trailing_empty",
    "bom",
    "crlf",
    "swap_lines",
    "delete_line",
]
BINARY_KINDS = ["truncate", "flip", "insert_random", "random_bytes", "binary_junk", "empty"]
PARQUET_KINDS = [*BINARY_KINDS, "parquet_meta", "parquet_meta"]


# --------------------------------------------------------------------------- oracle


class WrongAnswer(AssertionError):
    """A reader returned a result that breaks the invariants."""


def _check_columns(obj: Any, names: Sequence[str]) -> int:
    n = len(obj)
    for name in names:
        values = getattr(obj, name)
        if values is None:
            continue
        values = np.asarray(values, dtype=float)
        if values.shape != (n,) or not np.isfinite(values).all():
            raise WrongAnswer(f"{name}: shape {values.shape} or non-finite values")
        low, high, _unit = LIMITS.get(name, (-1.0, 1.0, "1"))  # direction
        if (values < low).any() or (values > high).any():
            raise WrongAnswer(f"{name} outside [{low}, {high}]: {values.min()}..{values.max()}")
    return n


def check_valid(result: Any) -> None:
    """Raise :class:`WrongAnswer` unless ``result`` holds the invariants of its type."""
    if isinstance(result, list):
        last = -np.inf
        for log in result:
            check_valid(log)
            if log.time[0] <= last:
                raise WrongAnswer("time does not increase across chunks")
            last = log.time[-1]
        return
    if isinstance(result, FrictionSamples):
        if _check_columns(result, list(SAMPLE_COLUMNS)) < 1:
            raise WrongAnswer("no samples")
        if not set(np.unique(result.direction)) <= {-1, 0, 1}:
            raise WrongAnswer("direction")
    elif isinstance(result, RawLog):
        names = ["time", "position", "velocity", "temperature", "torque", "current"]
        if _check_columns(result, names) < 1:
            raise WrongAnswer("empty log")
        if (np.diff(result.time) <= 0).any():
            raise WrongAnswer("time not strictly increasing")
        if not np.isfinite(result.motor_torque).all():
            raise WrongAnswer("motor torque")
    elif hasattr(result, "joints"):  # a fleet manifest
        if not result.joints:
            raise WrongAnswer("a manifest without joints")
    else:
        raise WrongAnswer(f"unexpected result {type(result).__name__}")


def same_values(a: Any, b: Any) -> bool:
    if isinstance(a, list):
        a, b = RawLog.concatenate(a), RawLog.concatenate(b)
    if hasattr(a, "joints"):
        return [j.settings() for j in a.joints] == [j.settings() for j in b.joints]
    names = SAMPLE_COLUMNS if isinstance(a, FrictionSamples) else ["time", "velocity", "torque"]
    return all(np.array_equal(getattr(a, k), getattr(b, k)) for k in names)


class _Count(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


def classify(
    call: Callable[[], Any], path: Path, check: Callable[[Any], None] = check_valid
) -> tuple[str, Any]:
    """``("error", message)`` or ``("valid", result)``; anything else raises.

    Another exception propagates (a traceback); a RuntimeWarning, a multi-line message, a
    message that does not name ``path``, more than two log warnings or a result that
    ``check`` refuses (default :func:`check_valid`) raise :class:`WrongAnswer` or
    AssertionError.
    """
    counter = _Count()
    logger = logging.getLogger("fricid")
    logger.addHandler(counter)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            try:
                result = call()
            except FricidError as exc:
                message = str(exc)
                assert "\n" not in message and "\r" not in message, f"multi-line: {message!r}"
                assert path.name in message, f"the message does not name {path.name}: {message}"
                return "error", message
    finally:
        logger.removeHandler(counter)
    assert len(counter.records) <= 2, f"{len(counter.records)} log warnings for one file"
    check(result)
    return "valid", result


# --------------------------------------------------------------------------- the readers


def _samples() -> FrictionSamples:
    v = np.array([-0.8, -0.4, -0.1, 0.1, 0.4, 0.8])
    return FrictionSamples(
        velocity=v,
        load=np.abs(v),
        temperature=30.0,
        friction=0.2 * np.sign(v) + 0.1 * v,
        count=np.arange(1, 7),
        std=np.full(6, 0.01),
        source="bench",
        meta={"k": [1, 2]},
    )


def _rawlog(current: bool = False) -> RawLog:
    t = np.arange(20) * 0.01
    effort = 0.1 + 0.05 * np.sin(t)
    return RawLog(
        time=t,
        position=0.2 * t,
        velocity=np.full(20, 0.2),
        temperature=25.0 + t,
        torque=None if current else effort,
        current=effort / 0.05 if current else None,
        torque_constant=0.05 if current else None,
        joint="j1",
        source="run.bin",
    )


EPOS = (
    "Date:;2020-07-08 21:28:28\r\nSampling period:;10.000\r\n"
    "Scale:;0;True;2.000;6.000;-14.000;2.000\r\n"
    ";Velocity actual value averaged;Torque actual value averaged\r\nms;rpm;%\r\n"
    + "".join(f"{10.0 * i:.3f};-10;{-30 + i % 3:.1f}\r\n" for i in range(20))
)
GENERIC = "# exported\nt [s],q [deg],dq [deg/s],tau [mNm],T [degC]\n" + "".join(
    f"{0.01 * i:.2f},{0.5 * i:.2f},50,{100 + i},{25 + 0.1 * i:.1f}\n" for i in range(20)
)
GENERIC_MAP = {
    "time": "t [s]",
    "position": "q [deg]",
    "velocity": "dq [deg/s]",
    "torque": "tau [mNm]",
    "temperature": "T [degC]",
}
MANIFEST_CSV = (
    "# fleet\nrobot,joint,log,model,method,seed,positions [deg],fix\n"
    "R1,j1,logs/a.parquet,msk;vlt,lm,3,-60:-20:10,xi=1\nR1,j2,logs/b.csv,stribeck,bas,1,,\n"
)
MANIFEST_YAML = (
    "defaults:\n  method: lm\n  positions [deg]: [-60, -40, -20]\njoints:\n"
    "  - {robot: R1, joint: j1, log: logs/a.parquet, model: [msk, vlt], seed: 3}\n"
    "  - robot: R2\n    joint: j1\n    log: b.csv\n    fix: {xi: 1}\n"
)


@dataclass(frozen=True)
class Reader:
    """A reader under test: its undamaged file and how to read a file of that kind."""

    name: str
    suffix: str
    build: Callable[[Path], None]  # writes the undamaged file at the given path
    read: Callable[[Path], Any]
    kinds: Sequence[str]


def _write(text: str) -> Callable[[Path], None]:
    return lambda path: path.write_bytes(text.encode())


def _mcap(path: Path) -> None:
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    js, hdr, tm = (
        ts.types[k]
        for k in (
            "sensor_msgs/msg/JointState",
            "std_msgs/msg/Header",
            "builtin_interfaces/msg/Time",
        )
    )
    folder = path.with_suffix("")
    with Writer(folder, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        conn = w.add_connection("/joint_states", js.__msgtype__, typestore=ts)
        for i in range(40):
            ns = 1_700_000_000_000_000_000 + i * 2_000_000
            msg = js(
                header=hdr(stamp=tm(sec=ns // 10**9, nanosec=ns % 10**9), frame_id=""),
                name=["elbow"],
                position=np.array([0.01 * i]),
                velocity=np.array([0.3]),
                effort=np.array([0.1 + 0.001 * i]),
            )
            w.write(conn, ns, ts.serialize_cdr(msg, js.__msgtype__))
    shutil.move(next(folder.glob("*.mcap")), path)
    shutil.rmtree(folder)


READERS = {
    r.name: r
    for r in [
        Reader(
            "samples_csv",
            ".csv",
            lambda p: write_samples(_samples(), p),
            read_samples,
            [*TEXT_KINDS, "meta_line"],
        ),
        Reader(
            "rawlog_csv",
            ".csv",
            lambda p: write_rawlog(_rawlog(), p),
            read_rawlog,
            [*TEXT_KINDS, "meta_line"],
        ),
        Reader(
            "rawlog_csv_chunks",
            ".csv",
            lambda p: write_rawlog(_rawlog(True), p),
            lambda p: list(iter_rawlog(p, chunk_rows=7)),
            [*TEXT_KINDS, "meta_line"],
        ),
        Reader(
            "samples_parquet",
            ".parquet",
            lambda p: write_samples(_samples(), p),
            read_samples,
            PARQUET_KINDS,
        ),
        Reader(
            "rawlog_parquet",
            ".parquet",
            lambda p: write_rawlog(_rawlog(True), p),
            lambda p: list(iter_rawlog(p, chunk_rows=7)),
            PARQUET_KINDS,
        ),
        Reader("epos", ".csv", _write(EPOS), read_epos, TEXT_KINDS),
        Reader(
            "generic_csv",
            ".csv",
            _write(GENERIC),
            lambda p: read_table_log(p, GENERIC_MAP),
            TEXT_KINDS,
        ),
        Reader(
            "mcap",
            ".mcap",
            _mcap,
            lambda p: read_rosbag(p, "elbow", temperature=25.0),
            [*BINARY_KINDS, "mcap_length", "mcap_length"],
        ),
        Reader("manifest_csv", ".csv", _write(MANIFEST_CSV), read_manifest, TEXT_KINDS),
        Reader("manifest_yaml", ".yaml", _write(MANIFEST_YAML), read_manifest, TEXT_KINDS),
    ]
}


class Workspace:
    """Undamaged files (built once) and a scratch folder for damaged copies."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.base: dict[str, tuple[bytes, Any]] = {}
        self.n = 0

    def baseline(self, reader: Reader) -> tuple[bytes, Any]:
        if reader.name not in self.base:
            path = self.folder / f"base_{reader.name}{reader.suffix}"
            reader.build(path)
            self.base[reader.name] = (path.read_bytes(), reader.read(path))
        return self.base[reader.name]

    def run(self, reader: Reader, ch: RngChooser) -> tuple[str, list[str]]:
        """One damaged file: its outcome ("error" or "valid") and the damage done."""
        data, expected = self.baseline(reader)
        kinds = [ch.choice(reader.kinds) for _ in range(ch.integer(1, 3))]
        for kind in kinds:
            data = mutate(data, kind, ch)
        self.n += 1
        path = self.folder / f"case{self.n}{reader.suffix}"
        path.write_bytes(data)
        try:
            outcome, result = classify(lambda: reader.read(path), path)
        finally:
            path.unlink()
        if outcome == "valid" and set(kinds) <= BENIGN and not same_values(result, expected):
            raise WrongAnswer(f"{kinds} changed the values read")
        return outcome, kinds
