"""Parquet machinery shared by the readers and writers: schema metadata, column reads, batch
streaming, streamed atomic writing."""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from ..errors import DataError
from ..units import SI_UNITS
from ._csv import one_line, rechunk
from ._meta import dumps_meta
from .atomic import atomic_path

__all__ = [
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
    FileNotFoundError
        No such file.
    DataError
        A damaged or truncated file.
    """
    try:
        # no pre-buffering: it reads ahead whole row groups, unbounded for iter_batches
        return pq.ParquetFile(path, pre_buffer=False)
    except (pa.ArrowException, OSError, UnicodeError) as exc:
        if isinstance(exc, FileNotFoundError):
            raise
        raise DataError(f"not a readable Parquet file ({one_line(exc)})", file=path) from None


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
                f"non-finite value {values[row]!r} (NaN and infinities are not data)",
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
    try:
        table = pf.read(columns=labels)
    except (pa.ArrowException, OSError, UnicodeError) as exc:
        raise DataError(f"cannot read Parquet data ({one_line(exc)})", file=path) from None
    return _to_float(table, labels, path, 0)


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
        As :func:`read_columns`.
    """
    batches = pf.iter_batches(batch_size=min(chunk_rows, 1 << 20), columns=labels)
    stream = rechunk(batches, chunk_rows)
    start = 0
    while True:
        try:
            table = next(stream)
        except StopIteration:
            return
        except (pa.ArrowException, OSError, UnicodeError) as exc:
            raise DataError(f"cannot read Parquet data ({one_line(exc)})", file=path) from None
        yield start, _to_float(table, labels, path, start)
        start += table.num_rows


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
    doc: dict[str, Any] = {"format": fmt, "units": dict(units)}
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
        :data:`ROW_GROUP_ROWS` rows.
    """
    with atomic_path(path) as tmp:
        writer = None
        try:
            for table in tables:
                if writer is None:
                    schema = table.schema.with_metadata({META_KEY: doc})
                    writer = pq.ParquetWriter(tmp, schema)
                writer.write_table(table, row_group_size=ROW_GROUP_ROWS)
        finally:
            if writer is not None:
                writer.close()
