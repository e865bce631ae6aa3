"""Damaged input files for every reader and the oracle that judges a reader's outcome.

Shared by ``tests/io/test_fuzz_readers.py`` (hypothesis draws the damage) and
``benchmarks/fuzz_readers.py`` (a seeded generator draws it, longer, and counts outcomes).
A reader given a damaged file must end in a :class:`~fricid.errors.FricidError` on one line
naming the file, or a valid result (finite SI values within :data:`fricid.samples.LIMITS`,
consistent row counts, time increasing; after a change that keeps the data, the very values
of the undamaged file). :func:`classify` raises for anything else.

Beyond the table files: MATLAB v5 files (their 128-byte header, tags, dimensions, classes
and flags rewritten word by word, inside compressed elements too; decompression bombs; every
MATLAB type in place of a variable) and v7.3 files (every HDF5 construct fricid must refuse:
huge declared datasets and chunks, links elsewhere or nowhere, external storage, logical,
complex, cell, sparse, text), per-channel folders (random file sets and patterns:
:func:`channels_case`), and byte flips in Parquet and MCAP files that carry checksums, after
which a valid result must hold the very values of the undamaged file. Every case must also
stay within :data:`LIMIT_BYTES` of peak memory and :data:`LIMIT_SECONDS`.

The module is over 500 lines on purpose: the mutations, the oracle and the table of readers
with their undamaged files are one fixture, used whole by the test and by the benchmark.
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import re
import resource
import shutil
import struct
import time
import warnings
import zlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import strategies as st

from fricid.errors import ConfigError, DataQualityWarning, FricidError
from fricid.fleet import read_manifest
from fricid.io import (
    iter_rawlog,
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
from fricid.io import matlab as _matlab
from fricid.io.channels import compile_pattern
from fricid.samples import LIMITS, SAMPLE_COLUMNS, FrictionSamples, RawLog

#: Peak memory [bytes] and time [s] any one case may take.
LIMIT_BYTES, LIMIT_SECONDS = 2 * 2**30, 60.0
#: The cap of the MATLAB reader during the fuzz (its default is 2 GiB): bombs reach it in
#: well under a second.
FUZZ_MAT_CAP = 64 * 2**20

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
    if kind == "flip1":  # one byte: what a checksum must catch
        if not data:
            return data
        b = bytearray(data)
        b[ch.integer(0, len(b) - 1)] ^= ch.integer(1, 255)
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
    if kind in MAT_KINDS:
        return MAT_KINDS[kind](data, ch)
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


# --------------------------------------------------------------------------- MATLAB files

MAT_TEXT = b"MATLAB 5.0 MAT-file, Platform: GLNXA64, Created on: Mon Mar  2 10:00:00 2026"
#: The table of means every MATLAB fixture holds: velocity [rad/s] and friction [N m].
MAT_TABLE = {
    "v": np.array([0.05, 0.2, 1.0, -0.05, -0.2, -1.0]),
    "f": np.array([0.31, 0.33, 0.4, -0.31, -0.33, -0.4]),
}
MAT_VARS = {"velocity": "v", "friction": "f"}
MAT_UNITS = {"velocity": "rad/s", "friction": "N m"}


def mat_header(order: str = "<", text: bytes = MAT_TEXT) -> bytes:
    """A v5 header: 116 bytes of text, no subsystem, version 0x0100, the byte order mark."""
    mark = b"IM" if order == "<" else b"MI"
    return text.ljust(116, b" ")[:116] + bytes(8) + struct.pack(order + "H", 0x0100) + mark


def mat_element(mdtype: int, data: bytes, order: str = "<") -> bytes:
    """A v5 data element: its tag, its data, padding to 8 bytes."""
    return struct.pack(order + "II", mdtype, len(data)) + data + bytes(-len(data) % 8)


def mat_array(
    name: str,
    dims: Sequence[int],
    cls: int = 6,
    parts: Sequence[bytes] = (b"",),
    mi: int = 9,
    flags: int = 0,
) -> bytes:
    """An ``miMATRIX`` element: flags (class ``cls``), dimensions, name, data parts."""
    body = (
        mat_element(6, struct.pack("<II", cls | flags, 0))
        + mat_element(5, struct.pack(f"<{len(dims)}i", *dims))
        + mat_element(1, name.encode())
        + b"".join(mat_element(mi, part) for part in parts)
    )
    return mat_element(14, body)


def mat_compressed(element: bytes, tail: bytes = b"", level: int = 1) -> bytes:
    """An ``miCOMPRESSED`` element holding ``element`` (and ``tail`` after it)."""
    packed = zlib.compress(element + tail, level)
    return struct.pack("<II", 15, len(packed)) + packed


def _mat_split(data: bytes) -> list[tuple[bool, bytes]] | None:
    """A v5 file's top-level elements, compressed ones inflated; None when not parseable."""
    out, pos = [], 128
    while pos + 8 <= len(data):
        mdtype, nbytes = struct.unpack_from("<II", data, pos)
        body = data[pos + 8 : pos + 8 + nbytes]
        if mdtype == 15:
            try:
                out.append((True, zlib.decompress(body)))
            except zlib.error:
                return None
        else:
            out.append((False, data[pos : pos + 8 + nbytes]))
        pos += 8 + nbytes
    return out if pos == len(data) and len(data) >= 128 else None


