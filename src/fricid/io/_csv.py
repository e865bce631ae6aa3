"""CSV machinery shared by the readers and writers: the preamble, fast numeric reading, error
location, streamed atomic writing.

The normal path is pyarrow's multi-threaded CSV reader (no Python loop per row). Only when it
fails, or finds a NaN or infinity, does :func:`locate_bad_value` walk the file with the
:mod:`csv` module to name the exact line and column.
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv

from ..errors import DataError
from ..units import SI_UNITS
from ._columns import split_label
from ._dialect import Dialect, detect_dialect
from ._files import check_input
from ._meta import dumps_meta, encode_text
from .atomic import atomic_write

__all__ = [
    "Preamble",
    "csv_preamble",
    "iter_numeric",
    "locate_bad_value",
    "preamble_fields",
    "read_numeric",
    "read_preamble",
    "rechunk",
    "record_line",
    "write_csv",
]

#: Bytes pyarrow parses at a time when streaming (about 13 k rows of a raw log). With its
#: read-ahead, streaming a 50-million-row CSV stays within about 100 MB above the baseline.
#: (Not memory-mapped: mapped pages would count in the resident size, up to the whole file.)
STREAM_BLOCK_BYTES = 1 << 20


@dataclass(frozen=True)
class Preamble:
    """The part of a CSV file before the data.

    Attributes
    ----------
    path : pathlib.Path
        The file.
    labels : list of str
        The column labels of the header line, as written.
    header_line : int
        1-based line number of the header.
    header_offset : int
        Byte offset of the header line.
    comments : dict of str to tuple of (str or None, str)
        ``{name: (unit or None, value text)}`` from leading ``# name [unit]: value`` lines,
        names lower-cased.
    dialect : Dialect
        The delimiter and decimal mark (:mod:`fricid.io._dialect`: detected or given).
    """

    path: Path
    labels: list[str]
    header_line: int
    header_offset: int
    comments: dict[str, tuple[str | None, str]] = field(default_factory=dict)
    dialect: Dialect = field(default_factory=Dialect)


def one_line(exc: BaseException) -> str:
    """An exception's message on one line (pyarrow's span several)."""
    return " ".join(str(exc).split()) or type(exc).__name__


def _decode(raw: bytes, path: Path, line: int) -> str:
    """One line as UTF-8 text; anything else is a :class:`DataError` naming the line."""
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise DataError(f"not UTF-8 text: {exc.reason}", file=path, row=line) from None


def read_preamble(path: str | os.PathLike[str]) -> Preamble:
    """Read the leading ``#`` comment lines and the header line of a CSV file.

    Blank lines before the header are skipped; a UTF-8 byte-order mark is ignored. The
    delimiter (``,``, ``;`` or a tab) and the decimal mark are detected from the header and
    the first data line unless given (:func:`fricid.io.csv_dialect`, ``fricid --delimiter``).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.

    Returns
    -------
    Preamble
        The comments, the header's labels and where the header is.

    Raises
    ------
    DataError
        Not a regular file (a folder, a device, a FIFO), an empty file, no header line, or
        text that is not UTF-8 (the line named).
    """
    path = Path(path)
    comments: dict[str, tuple[str | None, str]] = {}
    offset = 0
    line = 0
    check_input(path, what="CSV file")
    with open(path, "rb") as fh:
        while True:
            raw = fh.readline()
            if not raw:
                what = "empty file" if line == 0 else "no header line after the comments"
                raise DataError(f"{what}: expected a header line of column names", file=path)
            line += 1
            text = _decode(raw, path, line)
            if line == 1:
                text = text.removeprefix("\ufeff")
            stripped = text.strip()
            if stripped.startswith("#"):
                key, sep, value = stripped[1:].partition(":")
                if sep:
                    name, unit = split_label(key)
                    comments[name.lower()] = (unit, value.strip())
            elif stripped:
                header = text.rstrip("\r\n")
                dialect = detect_dialect(header, _first_data_line(fh))
                try:
                    labels = next(csv.reader([header], delimiter=dialect.delimiter))
                except csv.Error as exc:
                    raise DataError(f"malformed header line: {exc}", file=path, row=line) from None
                return Preamble(path, labels, line, offset, comments, dialect)
            offset += len(raw)


def _first_data_line(fh: Any) -> str | None:
    """The first non-blank line after the header (the file's position is left there), or
    None; as text, invalid UTF-8 replaced (the read itself names such a line)."""
    for _ in range(1000):
        raw = fh.readline()
        if not raw:
            return None
        text = raw.decode("utf-8", errors="replace").rstrip("\r\n")
        if text.strip():
            return text
    return None


def _convert_options(labels: list[str], dialect: Dialect) -> pacsv.ConvertOptions:
    """pyarrow's options to read ``labels`` as float64 with no null values."""
    return pacsv.ConvertOptions(
        column_types={label: pa.float64() for label in labels},
        include_columns=labels,
        null_values=[],
        strings_can_be_null=False,
        quoted_strings_can_be_null=False,
        decimal_point=dialect.decimal,
    )


def _parse_options(dialect: Dialect) -> pacsv.ParseOptions:
    """pyarrow's options to split fields at the file's delimiter."""
    return pacsv.ParseOptions(delimiter=dialect.delimiter)


def _parse_float(text: str, decimal: str = ".") -> float | None:
    """``float(text)`` as pyarrow reads it (no digit separators), or None."""
    text = text.strip()
    if "_" in text:
        return None
    if decimal == ",":
        if "." in text:
            return None
        text = text.replace(",", ".")
    try:
        return float(text)
    except ValueError:
        return None


def locate_bad_value(pre: Preamble, labels: list[str], start: int = 0) -> DataError | None:
    """Find the first malformed row, non-numeric or non-finite value in some columns.

    Parameters
    ----------
    pre : Preamble
        The file's preamble.
    labels : list of str
        The columns to check.
    start : int, default 0
        Records (0-based) before this one are known to be good and are only counted.

    Returns
    -------
    DataError or None
        The error, naming the file, the 1-based line number and the column label; None when
        every value is a finite number.
    """
    index = {label: pre.labels.index(label) for label in labels}
    wanted = sorted(index.items(), key=lambda item: item[1])
    width = len(pre.labels)
    with open(pre.path, encoding="utf-8", errors="replace", newline="") as fh:
        for _ in range(pre.header_line):
            fh.readline()
        reader = csv.reader(fh, delimiter=pre.dialect.delimiter)
        record = -1
        for fields in reader:
            if not fields:
                continue
            record += 1
            if record < start:
                continue
            line = pre.header_line + reader.line_num
            if len(fields) != width:
                return DataError(
                    f"row has {len(fields)} fields, the header has {width} "
                    "(truncated or malformed row)",
                    file=pre.path,
                    row=line,
                )
            for label, i in wanted:
                value = _parse_float(fields[i], pre.dialect.decimal)
                if value is None:
                    what = "empty value" if not fields[i].strip() else "not a number"
                    return DataError(
                        f"{what}: {fields[i]!r}", file=pre.path, row=line, column=label
                    )
                if not math.isfinite(value):
                    return DataError(
                        f"non-finite value {fields[i]!r} (NaN and infinities are not data)",
                        file=pre.path,
                        row=line,
                        column=label,
                    )
    return None


def record_line(pre: Preamble, record: int) -> int | None:
    """The line a data record is on.

    Parameters
    ----------
    pre : Preamble
        The file's preamble.
    record : int
        0-based index of a data record (blank lines do not count).

    Returns
    -------
    int or None
        Its 1-based line number in the file, or None past the end.
    """
    with open(pre.path, encoding="utf-8", errors="replace", newline="") as fh:
        for _ in range(pre.header_line):
            fh.readline()
        reader = csv.reader(fh, delimiter=pre.dialect.delimiter)
        n = -1
        for fields in reader:
            if fields:
                n += 1
                if n == record:
                    return pre.header_line + reader.line_num
    return None


def _fail(pre: Preamble, labels: list[str], exc: Exception, start: int = 0) -> DataError:
    """The error to raise for a failed read: the located bad value, else ``exc`` as text."""
    located = locate_bad_value(pre, labels, start)
    if located is not None:
        return located
    return DataError(f"cannot read CSV data: {one_line(exc)}", file=pre.path)


def _check_finite(
    pre: Preamble, labels: list[str], columns: dict[str, np.ndarray], start: int = 0
) -> None:
    """Raise the located :class:`DataError` if any value in ``columns`` is not finite."""
    if all(np.isfinite(values).all() for values in columns.values()):
        return
    raise _fail(pre, labels, ValueError("non-finite value"), start)


def read_numeric(pre: Preamble, labels: list[str]) -> dict[str, np.ndarray]:
    """Read whole columns of a CSV file.

    Parameters
    ----------
    pre : Preamble
        The file's preamble.
    labels : list of str
        The columns to read, as labelled in the header.

    Returns
    -------
    dict of str to ndarray
        Label -> float64 array of every row.

    Raises
    ------
    DataError
        A malformed row, a non-numeric or non-finite value (line and column named).
    """
    try:
        with pa.OSFile(str(pre.path)) as fh:
            fh.seek(pre.header_offset)
            table = pacsv.read_csv(
                fh,
                parse_options=_parse_options(pre.dialect),
                convert_options=_convert_options(labels, pre.dialect),
            )
    except pa.ArrowInvalid as exc:
        raise _fail(pre, labels, exc) from None
    columns = {label: table.column(label).to_numpy() for label in labels}
    _check_finite(pre, labels, columns)
    return columns


def rechunk(batches: Iterable[pa.RecordBatch], rows: int) -> Iterator[pa.Table]:
    """Regroup record batches into tables of a fixed number of rows.

    Parameters
    ----------
    batches : iterable of pyarrow.RecordBatch
        Batches of any sizes, with the same schema.
    rows : int
        Rows per table.

    Yields
    ------
    pyarrow.Table
        Tables of exactly ``rows`` rows; the last may be shorter.
    """
    buffer: list[pa.RecordBatch] = []
    held = 0
    for batch in batches:
        if batch.num_rows == 0:
            continue
        buffer.append(batch)
        held += batch.num_rows
        while held >= rows:
            table = pa.Table.from_batches(buffer)
            yield table.slice(0, rows)
            buffer = table.slice(rows).to_batches()
            held -= rows
    if held:
        yield pa.Table.from_batches(buffer)


def iter_numeric(
    pre: Preamble, labels: list[str], chunk_rows: int
) -> Iterator[tuple[int, dict[str, np.ndarray]]]:
    """Stream columns of a CSV file in chunks.

    Memory is bounded by a few chunks whatever the file size.

    Parameters
    ----------
    pre : Preamble
        The file's preamble.
    labels : list of str
        The columns to read.
    chunk_rows : int
        Rows per chunk.

    Yields
    ------
    start : int
        0-based index of the chunk's first record.
    columns : dict of str to ndarray
        Label -> float64 array of the chunk's rows.

    Raises
    ------
    DataError
        A malformed row, a non-numeric or non-finite value (line and column named).
    """

    def batches() -> Iterator[pa.RecordBatch]:
        with pa.OSFile(str(pre.path)) as fh:
            fh.seek(pre.header_offset)
            reader = pacsv.open_csv(
                fh,
                read_options=pacsv.ReadOptions(block_size=STREAM_BLOCK_BYTES),
                parse_options=_parse_options(pre.dialect),
                convert_options=_convert_options(labels, pre.dialect),
            )
            yield from reader

    start = 0
    stream = rechunk(batches(), chunk_rows)
    while True:
        try:
            table = next(stream)
        except StopIteration:
            return
        except pa.ArrowInvalid as exc:
            raise _fail(pre, labels, exc, start) from None
        columns = {label: table.column(label).to_numpy() for label in labels}
        _check_finite(pre, labels, columns, start)
        yield start, columns
        start += table.num_rows


# --------------------------------------------------------------------------- writing


def preamble_fields(
    fmt: str,
    source: str | None,
    joint: str | None,
    torque_constant: float | None,
    meta: Mapping[str, Any],
) -> list[tuple[str, str]]:
    """The ``# key: value`` comment lines of a fricid table file.

    Parameters
    ----------
    fmt : str
        The format tag, e.g. ``"fricid-rawlog/1"``.
    source, joint : str or None
        Written through :func:`~fricid.io._meta.encode_text` when given.
    torque_constant : float or None
        K [N m/A], written with its unit when given.
    meta : mapping
        Free-form metadata, written as one line of JSON.

    Returns
    -------
    list of tuple of (str, str)
        ``(key, value text)`` in the order written.
    """
    fields = [("format", fmt)]
    if source is not None:
        fields.append(("source", encode_text(str(source))))
    if joint is not None:
        fields.append(("joint", encode_text(str(joint))))
    if torque_constant is not None:
        key = f"torque_constant [{SI_UNITS['torque_constant']}]"
        fields.append((key, repr(float(torque_constant))))
    fields.append(("meta", dumps_meta(meta)))
    return fields


def csv_preamble(fields: list[tuple[str, str]], units: Mapping[str, str]) -> bytes:
    """The comment lines and the header line of a CSV file.

    Parameters
    ----------
    fields : list of tuple of (str, str)
        ``(key, value text)`` comment lines (:func:`preamble_fields`).
    units : mapping of str to str
        Column -> unit, in column order; unit ``"1"`` means dimensionless (no brackets).

    Returns
    -------
    bytes
        UTF-8 text ending in a newline, e.g. ``# format: ...`` then ``time [s],...``.
    """
    lines = [f"# {key}: {value}" for key, value in fields]
    lines.append(
        ",".join(name if unit == "1" else f"{name} [{unit}]" for name, unit in units.items())
    )
    return ("\n".join(lines) + "\n").encode("utf-8")


def write_csv(path: Path, preamble: bytes, tables: Iterable[pa.Table]) -> None:
    """Write a CSV file atomically, table by table.

    Parameters
    ----------
    path : pathlib.Path
        The file; nothing is left there if writing fails part-way.
    preamble : bytes
        The comment and header lines (:func:`csv_preamble`).
    tables : iterable of pyarrow.Table
        The rows, in order, all with the same columns (streamed: one in memory at a time).
    """
    options = pacsv.WriteOptions(include_header=False)
    with atomic_write(path, "wb") as fh:
        fh.write(preamble)
        writer = None
        for table in tables:
            if writer is None:
                writer = pacsv.CSVWriter(fh, table.schema, write_options=options)
            writer.write_table(table)
        if writer is not None:
            writer.close()
