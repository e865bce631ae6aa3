"""Streaming Parquet float64 columns batch by batch into chunks gives what reading each chunk
as one table gives: the same values, and the same error (message, row, column) for a null or
a non-finite value, wherever it falls among the batches."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from fricid.errors import DataError
from fricid.io import _parquet
from fricid.io._csv import rechunk

LABELS = ["a", "b", "c"]


def _write(path: Path, rows: int, nulls: dict[str, int], bad: dict[str, float]) -> Path:
    """A float64 table of ``rows`` rows; ``nulls``: label -> row of a null; ``bad``: label ->
    row of a non-finite value (the row is the key's value, the value NaN or inf)."""
    columns = {}
    for j, label in enumerate(LABELS):
        values = np.arange(rows, dtype=float) + 0.25 * j
        mask = np.zeros(rows, dtype=bool)
        if label in nulls:
            mask[nulls[label]] = True
        if label in bad:
            values[int(bad[label])] = np.inf if j % 2 else np.nan
        columns[label] = pa.array(values, type=pa.float64(), mask=mask)
    pq.write_table(pa.table(columns), path, row_group_size=13)
    return path


def _table_by_table(path: Path, chunk_rows: int) -> list:
    """Each chunk read as one Arrow table (the reference)."""
    pf = pq.ParquetFile(path)
    out, start = [], 0
    for table in rechunk(pf.iter_batches(batch_size=5, columns=LABELS), chunk_rows):
        out.append((start, _parquet._to_float(table, LABELS, path, start)))
        start += table.num_rows
    return out


def _outcome(read):
    try:
        return "ok", [(s, {k: v.tolist() for k, v in c.items()}) for s, c in read()]
    except DataError as err:
        return "error", (err.message, err.row, err.column)


CASES = [
    ({}, {}),
    ({"b": 40}, {}),
    ({"c": 3}, {"a": 30}),  # a null in a later column, a NaN in an earlier one, one chunk
    ({"a": 33, "c": 31}, {}),
    ({}, {"b": 58, "c": 57}),
    ({"b": 12}, {"a": 45}),  # different chunks: the first chunk's error
]


@pytest.mark.parametrize("chunk_rows", [7, 25, 60, 1000])
@pytest.mark.parametrize(("nulls", "bad"), CASES)
def test_batches_filled_into_chunks_read_as_whole_tables(
    tmp_path, monkeypatch, chunk_rows, nulls, bad
):
    path = _write(tmp_path / "t.parquet", 60, nulls, bad)
    monkeypatch.setattr(_parquet, "STREAM_BATCH_ROWS", 4)  # many batches per chunk

    def streamed():
        pf = pq.ParquetFile(path)
        return list(_parquet.iter_columns(pf, LABELS, path, chunk_rows))

    def reference():
        return _table_by_table(path, chunk_rows)

    assert _outcome(streamed) == _outcome(reference)
