"""Parquet machinery shared by the readers and writers: schema metadata, column reads, batch
streaming, streamed atomic writing, integrity.

Integrity: fricid writes every page with its CRC-32 (Parquet's page checksums) and reads with
their verification on, so a damaged page is an error, never other values. The footer has no
checksum in Parquet, so fricid adds one record at the end of writing, under
:data:`CHECK_KEY`: the row count, the CRC-32 of fricid's metadata document and the CRC-32 of
each column's values (as float64, little-endian, in row order). A reader checks the record
when it opens the file (a renamed or missing column, other metadata, another row count) and
each column's values once read. A file without the record (written by another tool, or by an
older fricid) is read as before, its page checksums verified where it has them.
"""

from __future__ import annotations

import json
import os
import zlib
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from ..errors import DataError
from ..units import SI_UNITS
from ._csv import one_line, rechunk
from ._files import check_input
from ._meta import dumps_meta
from .atomic import atomic_path

__all__ = [
    "CHECK_KEY",
    "META_KEY",
    "ROW_GROUP_ROWS",
    "iter_columns",
    "open_parquet",
    "parquet_doc",
    "read_columns",
    "schema_meta",
    "write_parquet",
]

#: Key of fricid's JSON document in the Parquet schema metadata.
META_KEY = b"fricid"

#: Key of fricid's integrity record in the Parquet footer's key-value metadata.
CHECK_KEY = b"fricid-check"

#: Largest Parquet row group written: bounds the memory a streaming reader needs per group
#: (5 float64 columns x 256 Ki rows = 10 MB).
ROW_GROUP_ROWS = 1 << 18


def open_parquet(path: str | os.PathLike[str]) -> pq.ParquetFile:
    """Open a Parquet file.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    pyarrow.parquet.ParquetFile
        The open file (no read-ahead: memory stays bounded when streaming).

    Raises
    ------
    DataError
        No such file, not a regular file (a folder, a device, a FIFO), a damaged or
        truncated file.
    """
    check_input(path, what="Parquet file")
    try:
        # no pre-buffering: it reads ahead whole row groups, unbounded for iter_batches
        pf = pq.ParquetFile(path, pre_buffer=False, page_checksum_verification=True)
    except (pa.ArrowException, OSError, UnicodeError) as exc:
        raise DataError(f"not a readable Parquet file ({one_line(exc)})", file=path) from None
    check_record(pf, path)
    return pf


def _damaged(what: str, path: str | os.PathLike[str]) -> DataError:
    return DataError(
        f"damaged or changed file: {what} (fricid's integrity record): the file is not as "
        "fricid wrote it. If you changed it on purpose (another tool, such as pandas, kept "
        f"fricid's metadata, which promises the record), save it without the schema's "
        f"'{META_KEY.decode()}' metadata",
        file=path,
    )


def check_record(pf: pq.ParquetFile, path: str | os.PathLike[str]) -> dict[str, int] | None:
    """Check a file's footer against fricid's integrity record (:data:`CHECK_KEY`).

    Parameters
    ----------
    pf : pyarrow.parquet.ParquetFile
        The open file.
    path : str or os.PathLike
        Its path (for messages).

    Returns
    -------
    dict of str to int or None
        Column -> CRC-32 of its values, to check once they are read; None for a file
        without the record (written by another tool or an older fricid).

    Raises
    ------
    DataError
        A record that is damaged or absent though fricid's metadata says it was written,
        metadata or a row count that does not match it, a column of the record missing.
    """
    try:
        raw = (pf.metadata.metadata or {}).get(CHECK_KEY)
        doc = (pf.schema_arrow.metadata or {}).get(META_KEY)
        names = pf.schema_arrow.names
        rows = pf.metadata.num_rows
    except (pa.ArrowException, OSError, UnicodeError) as exc:
        raise DataError(f"not a readable Parquet file ({one_line(exc)})", file=path) from None
    if raw is None:
        try:
            promised = json.loads(doc or b"{}").get("integrity") == CHECK_KEY.decode()
        except (ValueError, AttributeError, RecursionError):
            promised = False  # schema_meta names the bad document
        if promised:
            raise _damaged("the record is missing", path)
        return None
    try:
        record = json.loads(raw)
        crcs = record["crc32"]
        ok = (
            isinstance(record["rows"], int)
            and isinstance(record["doc_crc32"], int)
            and isinstance(crcs, dict)
            and all(isinstance(v, int) for v in crcs.values())
        )
    except (ValueError, KeyError, TypeError, RecursionError):
        ok = False
    if not ok:
        raise _damaged("the record is not readable", path)
    if record["doc_crc32"] != zlib.crc32(doc or b""):
        raise _damaged("the metadata does not match its checksum", path)
    if record["rows"] != rows:
        raise _damaged(f"{rows} rows, {record['rows']} written", path)
    missing = [name for name in crcs if name not in names]
    if missing:
        raise _damaged(f"column '{missing[0]}' is missing", path)
    return crcs


