"""Read and write :class:`~fricid.samples.FrictionSamples` and :class:`~fricid.samples.RawLog`.

The format follows the file suffix: ``.csv``, or ``.parquet`` / ``.pq``.

CSV
    Leading ``# key: value`` comment lines carry the metadata (``format``, ``source``,
    ``joint``, ``torque_constant [N m/A]``, free-form ``meta`` as JSON); the header names
    carry the units, e.g. ``velocity [rad/s],load [N m],temperature [degC],friction [N m],
    direction,count,std [N m]``. On reading, columns may come in any order and in any known
    unit (``[deg/s]``, ``[mNm]``, ...), converted to SI; unknown columns are ignored.
Parquet
    Columns in SI; units and metadata in the schema metadata under the key ``fricid`` (JSON).

Every bad input is a :class:`~fricid.errors.DataError` naming the file, the row (the 1-based
line number in a CSV, the 0-based record in Parquet) and the column. Writes are atomic.
"""

from __future__ import annotations

import contextlib
import itertools
import json
import math
import os
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from ..errors import ConfigError, DataError
from ..samples import RAWLOG_COLUMNS, SAMPLE_COLUMNS, FrictionSamples, RawLog
from ..units import SI_UNITS, to_si
from ._columns import Column, check_unit, resolve_columns
from ._csv import iter_numeric, read_numeric, read_preamble, record_line
from ._meta import decode_text, dumps_meta, encode_text, loads_meta
from ._parquet import META_KEY, iter_columns, open_parquet, read_columns, schema_meta
from .atomic import atomic_path, atomic_write

__all__ = ["iter_rawlog", "read_rawlog", "read_samples", "write_rawlog", "write_samples"]

PathLike = str | os.PathLike[str]

#: Format tags written to every file (CSV ``# format:`` line, Parquet metadata).
SAMPLES_FORMAT = "fricid-samples/1"
RAWLOG_FORMAT = "fricid-rawlog/1"

#: Largest Parquet row group written: bounds the memory :func:`iter_rawlog` needs per group
#: (5 float64 columns x 256 Ki rows = 10 MB).
ROW_GROUP_ROWS = 1 << 18

# column -> physical quantity for unit conversion (None: dimensionless)
_SAMPLES_SCHEMA: dict[str, str | None] = {
    "velocity": "velocity",
    "load": "torque",
    "temperature": "temperature",
    "friction": "torque",
    "direction": None,
    "count": None,
    "std": "torque",
}
_SAMPLES_REQUIRED = ("velocity", "load", "temperature", "friction")
_RAWLOG_SCHEMA: dict[str, str | None] = {name: name for name in RAWLOG_COLUMNS}
_RAWLOG_REQUIRED = ("time", "position", "velocity", "temperature")


def _format(path: PathLike) -> str:
    suffix = Path(path).suffix.lower()
    if suffix == ".csv":
        return "csv"
    if suffix in (".parquet", ".pq"):
        return "parquet"
    raise ConfigError(
        f"cannot tell the file format of '{path}' from its suffix '{suffix}'; "
        "use one of: .csv, .parquet, .pq"
    )


# --------------------------------------------------------------------------- reading


@dataclass
class _Info:
    """Metadata found in a file."""

    format: str | None = None
    source: str | None = None
    joint: str | None = None
    torque_constant: float | None = None
    meta: dict[str, Any] = field(default_factory=dict)


