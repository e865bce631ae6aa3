"""CSV machinery shared by the readers: the preamble, fast numeric reading, error location.

The normal path is pyarrow's multi-threaded CSV reader (no Python loop per row). Only when it
fails, or finds a NaN or infinity, does :func:`locate_bad_value` walk the file with the
:mod:`csv` module to name the exact line and column.
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv

from ..errors import DataError
from ._columns import split_label

__all__ = [
    "Preamble",
    "iter_numeric",
    "locate_bad_value",
    "read_numeric",
    "read_preamble",
    "rechunk",
    "record_line",
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
    path : the file.
    comments : ``{name: (unit or None, value text)}`` from leading ``# name [unit]: value``
        lines, names lower-cased.
    labels : the column labels of the header line, as written.
    header_line : 1-based line number of the header.
    header_offset : byte offset of the header line.
    """

    path: Path
    labels: list[str]
    header_line: int
    header_offset: int
    comments: dict[str, tuple[str | None, str]] = field(default_factory=dict)


def one_line(exc: BaseException) -> str:
    """An exception's message on one line (pyarrow's span several)."""
    return " ".join(str(exc).split()) or type(exc).__name__


def _decode(raw: bytes, path: Path, line: int) -> str:
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise DataError(f"not UTF-8 text: {exc.reason}", file=path, row=line) from None


def read_preamble(path: str | os.PathLike[str]) -> Preamble:
    """Read leading ``#`` comment lines and the header line of a CSV file.

    Blank lines before the header are skipped. Raises :class:`DataError` for an empty file or
    one with no header line.
    """
    path = Path(path)
    comments: dict[str, tuple[str | None, str]] = {}
    offset = 0
    line = 0
    try:
        fh = open(path, "rb")  # noqa: SIM115 - closed below
    except IsADirectoryError:
        raise DataError("is a folder, not a CSV file", file=path) from None
    with fh:
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
                try:
                    labels = next(csv.reader([text.rstrip("\r\n")]))
                except csv.Error as exc:
                    raise DataError(f"malformed header line: {exc}", file=path, row=line) from None
                return Preamble(path, labels, line, offset, comments)
            offset += len(raw)


def _convert_options(labels: list[str]) -> pacsv.ConvertOptions:
    return pacsv.ConvertOptions(
        column_types={label: pa.float64() for label in labels},
        include_columns=labels,
        null_values=[],
        strings_can_be_null=False,
        quoted_strings_can_be_null=False,
    )


def _parse_float(text: str) -> float | None:
    """``float(text)`` as pyarrow reads it (no digit separators), or None."""
    text = text.strip()
    if "_" in text:
        return None
    try:
        return float(text)
    except ValueError:
        return None


def locate_bad_value(pre: Preamble, labels: list[str], start: int = 0) -> DataError | None:
    """The first malformed row, non-numeric or non-finite value in ``labels``, or None.

    Records before ``start`` (0-based) are known to be good and only counted. The error names
    the file, the 1-based line number and the column label.
    """
    index = {label: pre.labels.index(label) for label in labels}
    wanted = sorted(index.items(), key=lambda item: item[1])
    width = len(pre.labels)
    with open(pre.path, encoding="utf-8", errors="replace", newline="") as fh:
        for _ in range(pre.header_line):
            fh.readline()
        reader = csv.reader(fh)
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
                value = _parse_float(fields[i])
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
    """The 1-based line number of data record ``record`` (0-based), or None past the end."""
    with open(pre.path, encoding="utf-8", errors="replace", newline="") as fh:
        for _ in range(pre.header_line):
            fh.readline()
        reader = csv.reader(fh)
        n = -1
        for fields in reader:
            if fields:
                n += 1
                if n == record:
                    return pre.header_line + reader.line_num
    return None


def _fail(pre: Preamble, labels: list[str], exc: Exception, start: int = 0) -> DataError:
    located = locate_bad_value(pre, labels, start)
    if located is not None:
        return located
    return DataError(f"cannot read CSV data: {one_line(exc)}", file=pre.path)


def _check_finite(
    pre: Preamble, labels: list[str], columns: dict[str, np.ndarray], start: int = 0
) -> None:
    if all(np.isfinite(values).all() for values in columns.values()):
        return
    raise _fail(pre, labels, ValueError("non-finite value"), start)


def read_numeric(pre: Preamble, labels: list[str]) -> dict[str, np.ndarray]:
    """All rows of the columns ``labels`` as float64 arrays (finite, else DataError)."""
    try:
        with pa.OSFile(str(pre.path)) as fh:
            fh.seek(pre.header_offset)
            table = pacsv.read_csv(fh, convert_options=_convert_options(labels))
    except pa.ArrowInvalid as exc:
        raise _fail(pre, labels, exc) from None
    columns = {label: table.column(label).to_numpy() for label in labels}
    _check_finite(pre, labels, columns)
    return columns


def rechunk(batches: Iterable[pa.RecordBatch], rows: int) -> Iterator[pa.Table]:
    """Regroup record batches into tables of exactly ``rows`` rows (the last may be shorter)."""
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
    """Stream ``(first record index, {label: float64 array})`` chunks of ``chunk_rows`` rows.

    Memory is bounded by a few chunks whatever the file size.
    """

    def batches() -> Iterator[pa.RecordBatch]:
        with pa.OSFile(str(pre.path)) as fh:
            fh.seek(pre.header_offset)
            reader = pacsv.open_csv(
                fh,
                read_options=pacsv.ReadOptions(block_size=STREAM_BLOCK_BYTES),
                convert_options=_convert_options(labels),
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
