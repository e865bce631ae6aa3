"""Parquet machinery shared by the readers: schema metadata, column reads, batch streaming."""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from ..errors import DataError
from ._csv import one_line, rechunk

__all__ = ["META_KEY", "iter_columns", "open_parquet", "read_columns", "schema_meta"]

#: Key of fricid's JSON document in the Parquet schema metadata.
META_KEY = b"fricid"


def open_parquet(path: str | os.PathLike[str]) -> pq.ParquetFile:
    """Open a Parquet file; a damaged or truncated file is a :class:`DataError`."""
    try:
        # no pre-buffering: it reads ahead whole row groups, unbounded for iter_batches
        return pq.ParquetFile(path, pre_buffer=False)
    except (pa.ArrowException, OSError, UnicodeError) as exc:
        if isinstance(exc, FileNotFoundError):
            raise
        raise DataError(f"not a readable Parquet file ({one_line(exc)})", file=path) from None


def schema_meta(pf: pq.ParquetFile, path: str | os.PathLike[str]) -> dict[str, Any]:
    """fricid's metadata document of a Parquet file (empty when another tool wrote it)."""
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
    """All rows of ``labels`` as finite float64 arrays (rows in errors are 0-based records)."""
    try:
        table = pf.read(columns=labels)
    except (pa.ArrowException, OSError, UnicodeError) as exc:
        raise DataError(f"cannot read Parquet data ({one_line(exc)})", file=path) from None
    return _to_float(table, labels, path, 0)


def iter_columns(
    pf: pq.ParquetFile, labels: list[str], path: Path, chunk_rows: int
) -> Iterator[tuple[int, dict[str, np.ndarray]]]:
    """Stream ``(first record index, {label: array})`` chunks of ``chunk_rows`` rows."""
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