@dataclass
class _Opened:
    """A table file opened for reading: resolved columns, metadata and data accessors."""

    path: Path
    columns: dict[str, Column]
    info: _Info
    read_all: Callable[[], dict[str, np.ndarray]]
    iterate: Callable[[int], Iterator[tuple[int, dict[str, np.ndarray]]]]
    to_row: Callable[[int], int | None]  # record index -> row number for messages

    def si(self, raw: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """File columns (keyed by label) to SI arrays keyed by column name."""
        return {name: col.to_si(raw[col.label]) for name, col in self.columns.items()}


def _csv_info(comments: dict[str, tuple[str | None, str]], path: Path) -> _Info:
    info = _Info()
    for key in ("format", "source", "joint"):
        if key in comments:
            setattr(info, key, decode_text(comments[key][1], file=path, key=key))
    if "torque_constant" in comments:
        unit, text = comments["torque_constant"]
        unit = unit or SI_UNITS["torque_constant"]
        check_unit(unit, "torque_constant", file=path, column="torque_constant")
        info.torque_constant = _torque_constant(text, unit, path)
    if "meta" in comments:
        info.meta = loads_meta(comments["meta"][1], file=path)
    return info


def _torque_constant(value: Any, unit: str, path: Path) -> float:
    """K [N m/A] from file metadata: a finite, positive number in a known unit."""
    check_unit(unit, "torque_constant", file=path, column="torque_constant")
    number = None
    if isinstance(value, str):
        with contextlib.suppress(ValueError):
            number = float(value)
    elif isinstance(value, int | float) and not isinstance(value, bool):
        number = float(value)
    if number is None or not math.isfinite(number) or number <= 0:
        raise DataError(
            f"metadata 'torque_constant' must be a positive number [{unit}], got {value!r}",
            file=path,
        )
    return float(to_si(number, unit, "torque_constant"))


def _parquet_info(doc: dict[str, Any], path: Path) -> _Info:
    for key in ("format", "source", "joint"):
        if not isinstance(doc.get(key, ""), str):
            raise DataError(
                f"schema metadata '{key}' must be a string, got {doc[key]!r}", file=path
            )
    units = doc.get("units", {})
    if not isinstance(units, dict) or not all(isinstance(u, str) for u in units.values()):
        raise DataError(
            f"schema metadata 'units' must map column names to unit strings, got {units!r}",
            file=path,
        )
    info = _Info(format=doc.get("format"), source=doc.get("source"), joint=doc.get("joint"))
    k = doc.get("torque_constant")
    if k is not None:
        unit = units.get("torque_constant", SI_UNITS["torque_constant"])
        info.torque_constant = _torque_constant(k, unit, path)
    meta = doc.get("meta", {})
    if not isinstance(meta, dict):
        raise DataError(f"metadata 'meta' must be a JSON object, got {meta!r}", file=path)
    info.meta = meta
    return info


def _check_format(found: str | None, expected: str, path: Path) -> None:
    if found is None or found == expected:
        return
    kind = found.split("/")[0]
    if kind == expected.split("/")[0]:
        raise DataError(
            f"file format '{found}' is not supported by this fricid (reads '{expected}')",
            file=path,
        )
    reader = {"fricid-samples": "read_samples", "fricid-rawlog": "read_rawlog"}.get(
        kind, "another reader"
    )
    raise DataError(f"this is a '{found}' file, not '{expected}'; read it with {reader}", file=path)


def _open(
    path: PathLike, schema: dict[str, str | None], required: tuple[str, ...], expected: str
) -> _Opened:
    """Open a table file, check its format tag, resolve its columns against ``schema``."""
    path = Path(path)
    if _format(path) == "csv":
        pre = read_preamble(path)
        info = _csv_info(pre.comments, path)
        _check_format(info.format, expected, path)
        columns = resolve_columns(pre.labels, schema, required, file=path)
        labels = [c.label for c in columns.values()]
        return _Opened(
            path,
            columns,
            info,
            read_all=lambda: read_numeric(pre, labels),
            iterate=lambda n: iter_numeric(pre, labels, n),
            to_row=lambda record: record_line(pre, record),
        )
    pf = open_parquet(path)
    doc = schema_meta(pf, path)
    info = _parquet_info(doc, path)
    _check_format(info.format, expected, path)
    columns = resolve_columns(
        pf.schema_arrow.names, schema, required, file=path, units=doc.get("units")
    )
    labels = [c.label for c in columns.values()]
    return _Opened(
        path,
        columns,
        info,
        read_all=lambda: read_columns(pf, labels, path),
        iterate=lambda n: iter_columns(pf, labels, path, n),
        to_row=lambda record: record,
    )


def _meta(info: _Info, path: Path) -> dict[str, Any]:
    """The file's meta, plus the source recorded in it (``recorded_source``) when that is not
    the file itself: ``source`` is the file read, which messages must name (issue 12)."""
    meta = dict(info.meta)  # one copy per chunk
    if info.source is not None and info.source != str(path):
        meta["recorded_source"] = info.source
    return meta


def _relocate(err: DataError, opened: _Opened, first_record: int) -> DataError:
    """Re-issue a validation error of the data types with this file's row and column."""
    row = None if err.row is None else opened.to_row(first_record + err.row)
    col = opened.columns.get(err.column) if err.column else None
    column = col.label if col is not None else err.column
    return DataError(err.message, file=opened.path, row=row, column=column)


def read_samples(path: PathLike) -> FrictionSamples:
    """Read friction samples from a CSV or Parquet file.

    Parameters
    ----------
    path : ``.csv``, ``.parquet`` or ``.pq`` file written by :func:`write_samples`, or any
        table with the columns velocity, load, temperature, friction (and optionally
        direction, count, std) and explicit units.

    Returns
    -------
    FrictionSamples
        In SI units. ``source`` is ``path``; a different source recorded in the file is
        kept as ``meta["recorded_source"]``.
    """
    opened = _open(path, _SAMPLES_SCHEMA, _SAMPLES_REQUIRED, SAMPLES_FORMAT)
    cols = opened.si(opened.read_all())
    count = cols.get("count")
    if count is not None and (count != np.round(count)).any():
        row = int(np.flatnonzero(count != np.round(count))[0])
        raise _relocate(
            DataError(f"count must be a whole number, got {count[row]!r}", row=row, column="count"),
            opened,
            0,
        )
    info = opened.info
    try:
        return FrictionSamples(**cols, source=str(opened.path), meta=_meta(info, opened.path))
    except DataError as err:
        raise _relocate(err, opened, 0) from None


def _open_rawlog(path: PathLike) -> _Opened:
    opened = _open(path, _RAWLOG_SCHEMA, _RAWLOG_REQUIRED, RAWLOG_FORMAT)
    if "torque" not in opened.columns and "current" not in opened.columns:
        raise DataError(
            "missing required column 'torque' (e.g. 'torque [N m]') or 'current' "
            "(e.g. 'current [A]', with a torque constant)",
            file=opened.path,
            column="torque",
        )
    return opened


def _rawlog(opened: _Opened, cols: dict[str, np.ndarray], first_record: int) -> RawLog:
    info = opened.info
    try:
        return RawLog(
            time=cols["time"],
            position=cols["position"],
            velocity=cols["velocity"],
            temperature=cols["temperature"],
            torque=cols.get("torque"),
            current=cols.get("current"),
            torque_constant=info.torque_constant,
            joint=info.joint if info.joint is not None else "joint",
            source=str(opened.path),
            meta=_meta(info, opened.path),
        )
    except DataError as err:
        raise _relocate(err, opened, first_record) from None


def read_rawlog(path: PathLike) -> RawLog:
    """Read a whole raw joint log from a CSV or Parquet file (SI units).

    For files too large for memory, use :func:`iter_rawlog`. A file with no data rows is a
    :class:`~fricid.errors.DataError`.
    """
    opened = _open_rawlog(path)
    log = _rawlog(opened, opened.si(opened.read_all()), 0)
    if len(log) == 0:
        raise DataError("no data rows after the header", file=opened.path)
    return log


def iter_rawlog(path: PathLike, chunk_rows: int = 1_000_000) -> Iterator[RawLog]:
    """Read a raw log in chunks of ``chunk_rows`` rows (the last may be shorter).

    Memory stays bounded by a few chunks whatever the file size: Parquet is read batch by
    batch (one row group at a time), CSV block by block. The chunks concatenate to
    :func:`read_rawlog`'s log; time must also increase across chunk boundaries. The file is
    opened and its columns checked at the call; data errors surface at the chunk holding them.
    """
    if isinstance(chunk_rows, bool) or not isinstance(chunk_rows, int | np.integer):
        raise ConfigError(f"chunk_rows must be a positive integer, got {chunk_rows!r}")
    if chunk_rows < 1:
        raise ConfigError(f"chunk_rows must be a positive integer, got {chunk_rows!r}")
    return _iter_rawlog(_open_rawlog(path), int(chunk_rows))


def _iter_rawlog(opened: _Opened, chunk_rows: int) -> Iterator[RawLog]:
    last_time: float | None = None
    for start, raw in opened.iterate(chunk_rows):
        log = _rawlog(opened, opened.si(raw), start)
        if last_time is not None and log.time[0] <= last_time:
            raise DataError(
                f"time is not strictly increasing ({last_time!r} then {log.time[0]!r})",
                file=opened.path,
                row=opened.to_row(start),
                column=opened.columns["time"].label,
            )
        last_time = float(log.time[-1])
        yield log
    if last_time is None:
        raise DataError("no data rows after the header", file=opened.path)


# --------------------------------------------------------------------------- writing


def _label(name: str, unit: str) -> str:
    return name if unit == "1" else f"{name} [{unit}]"


def _csv_preamble(fields: list[tuple[str, str]], units: dict[str, str]) -> bytes:
    lines = [f"# {key}: {value}" for key, value in fields]
    lines.append(",".join(_label(name, unit) for name, unit in units.items()))
    return ("\n".join(lines) + "\n").encode("utf-8")


def _info_fields(fmt: str, source: str | None, joint: str | None, k: float | None, meta) -> list:
    fields = [("format", fmt)]
    if source is not None:
        fields.append(("source", encode_text(str(source))))
    if joint is not None:
        fields.append(("joint", encode_text(str(joint))))
    if k is not None:
        fields.append((f"torque_constant [{SI_UNITS['torque_constant']}]", repr(float(k))))
    fields.append(("meta", dumps_meta(meta)))
    return fields


def _parquet_doc(fmt: str, units: dict[str, str], source, joint, k, meta) -> bytes:
    doc: dict[str, Any] = {"format": fmt, "units": dict(units)}
    if k is not None:
        doc["units"]["torque_constant"] = SI_UNITS["torque_constant"]
        doc["torque_constant"] = float(k)
    if source is not None:
        doc["source"] = str(source)
    if joint is not None:
        doc["joint"] = str(joint)
    doc["meta"] = json.loads(dumps_meta(meta))
    return json.dumps(doc, ensure_ascii=True).encode("ascii")


def _write_csv(path: Path, preamble: bytes, tables: Iterable[pa.Table]) -> None:
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


def _write_parquet(path: Path, doc: bytes, tables: Iterable[pa.Table]) -> None:
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


def write_samples(samples: FrictionSamples, path: PathLike) -> Path:
    """Write friction samples to ``path`` (CSV or Parquet by suffix), atomically.

    Returns the path written. Units are SI and stated in the file.
    """
    if not isinstance(samples, FrictionSamples):
        raise ConfigError(
            f"write_samples(samples, path) needs a FrictionSamples, got {type(samples).__name__}"
        )
    path = Path(path)
    fmt = _format(path)
    table = pa.table({name: np.asarray(getattr(samples, name)) for name in SAMPLE_COLUMNS})
    if fmt == "csv":
        fields = _info_fields(SAMPLES_FORMAT, samples.source, None, None, samples.meta)
        _write_csv(path, _csv_preamble(fields, SAMPLE_COLUMNS), [table])
    else:
        doc = _parquet_doc(SAMPLES_FORMAT, SAMPLE_COLUMNS, samples.source, None, None, samples.meta)
        _write_parquet(path, doc, [table])
    return path


def _rawlog_units(log: RawLog) -> dict[str, str]:
    return {
        name: unit
        for name, unit in RAWLOG_COLUMNS.items()
        if name not in ("torque", "current") or getattr(log, name) is not None
    }


def _rawlog_tables(first: RawLog, chunks: Iterator[RawLog]) -> Iterator[pa.Table]:
    """Check each chunk against the first and turn it into a table."""
    units = _rawlog_units(first)
    last_time: float | None = None
    for i, chunk in enumerate(itertools.chain([first], chunks)):
        if not isinstance(chunk, RawLog):
            raise ConfigError(f"chunk {i} is a {type(chunk).__name__}, not a RawLog")
        if _rawlog_units(chunk) != units:
            raise ConfigError(
                f"chunk {i} has columns {list(_rawlog_units(chunk))}, the first chunk "
                f"{list(units)}; every chunk must log the same effort (torque and/or current)"
            )
        if len(chunk) and last_time is not None and chunk.time[0] <= last_time:
            raise DataError(
                f"chunk {i} does not continue in time ({last_time!r} then {chunk.time[0]!r})",
                file=chunk.source,
                column="time",
            )
        if len(chunk):
            last_time = float(chunk.time[-1])
        yield pa.table({name: getattr(chunk, name) for name in units})


def write_rawlog(log_or_chunks: RawLog | Iterable[RawLog], path: PathLike) -> Path:
    """Write a raw log, or an iterable of consecutive chunks of one, atomically.

    Chunks are streamed: a Parquet file gets one row group per chunk (pyarrow
    ``ParquetWriter``), a CSV file grows chunk by chunk, so a log larger than memory can be
    converted with ``write_rawlog(iter_rawlog(src), dst)``. Metadata (joint, source, torque
    constant, meta) comes from the first chunk. If the chunks raise part-way, nothing is
    left at ``path``. Returns the path written.
    """
    if isinstance(log_or_chunks, str | os.PathLike):
        raise ConfigError("write_rawlog(log_or_chunks, path): the log comes first, then the path")
    path = Path(path)
    fmt = _format(path)
    chunks = iter([log_or_chunks] if isinstance(log_or_chunks, RawLog) else log_or_chunks)
    first = next(chunks, None)
    if first is None:
        raise ConfigError("write_rawlog got no chunks to write")
    if not isinstance(first, RawLog):
        raise ConfigError(f"write_rawlog needs RawLog chunks, got {type(first).__name__}")
    units = _rawlog_units(first)
    tables = _rawlog_tables(first, chunks)
    info = (first.source, first.joint, first.torque_constant, first.meta)
    if fmt == "csv":
        _write_csv(path, _csv_preamble(_info_fields(RAWLOG_FORMAT, *info), units), tables)
    else:
        _write_parquet(path, _parquet_doc(RAWLOG_FORMAT, units, *info), tables)
    return path