def _mat_join(head: bytes, elements: list[tuple[bool, bytes]]) -> bytes:
    return head + b"".join(mat_compressed(e) if z else e for z, e in elements)


#: Words written into a MATLAB structure: classes, types, sizes, flags, absurd counts.
MAT_WORDS = [
    0,
    1,
    2,
    3,
    4,
    5,
    6,
    8,
    9,
    14,
    15,
    16,
    17,
    0x0200 | 6,
    0x0800 | 6,
    100_000,
    2**20,
    2**31 - 1,
    2**32 - 1,
    (4 << 16) | 5,
    (8 << 16) | 1,
]


def _mat_word(data: bytes, ch: RngChooser) -> bytes:
    """One 32-bit word of one array's structure replaced (inside a compressed element too)."""
    elements = _mat_split(data)
    if not elements:
        return data
    i = ch.integer(0, len(elements) - 1)
    z, element = elements[i]
    if len(element) < 8:
        return data
    at = 4 * ch.integer(0, len(element) // 4 - 1)
    word = ch.choice(MAT_WORDS) if ch.integer(0, 3) else ch.integer(0, 2**32 - 1)
    b = bytearray(element)
    struct.pack_into("<I", b, at, word)
    elements[i] = (z, bytes(b))
    return _mat_join(data[:128], elements)


def _mat_head(data: bytes, ch: RngChooser) -> bytes:
    """The header's version, byte order mark or first bytes damaged."""
    b = bytearray(data.ljust(128, b"\0"))
    what = ch.integer(0, 3)
    if what == 0:
        b[124:126] = struct.pack("<H", ch.choice([0, 0x0200, 0x0101, 0xFFFF]))
    elif what == 1:
        b[126:128] = ch.choice([b"MI", b"\0\0", b"IX", b"im"])
    elif what == 2:
        b[0:4] = bytes(4)
    else:
        b[:128] = bytes(128)
    return bytes(b)


def _mat_text(data: bytes, ch: RngChooser) -> bytes:
    """The descriptive text of the header rewritten: a change that keeps the data."""
    text = ch.raw(ch.integer(4, 116)).replace(b"\0", b" ")
    text = b"M" + text[1:] if text[:1] == b"\0" else text
    return b"MATL" + text.ljust(112, b" ")[:112] + data[116:]


def _mat_bomb(data: bytes, ch: RngChooser) -> bytes:
    """Zeros after one array inside its compressed element: a few MiB, or past the cap."""
    elements = _mat_split(data)
    if not elements:
        return data
    i = ch.integer(0, len(elements) - 1)
    size = ch.choice([2**20, FUZZ_MAT_CAP + 2**20])
    parts = [
        mat_compressed(e, bytes(size)) if k == i else mat_compressed(e) if z else e
        for k, (z, e) in enumerate(elements)
    ]
    return data[:128] + b"".join(parts)


def _mat_values(ch: RngChooser) -> Any:
    """A value of another MATLAB type for one of the variables."""
    import scipy.sparse

    v = MAT_TABLE["v"]
    return ch.choice(
        [
            v > 0,  # logical
            v + 1j * v,  # complex
            scipy.sparse.csc_matrix(v.reshape(1, -1)),
            np.array([v[0], "x"], dtype=object),  # cell
            "text",
            (v * 100).astype(np.int16),  # a class that is numbers
            v.astype(np.float32),
            {"a": v},  # struct
            np.zeros((0,)),
            np.full(6, np.nan),
            np.tile(v, (3, 1)).T,  # one column per joint
            np.array(1e300),
            v[:3],  # another length
            [{"a": 1.0}, {"a": 2.0}],  # struct array
        ]
    )


def _mat_type(data: bytes, ch: RngChooser) -> bytes:
    """The file written again with one variable of another type."""
    table = dict(MAT_TABLE)
    table[ch.choice(["v", "f"])] = _mat_values(ch)
    sink = io.BytesIO()
    import scipy.io

    scipy.io.savemat(sink, table, do_compression=bool(ch.integer(0, 1)))
    return sink.getvalue()


def _mat73(table: dict[str, Any] | None = None, variant: str = "", ch: Any = None) -> bytes:
    """A v7.3 file as MATLAB writes one (a 512-byte user block with the MATLAB header,
    ``MATLAB_class`` attributes, arrays transposed), ``variant`` applied to ``v``."""
    import h5py

    sink = io.BytesIO()
    with h5py.File(sink, "w", userblock_size=512) as f:
        for name, values in (table or MAT_TABLE).items():
            if name == "v" and variant:
                _h5_variant(f, variant, values)
                continue
            ds = f.create_dataset(name, data=np.atleast_2d(values))
            ds.attrs["MATLAB_class"] = np.bytes_(b"double")
    raw = bytearray(sink.getvalue())
    raw[:128] = mat_header(text=MAT_TEXT.replace(b"5.0", b"7.3"))
    raw[124:126] = struct.pack("<H", 0x0200)
    return bytes(raw)


#: Constructs of HDF5 that a v7.3 variable may be, most of which fricid must refuse.
H5_VARIANTS = [
    "huge",
    "huge_chunk",
    "bool",
    "complex",
    "cell",
    "string",
    "class_logical",
    "class_char",
    "sparse",
    "struct",
    "empty",
    "dangling",
    "external_link",
    "external_storage",
    "alias",
    "int16",
    "nan",
    "3d",
    "null",
    "datatype",
]


def _h5_variant(f: Any, variant: str, values: np.ndarray) -> None:
    """Variable ``v`` of an open HDF5 file written as ``variant`` (:data:`H5_VARIANTS`)."""
    import h5py

    data = np.atleast_2d(values)
    cls = {"class_logical": b"logical", "class_char": b"char", "int16": b"int16"}.get(variant)
    if variant == "huge":
        f.create_dataset("v", shape=(100_000, 100_000), dtype="f8", chunks=(100, 100))
    elif variant == "huge_chunk":
        f.create_dataset(
            "v", shape=data.shape, dtype="f8", maxshape=(None, None), chunks=(1, 2**28 + 2**20)
        )
    elif variant == "bool":
        f.create_dataset("v", data=data > 0)
    elif variant == "complex":
        f.create_dataset("v", data=data + 1j)
    elif variant == "cell":
        refs = f.create_dataset("v", shape=(1, 2), dtype=h5py.ref_dtype)
        refs[0, 0] = f["f"].ref if "f" in f else f.create_dataset("#refs#/a", data=data).ref
    elif variant == "string":
        f.create_dataset("v", data=np.bytes_(b"text"))
    elif variant == "sparse":
        g = f.create_group("v")
        g.attrs["MATLAB_sparse"] = 6
        g.create_dataset("data", data=values)
    elif variant == "struct":
        f.create_group("v").create_dataset("a", data=data)
    elif variant == "empty":
        ds = f.create_dataset("v", data=np.array([0, 0], dtype=np.uint64))
        ds.attrs["MATLAB_empty"] = np.uint8(1)
    elif variant == "dangling":
        f["v"] = h5py.SoftLink("/nowhere")
    elif variant == "external_link":
        f["v"] = h5py.ExternalLink("other.mat", "/v")
    elif variant == "external_storage":
        f.create_dataset("v", shape=data.shape, dtype="f8", external=[("/dev/zero", 0, 48)])
    elif variant == "alias":
        f.create_dataset("w", data=data)
        f["v"] = h5py.SoftLink("/w")
    elif variant == "nan":
        f.create_dataset("v", data=np.full(data.shape, np.nan))
    elif variant == "3d":
        f.create_dataset("v", data=np.stack([data, data]))
    elif variant == "null":
        f.create_dataset("v", data=h5py.Empty("f8"))
    elif variant == "datatype":
        f["v"] = np.dtype("f8")
    else:
        ds = f.create_dataset(
            "v", data=(data * 100).astype(np.int16) if variant == "int16" else data
        )
        if cls is not None:
            ds.attrs["MATLAB_class"] = np.bytes_(cls)


def _h5_rewrite(data: bytes, ch: RngChooser) -> bytes:
    """The v7.3 file written again with ``v`` as one of :data:`H5_VARIANTS`."""
    return _mat73(variant=ch.choice(H5_VARIANTS))


MAT_KINDS = {
    "mat_word": _mat_word,
    "mat_header": _mat_head,
    "mat_text": _mat_text,
    "mat_bomb": _mat_bomb,
    "mat_type": _mat_type,
    "h5_variant": _h5_rewrite,
}


@contextlib.contextmanager
def mat_cap(cap: int) -> Any:
    """The MATLAB reader's cap set to ``cap`` bytes for the block."""
    old = getattr(_matlab, "MAX_BYTES", None)  # None: a fricid without the cap
    _matlab.MAX_BYTES = cap
    try:
        yield
    finally:
        if old is None:
            del _matlab.MAX_BYTES
        else:
            _matlab.MAX_BYTES = old


def read_mat_fuzz(path: Path) -> Any:
    """The MATLAB table of the fixtures read, under :data:`FUZZ_MAT_CAP`."""
    with mat_cap(FUZZ_MAT_CAP):
        return read_mat(path, MAT_VARS, MAT_UNITS)


def _mat_v5(compress: bool) -> Callable[[Path], None]:
    def build(path: Path) -> None:
        import scipy.io

        sink = io.BytesIO()
        scipy.io.savemat(sink, MAT_TABLE, do_compression=compress)
        path.write_bytes(mat_header() + sink.getvalue()[128:])

    return build


# --------------------------------------------------------------------------- MCAP checksums


def mcap_with_crcs(data: bytes) -> bytes:
    """An MCAP file with the CRC-32 of each chunk, of the data section and of the summary
    filled in, as the MCAP library's writer does (rosbags writes zeros: not computed)."""
    b = bytearray(data)
    pos, data_end, footer = 8, None, None
    while pos + 9 <= len(b):
        op, length = struct.unpack_from("<BQ", b, pos)
        if op == 0x06:
            name_len = struct.unpack_from("<I", b, pos + 9 + 28)[0]
            compression = bytes(b[pos + 41 : pos + 41 + name_len])
            size = struct.unpack_from("<Q", b, pos + 41 + name_len)[0]
            records = bytes(b[pos + 49 + name_len : pos + 49 + name_len + size])
            if compression == b"zstd":
                from backports import zstd

                records = zstd.decompress(records)
            struct.pack_into("<I", b, pos + 9 + 24, zlib.crc32(records))
        elif op == 0x0F:
            data_end = pos
        elif op == 0x02:
            footer = pos
            break
        pos += 9 + length
    assert data_end is not None and footer is not None, "not an MCAP file written by rosbags"
    struct.pack_into("<I", b, data_end + 9, zlib.crc32(bytes(b[:data_end])))
    summary = struct.unpack_from("<Q", b, footer + 9)[0]
    struct.pack_into("<I", b, footer + 25, zlib.crc32(bytes(b[summary or footer : footer + 25])))
    return bytes(b)


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
PARQUET_KINDS = [*BINARY_KINDS, "parquet_meta", "parquet_meta", *["flip1"] * 6]
MAT_V5_KINDS = [
    *BINARY_KINDS,
    *["mat_word"] * 4,
    "mat_header",
    "mat_text",
    "mat_bomb",
    "mat_type",
    "mat_type",
]
MAT_V73_KINDS = [*BINARY_KINDS, "h5_variant", "h5_variant", "h5_variant", "mat_text"]


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
    """Raise :class:`WrongAnswer` unless ``result`` holds the invariants of its type (a tuple:
    independent results, such as the runs of a per-channel folder)."""
    if isinstance(result, tuple):
        if not result:
            raise WrongAnswer("no results")
        for item in result:
            check_valid(item)
        return
    if isinstance(result, list):
        last = -np.inf
        for log in result:
            check_valid(log)
            if log.time[0] <= last:
                raise WrongAnswer("time does not increase across chunks")
            last = log.time[-1]
        return
    if isinstance(result, FrictionSamples):
        absent = {"load", "temperature"} - set(result.measured)  # not measured: all NaN
        if _check_columns(result, [c for c in SAMPLE_COLUMNS if c not in absent]) < 1:
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


def same_values(a: Any, b: Any, meta: bool = False) -> bool:
    """Whether two results hold the same values: every column, the joint and torque constant,
    with ``meta`` the metadata too (not the source: the file's name differs)."""
    if isinstance(a, list):
        a, b = RawLog.concatenate(a), RawLog.concatenate(b)
    if hasattr(a, "joints"):
        return [j.settings() for j in a.joints] == [j.settings() for j in b.joints]
    if type(a) is not type(b):
        return False
    if isinstance(a, FrictionSamples):
        names: Sequence[str] = list(SAMPLE_COLUMNS)
    else:
        names = ["time", "position", "velocity", "temperature", "torque", "current"]
        if (a.joint, a.torque_constant) != (b.joint, b.torque_constant):
            return False
    if meta and a.meta != b.meta:
        return False
    return all(_same(getattr(a, k), getattr(b, k)) for k in names)


def _same(x: Any, y: Any) -> bool:
    if x is None or y is None:
        return x is None and y is None
    return np.array_equal(x, y, equal_nan=True)


class _Count(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


def classify(
    call: Callable[[], Any],
    path: Path,
    check: Callable[[Any], None] = check_valid,
    *,
    options: bool = False,
) -> tuple[str, Any]:
    """``("error", message)`` or ``("valid", result)``; anything else raises.

    Another exception propagates (a traceback); a RuntimeWarning, a multi-line message, a
    message that does not name ``path`` (with ``options``, a ConfigError about the options
    drawn need not), more than two log warnings or a result that ``check`` refuses (default
    :func:`check_valid`) raise :class:`WrongAnswer` or AssertionError.
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
                if not (options and isinstance(exc, ConfigError)):
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
    #: Damage after which a valid result must hold the undamaged file's very values: changes
    #: that keep the data, or any damage at all to a file whose checksums cover it.
    exact: frozenset[str] = frozenset(BENIGN)


def _write(text: str) -> Callable[[Path], None]:
    return lambda path: path.write_bytes(text.encode())


def _mcap(path: Path, zstd: bool = False) -> None:
    """A bare MCAP file of 40 JointState messages, its chunks compressed with ``zstd`` (the
    MCAP library writer's default) or not."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.rosbag2.enums import CompressionFormat, CompressionMode
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
    writer = Writer(folder, version=9, storage_plugin=StoragePlugin.MCAP)
    if zstd:
        writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    with writer as w:
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


def _mcap_crc(zstd: bool) -> Callable[[Path], None]:
    def build(path: Path) -> None:
        _mcap(path, zstd)
        path.write_bytes(mcap_with_crcs(path.read_bytes()))

    return build


#: Any damage: a file with checksums gives an error or its very values.
ANY = frozenset([*BINARY_KINDS, "flip1", "mcap_length"])


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
            ANY,
        ),
        Reader(
            "rawlog_parquet",
            ".parquet",
            lambda p: write_rawlog(_rawlog(True), p),
            lambda p: list(iter_rawlog(p, chunk_rows=7)),
            PARQUET_KINDS,
            ANY,
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
        Reader(
            "mcap_crc",
            ".mcap",
            _mcap_crc(False),
            lambda p: read_rosbag(p, "elbow", temperature=25.0),
            [*BINARY_KINDS, *["flip1"] * 6, "mcap_length"],
            ANY,
        ),
        Reader(
            "mcap_zstd_crc",
            ".mcap",
            _mcap_crc(True),
            lambda p: read_rosbag(p, "elbow", temperature=25.0),
            [*BINARY_KINDS, *["flip1"] * 6, "mcap_length"],
            ANY,
        ),
        Reader(
            "mat_v5", ".mat", _mat_v5(False), read_mat_fuzz, MAT_V5_KINDS, frozenset({"mat_text"})
        ),
        Reader(
            "mat_v5z", ".mat", _mat_v5(True), read_mat_fuzz, MAT_V5_KINDS, frozenset({"mat_text"})
        ),
        Reader(
            "mat_v73",
            ".mat",
            lambda p: p.write_bytes(_mat73()),
            read_mat_fuzz,
            MAT_V73_KINDS,
            frozenset({"mat_text"}),
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
            outcome, result = within_limits(lambda: classify(lambda: reader.read(path), path))
        finally:
            path.unlink()
        checksummed = not reader.exact <= BENIGN  # the metadata is covered too
        if (
            outcome == "valid"
            and set(kinds) <= reader.exact
            and not same_values(result, expected, meta=checksummed)
        ):
            raise WrongAnswer(f"{kinds} changed the values read")
        return outcome, kinds


def peak_bytes() -> int:
    """The process's peak resident memory so far [bytes] (Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def within_limits(call: Callable[[], Any]) -> Any:
    """``call()``, failing with :class:`WrongAnswer` if it took over :data:`LIMIT_SECONDS` or
    the process's peak memory passed :data:`LIMIT_BYTES`."""
    start = time.perf_counter()
    result = call()
    took = time.perf_counter() - start
    if took > LIMIT_SECONDS:
        raise WrongAnswer(f"one case took {took:.0f} s (limit {LIMIT_SECONDS:.0f} s)")
    if peak_bytes() > LIMIT_BYTES:
        raise WrongAnswer(f"peak memory {peak_bytes() / 2**30:.2f} GiB (limit 2 GiB)")
    return result


# --------------------------------------------------------------------------- per-channel folders

#: Patterns of each channel: with fields that tell runs apart, without, sharing files.
CHANNEL_PATTERNS = {
    "torque": ["{name}_tau{joint}_{speed}.t", "run_tau*.t", "*", "*.t", "{name}_tau*.t"],
    "velocity": ["{name}_vel{joint}_{speed}.t", "run_vel*.t", "*", "*.t", "{name}_vel*.t"],
    "position": ["{name}_pos{joint}_{speed}.t", "run_pos*.t", "*", "*.t", "{name}_pos*.t"],
}
_CHANNEL_FILES = {"torque": "tau", "velocity": "vel", "position": "pos"}


def _channel_text(quantity: str, speed: int) -> bytes:
    t = np.arange(60) * 0.01
    w = np.deg2rad(speed)
    v = np.where(np.arange(60) < 30, w, -w)
    values = {"velocity": v, "position": np.cumsum(v) * 0.01, "torque": 0.3 * np.sign(v) + 0.1 * v}
    return "".join(f"{a:.3f} {b:.9g}\n" for a, b in zip(t, values[quantity], strict=True)).encode()


def channels_case(folder: Path, ch: RngChooser) -> tuple[str, list[str]]:
    """A random folder of per-channel files read with random patterns.

    Runs of joint 1 at one to three set-points, one file per channel; then files deleted,
    copied under another name, damaged (a text mutation), a FIFO or a link to ``/dev/zero``
    in a channel's name. Besides :func:`classify`'s oracle, a valid result must use every
    regular file a pattern matches exactly once: none dropped (a run lost), none read twice
    (one file as two channels).
    """
    folder.mkdir()
    speeds = [20, 40, 80][: ch.integer(1, 3)]
    for speed in speeds:
        for quantity, short in _CHANNEL_FILES.items():
            (folder / f"run_{short}1_{speed}.t").write_bytes(_channel_text(quantity, speed))
    done = []
    for _ in range(ch.integer(0, 3)):
        names = sorted(p.name for p in folder.iterdir())
        victim = folder / ch.choice(names) if names else None
        what = ch.choice(["delete", "copy", "damage", "fifo", "device", "subfolder"])
        done.append(what)
        if victim is None or not victim.is_file():
            continue
        if what == "delete":
            victim.unlink()
        elif what == "copy":
            shutil.copy(victim, folder / f"{victim.stem}{ch.choice(['_b', ' copy', '2'])}.t")
        elif what == "damage":
            victim.write_bytes(mutate(victim.read_bytes(), ch.choice(TEXT_KINDS), ch))
        elif what == "fifo" and hasattr(os, "mkfifo"):
            victim.unlink()
            os.mkfifo(victim)
        elif what == "device" and os.path.exists("/dev/zero"):
            victim.unlink()
            victim.symlink_to("/dev/zero")
        elif what == "subfolder":
            (folder / "sub").mkdir(exist_ok=True)
            shutil.copy(victim, folder / "sub" / victim.name)
    which = ch.integer(0, len(CHANNEL_PATTERNS["torque"]) - 1)
    patterns = {
        q: options[which if ch.integer(0, 3) else ch.integer(0, len(options) - 1)]
        for q, options in CHANNEL_PATTERNS.items()
    }
    units = {"torque": "N m", "velocity": "deg/s", "position": "deg"}

    def read() -> tuple[RawLog, ...]:
        with warnings.catch_warnings():  # rows dropped by the join: expected, not printed
            warnings.simplefilter("ignore", DataQualityWarning)
            return tuple(read_channels(folder, patterns, units, temperature=25.0))

    outcome, result = within_limits(lambda: classify(read, folder, options=True))
    if outcome == "valid":
        _check_files_used(folder, patterns, result)
    return outcome, [*done, *patterns.values()]


def _check_files_used(folder: Path, patterns: dict[str, str], logs: tuple[RawLog, ...]) -> None:
    used = [path for log in logs for path in log.meta["files"].values()]
    if len(used) != len(set(used)):
        raise WrongAnswer(f"a file read as two channels or in two runs: {sorted(used)}")
    regular = [p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()]
    matched = {
        str(folder / rel)
        for rx, _ in (compile_pattern(p) for p in patterns.values())
        for rel in regular
        if rx.fullmatch(rel)
    }
    if matched != set(used):
        raise WrongAnswer(f"files matched but not read: {sorted(matched - set(used))}")