def _crc(values: np.ndarray, start: int = 0) -> int:
    """CRC-32 of float64 values, little-endian (continuing from ``start``), read in place."""
    return zlib.crc32(memoryview(np.ascontiguousarray(values, dtype="<f8")).cast("B"), start)


def _check_values(
    crcs: dict[str, int] | None, found: dict[str, int], path: str | os.PathLike[str]
) -> None:
    """Each column read against the CRC-32 written with it."""
    for label, crc in found.items():
        if crcs is not None and label in crcs and crcs[label] != crc:
            raise DataError(
                "damaged file: its values do not match the checksum written with them "
                "(fricid's integrity record)",
                file=path,
                column=label,
            )


def schema_meta(pf: pq.ParquetFile, path: str | os.PathLike[str]) -> dict[str, Any]:
    """fricid's metadata document of a Parquet file.

    Parameters
    ----------
    pf : pyarrow.parquet.ParquetFile
        The open file.
    path : str or os.PathLike
        Its path (for messages).

    Returns
    -------
    dict
        The JSON object under :data:`META_KEY` in the schema metadata; empty when another
        tool wrote the file.

    Raises
    ------
    DataError
        Metadata that is not a JSON object.
    """
    raw = (pf.schema_arrow.metadata or {}).get(META_KEY)
    if raw is None:
        return {}
    try:
        doc = json.loads(raw)
    except (json.JSONDecodeError, UnicodeDecodeError, RecursionError) as exc:
        raise DataError(
            f"schema metadata 'fricid' is not valid JSON: {one_line(exc)}", file=path
        ) from None
    if not isinstance(doc, dict):
        raise DataError("schema metadata 'fricid' must be a JSON object", file=path)
    return doc


def _to_float(table: pa.Table, labels: list[str], path: Path, first: int) -> dict[str, np.ndarray]:
    """Columns as finite float64 arrays; null, non-numeric or non-finite is a DataError naming
    the record (``first`` is the 0-based index of the table's first record)."""
    columns = {}
    for label in labels:
        col = table.column(label)
        if col.null_count:
            row = int(np.flatnonzero(col.is_null().to_numpy(zero_copy_only=False))[0])
            raise DataError("missing (null) value", file=path, row=first + row, column=label)
        try:
            values = col.cast(pa.float64()).to_numpy()
        except (pa.ArrowInvalid, pa.ArrowNotImplementedError) as exc:
            raise DataError(
                f"not numeric ({col.type}): {one_line(exc)}", file=path, column=label
            ) from None
        bad = ~np.isfinite(values)
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            raise DataError(
                f"non-finite value {float(values[row])!r} (NaN and infinities are not data)",
                file=path,
                row=first + row,
                column=label,
            )
        columns[label] = values
    return columns


def read_columns(pf: pq.ParquetFile, labels: list[str], path: Path) -> dict[str, np.ndarray]:
    """Read whole columns of a Parquet file.

    Parameters
    ----------
    pf : pyarrow.parquet.ParquetFile
        The open file.
    labels : list of str
        The columns to read.
    path : pathlib.Path
        Its path (for messages).

    Returns
    -------
    dict of str to ndarray
        Label -> float64 array of every row.

    Raises
    ------
    DataError
        Unreadable data, a null, non-numeric or non-finite value (rows in messages are
        0-based records).
    """
    crcs = check_record(pf, path)
    try:
        table = pf.read(columns=labels)
    except (pa.ArrowException, OSError, UnicodeError) as exc:
        raise DataError(f"cannot read Parquet data ({one_line(exc)})", file=path) from None
    columns = _to_float(table, labels, path, 0)
    _check_values(crcs, {label: _crc(columns[label]) for label in labels}, path)
    return columns


def iter_columns(
    pf: pq.ParquetFile, labels: list[str], path: Path, chunk_rows: int
) -> Iterator[tuple[int, dict[str, np.ndarray]]]:
    """Stream columns of a Parquet file in chunks.

    Parameters
    ----------
    pf : pyarrow.parquet.ParquetFile
        The open file.
    labels : list of str
        The columns to read.
    path : pathlib.Path
        Its path (for messages).
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
        As :func:`read_columns`; values that do not match fricid's integrity record after
        the last chunk.
    """
    crcs = check_record(pf, path)
    found = dict.fromkeys(labels, 0)
    types = pf.schema_arrow
    if all(types.field(label).type == pa.float64() for label in labels):
        batches = pf.iter_batches(batch_size=min(chunk_rows, STREAM_BATCH_ROWS), columns=labels)
        stream = _filled(batches, labels, chunk_rows, pf.metadata.num_rows)
    else:
        batches = pf.iter_batches(batch_size=min(chunk_rows, 1 << 20), columns=labels)
        stream = rechunk(batches, chunk_rows)
    start = 0
    while True:
        try:
            table = next(stream)
        except StopIteration:
            _check_values(crcs, found, path)
            return
        except (pa.ArrowException, OSError, UnicodeError) as exc:
            raise DataError(f"cannot read Parquet data ({one_line(exc)})", file=path) from None
        if isinstance(table, _Filled):
            columns = table.checked(labels, path, start)
        else:
            columns = _to_float(table, labels, path, start)
        found = {label: _crc(columns[label], found[label]) for label in labels}
        rows = len(columns[labels[0]])
        del table
        yield start, columns
        del columns  # not held while the next chunk is read
        start += rows


#: Rows per record batch when streaming float64 columns into chunks: small, so the Arrow
#: buffers held at once stay a few MB whatever the chunk size.
STREAM_BATCH_ROWS = 1 << 16


class _Filled(dict):
    """A chunk of float64 columns filled batch by batch (label -> array), with the first null
    row of each column that had one (``nulls``), checked by :meth:`checked`."""

    def __init__(self, columns: dict[str, np.ndarray], nulls: dict[str, int]) -> None:
        super().__init__(columns)
        self.nulls = nulls

    def checked(self, labels: list[str], path: Path, first: int) -> dict[str, np.ndarray]:
        """The columns, checked as :func:`_to_float` checks a table: column by column, a
        null first, then a non-finite value (``first``: 0-based index of the first record)."""
        for label in labels:
            if label in self.nulls:
                row = first + self.nulls[label]
                raise DataError("missing (null) value", file=path, row=row, column=label)
            values = self[label]
            if not np.isfinite(values).all():
                row = int(np.flatnonzero(~np.isfinite(values))[0])
                raise DataError(
                    f"non-finite value {float(values[row])!r} (NaN and infinities are not data)",
                    file=path,
                    row=first + row,
                    column=label,
                )
        return dict(self)


def _filled(
    batches: Iterable[pa.RecordBatch], labels: list[str], rows: int, total: int
) -> Iterator[_Filled]:
    """Float64 record batches (``total`` rows in all) copied into chunks of ``rows`` rows (the
    last may be shorter): one fresh array per column and chunk, filled from small batches, so
    no chunk-sized Arrow table is built next to it."""
    chunk: dict[str, np.ndarray] = {}
    nulls: dict[str, int] = {}
    held = size = done = 0
    for batch in batches:
        offset = 0
        while offset < batch.num_rows:
            if not chunk:
                size = max(min(rows, total - done), 1)
                chunk = {label: np.empty(size) for label in labels}
            take = min(size - held, batch.num_rows - offset)
            for label in labels:
                col = batch.column(label).slice(offset, take)
                if col.null_count and label not in nulls:
                    mask = col.is_null().to_numpy(zero_copy_only=False)
                    nulls[label] = held + int(np.flatnonzero(mask)[0])
                chunk[label][held : held + take] = col.to_numpy(zero_copy_only=False)
            held += take
            offset += take
            if held == size:
                yield _Filled(chunk, nulls)
                done += held
                chunk, nulls, held = {}, {}, 0
    if held:  # fewer rows than the file's metadata counts (checked by the integrity record)
        yield _Filled({label: values[:held] for label, values in chunk.items()}, nulls)


# --------------------------------------------------------------------------- writing


def parquet_doc(
    fmt: str,
    units: Mapping[str, str],
    source: str | None,
    joint: str | None,
    torque_constant: float | None,
    meta: Mapping[str, Any],
) -> bytes:
    """fricid's metadata document for the schema of a Parquet file.

    Parameters
    ----------
    fmt : str
        The format tag, e.g. ``"fricid-samples/1"``.
    units : mapping of str to str
        Column -> unit.
    source, joint : str or None
        Recorded when given.
    torque_constant : float or None
        K [N m/A], recorded with its unit when given.
    meta : mapping
        Free-form metadata (JSON-serialisable).

    Returns
    -------
    bytes
        ASCII JSON, stored under :data:`META_KEY`.
    """
    doc: dict[str, Any] = {"format": fmt, "units": dict(units), "integrity": CHECK_KEY.decode()}
    if torque_constant is not None:
        doc["units"]["torque_constant"] = SI_UNITS["torque_constant"]
        doc["torque_constant"] = float(torque_constant)
    if source is not None:
        doc["source"] = str(source)
    if joint is not None:
        doc["joint"] = str(joint)
    doc["meta"] = json.loads(dumps_meta(meta))
    return json.dumps(doc, ensure_ascii=True).encode("ascii")


def write_parquet(path: Path, doc: bytes, tables: Iterable[pa.Table]) -> None:
    """Write a Parquet file atomically, table by table.

    Parameters
    ----------
    path : pathlib.Path
        The file; nothing is left there if writing fails part-way.
    doc : bytes
        The metadata document (:func:`parquet_doc`).
    tables : iterable of pyarrow.Table
        The rows, in order, all with the same schema; streamed, in row groups of at most
        :data:`ROW_GROUP_ROWS` rows. Pages are written with their checksums, and fricid's
        integrity record (:data:`CHECK_KEY`) is added at the end.
    """
    with atomic_path(path) as tmp:
        writer = None
        crcs: dict[str, int] = {}
        rows = 0
        try:
            for table in tables:
                if writer is None:
                    schema = table.schema.with_metadata({META_KEY: doc})
                    writer = pq.ParquetWriter(tmp, schema, write_page_checksum=True)
                    crcs = dict.fromkeys(table.schema.names, 0)
                writer.write_table(table, row_group_size=ROW_GROUP_ROWS)
                for name in crcs:
                    values = table.column(name).cast(pa.float64()).to_numpy(zero_copy_only=False)
                    crcs[name] = _crc(values, crcs[name])
                rows += table.num_rows
            if writer is not None:
                record = {"rows": rows, "doc_crc32": zlib.crc32(doc), "crc32": crcs}
                writer.add_key_value_metadata({CHECK_KEY: json.dumps(record).encode("ascii")})
        finally:
            if writer is not None:
                writer.close()
