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

import itertools
import os
from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np
import pyarrow as pa

from ..errors import ConfigError, DataError
from ..samples import (
    OPTIONAL_INPUTS,
    RAWLOG_COLUMNS,
    SAMPLE_COLUMNS,
    FrictionSamples,
    RawLog,
    drop_standstill,
)
from ._csv import csv_preamble, preamble_fields, write_csv
from ._parquet import parquet_doc, write_parquet
from ._tablefile import Opened, meta_of, open_table, relocate, table_format

__all__ = ["iter_rawlog", "read_rawlog", "read_samples", "write_rawlog", "write_samples"]

PathLike = str | os.PathLike[str]

#: Format tags written to every file (CSV ``# format:`` line, Parquet metadata).
SAMPLES_FORMAT = "fricid-samples/1"
RAWLOG_FORMAT = "fricid-rawlog/1"

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
_SAMPLES_REQUIRED = ("velocity", "friction")  # load, temperature: absent is not measured
_RAWLOG_SCHEMA: dict[str, str | None] = {name: name for name in RAWLOG_COLUMNS}
_RAWLOG_REQUIRED = ("time", "position", "velocity")  # and temperature, or its constant


# --------------------------------------------------------------------------- reading


def read_samples(path: PathLike) -> FrictionSamples:
    """Read friction samples from a CSV or Parquet file.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.csv``, ``.parquet`` or ``.pq`` file written by :func:`write_samples`, or any
        table with the columns velocity and friction (and optionally load, temperature,
        direction, count, std) and explicit units. A table without load or temperature
        gives samples that did not measure it (all NaN, see
        :attr:`FrictionSamples.measured <fricid.samples.FrictionSamples.measured>`).

    Returns
    -------
    FrictionSamples
        In SI units. ``source`` is ``path``; a different source recorded in the file is
        kept as ``meta["recorded_source"]``. Standstill rows (a per-direction mean at a speed
        far below every other, :func:`fricid.samples.drop_standstill`) are dropped with a
        :class:`~fricid.errors.DataQualityWarning` naming them (``meta["dropped_standstill"]``).

    Raises
    ------
    ConfigError
        A suffix other than ``.csv``, ``.parquet``, ``.pq``.
    DataError
        A missing column or unit, an unknown unit, a non-numeric or non-finite value, a
        fractional count, a file of another format (file, row and column named).

    See Also
    --------
    write_samples : the inverse.

    Examples
    --------
    >>> samples = read_samples("samples.csv")  # doctest: +SKIP
    >>> samples.X.shape  # doctest: +SKIP
    (60, 3)
    """
    opened = open_table(path, _SAMPLES_SCHEMA, _SAMPLES_REQUIRED, SAMPLES_FORMAT)
    cols = opened.si(opened.read_all())
    count = cols.get("count")
    if count is not None and (count != np.round(count)).any():
        row = int(np.flatnonzero(count != np.round(count))[0])
        raise relocate(
            DataError(
                f"count must be a whole number, got {float(count[row])!r}", row=row, column="count"
            ),
            opened,
            0,
        )
    info = opened.info
    for name in OPTIONAL_INPUTS:
        cols.setdefault(name, None)
    try:
        samples = FrictionSamples(**cols, source=str(opened.path), meta=meta_of(info, opened.path))
    except DataError as err:
        raise relocate(err, opened, 0) from None
    return drop_standstill(samples, stacklevel=2)


def _open_rawlog(path: PathLike, temperature: float | None = None) -> Opened:
    """Open a raw-log table; a DataError if it has neither a torque nor a current column, or
    no temperature column and no constant ``temperature`` given (a ConfigError if both)."""
    opened = open_table(path, _RAWLOG_SCHEMA, _RAWLOG_REQUIRED, RAWLOG_FORMAT)
    has = "temperature" in opened.columns
    if has and temperature is not None:
        raise ConfigError(
            f"{opened.path} has a temperature column; the temperature option is for a log "
            "without one"
        )
    if not has and temperature is None:
        raise DataError(
            "missing required column 'temperature' (e.g. 'temperature [degC]'); a log without "
            "one: give its constant temperature [degC] (fricid extract --temperature 25; fricid "
            "fit --trajectory and fricid report: --reader-option temperature=25; Python: "
            "temperature=25.0)",
            file=opened.path,
            column="temperature",
        )
    if "torque" not in opened.columns and "current" not in opened.columns:
        raise DataError(
            "missing required column 'torque' (e.g. 'torque [N m]') or 'current' "
            "(e.g. 'current [A]', with a torque constant)",
            file=opened.path,
            column="torque",
        )
    return opened


def _rawlog(
    opened: Opened, cols: dict[str, np.ndarray], first_record: int, temperature=None
) -> RawLog:
    """A :class:`RawLog` of SI columns (``temperature`` where the file has none); its
    validation errors located in the file."""
    info = opened.info
    try:
        return RawLog(
            time=cols["time"],
            position=cols["position"],
            velocity=cols["velocity"],
            temperature=cols.get("temperature", temperature),
            torque=cols.get("torque"),
            current=cols.get("current"),
            torque_constant=info.torque_constant,
            joint=info.joint if info.joint is not None else "joint",
            source=str(opened.path),
            meta=meta_of(info, opened.path),
        )
    except DataError as err:
        raise relocate(err, opened, first_record) from None


def read_rawlog(path: PathLike, *, temperature: float | None = None) -> RawLog:
    """Read a whole raw joint log from a CSV or Parquet file.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.csv``, ``.parquet`` or ``.pq`` file written by :func:`write_rawlog`, or any
        table with the columns time, position, velocity, temperature and torque or current,
        with explicit units.
    temperature : float, optional
        The constant temperature [degC] of a log without a temperature column.

    Returns
    -------
    RawLog
        In SI units; joint, source, torque constant and ``meta`` as recorded in the file.

    Raises
    ------
    ConfigError
        A suffix other than ``.csv``, ``.parquet``, ``.pq``; ``temperature`` given for a
        log with a temperature column.
    DataError
        No data rows, a missing column or unit, an unknown unit, a non-numeric or
        non-finite value, time not strictly increasing (file, row and column named).

    See Also
    --------
    iter_rawlog : the same log in chunks, for files too large for memory.
    write_rawlog : the inverse.
    """
    opened = _open_rawlog(path, temperature)
    log = _rawlog(opened, opened.si(opened.read_all()), 0, temperature)
    if len(log) == 0:
        raise DataError("no data rows after the header", file=opened.path)
    return log


def iter_rawlog(
    path: PathLike, chunk_rows: int = 1_000_000, *, temperature: float | None = None
) -> Iterator[RawLog]:
    """Read a raw log in chunks.

    Memory stays bounded by a few chunks whatever the file size: Parquet is read batch by
    batch (one row group at a time), CSV block by block. The file is opened and its columns
    checked at the call; data errors surface at the chunk holding them.

    Parameters
    ----------
    path : str or os.PathLike
        A raw-log table, as for :func:`read_rawlog`.
    chunk_rows : int, default 1000000
        Rows per chunk; the last may be shorter.

    Returns
    -------
    iterator of RawLog
        The chunks; they concatenate to :func:`read_rawlog`'s log (time must also increase
        across chunk boundaries).

    Raises
    ------
    ConfigError
        ``chunk_rows`` not a positive integer; a suffix fricid cannot read.
    DataError
        As :func:`read_rawlog`, at the call for the columns, from the iterator for the data.

    Examples
    --------
    >>> n = sum(len(chunk) for chunk in iter_rawlog("log.parquet"))  # doctest: +SKIP
    """
    if isinstance(chunk_rows, bool) or not isinstance(chunk_rows, int | np.integer):
        raise ConfigError(f"chunk_rows must be a positive integer, got {chunk_rows!r}")
    if chunk_rows < 1:
        raise ConfigError(f"chunk_rows must be a positive integer, got {chunk_rows!r}")
    opened = _open_rawlog(path, temperature)
    return _iter_rawlog(opened, int(chunk_rows), temperature)


def _iter_rawlog(opened: Opened, chunk_rows: int, temperature=None) -> Iterator[RawLog]:
    """The chunks of an opened raw log, time checked across their boundaries."""
    last_time: float | None = None
    for start, raw in opened.iterate(chunk_rows):
        log = _rawlog(opened, opened.si(raw), start, temperature)
        if last_time is not None and log.time[0] <= last_time:
            raise DataError(
                "time is not strictly increasing "
                f"({float(last_time)!r} then {float(log.time[0])!r})",
                file=opened.path,
                row=opened.to_row(start),
                column=opened.columns["time"].label,
            )
        last_time = float(log.time[-1])
        del raw
        yield log
        del log  # not held while the next chunk is read
    if last_time is None:
        raise DataError("no data rows after the header", file=opened.path)


# --------------------------------------------------------------------------- writing


def write_samples(samples: FrictionSamples, path: PathLike) -> Path:
    """Write friction samples to a CSV or Parquet file, atomically.

    Parameters
    ----------
    samples : FrictionSamples
        The samples.
    path : str or os.PathLike
        The file; ``.csv`` or ``.parquet`` / ``.pq`` chooses the format.

    Returns
    -------
    pathlib.Path
        The path written. Units are SI and stated in the file (CSV header, Parquet schema
        metadata), with the source and ``meta``. An input not measured (load, temperature)
        is left out.

    Raises
    ------
    ConfigError
        Not a :class:`FrictionSamples`, an unknown suffix, or ``meta`` that is not
        JSON-serialisable.

    See Also
    --------
    read_samples : the inverse.
    """
    if not isinstance(samples, FrictionSamples):
        raise ConfigError(
            f"write_samples(samples, path) needs a FrictionSamples, got {type(samples).__name__}"
        )
    path = Path(path)
    fmt = table_format(path)
    measured = samples.measured
    units = {k: u for k, u in SAMPLE_COLUMNS.items() if k not in OPTIONAL_INPUTS or k in measured}
    table = pa.table({name: np.asarray(getattr(samples, name)) for name in units})
    if fmt == "csv":
        fields = preamble_fields(SAMPLES_FORMAT, samples.source, None, None, samples.meta)
        write_csv(path, csv_preamble(fields, units), [table])
    else:
        doc = parquet_doc(SAMPLES_FORMAT, units, samples.source, None, None, samples.meta)
        write_parquet(path, doc, [table])
    return path


def _rawlog_units(log: RawLog) -> dict[str, str]:
    """The columns a log writes and their units (torque, current: only those present)."""
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
                f"chunk {i} does not continue in time "
                f"({float(last_time)!r} then {float(chunk.time[0])!r})",
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
    converted with ``write_rawlog(iter_rawlog(src), dst)``. If the chunks raise part-way,
    nothing is left at ``path``.

    Parameters
    ----------
    log_or_chunks : RawLog or iterable of RawLog
        The log, or its chunks in time order, all with the same effort columns. Metadata
        (joint, source, torque constant, meta) comes from the first chunk.
    path : str or os.PathLike
        The file; ``.csv`` or ``.parquet`` / ``.pq`` chooses the format.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    ConfigError
        Arguments in the wrong order, no chunks, a chunk that is not a :class:`RawLog` or
        has other columns than the first, an unknown suffix.
    DataError
        A chunk that does not continue the previous one in time.

    See Also
    --------
    read_rawlog, iter_rawlog : the inverse.
    """
    if isinstance(log_or_chunks, str | os.PathLike):
        raise ConfigError("write_rawlog(log_or_chunks, path): the log comes first, then the path")
    path = Path(path)
    fmt = table_format(path)
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
        write_csv(path, csv_preamble(preamble_fields(RAWLOG_FORMAT, *info), units), tables)
    else:
        write_parquet(path, parquet_doc(RAWLOG_FORMAT, units, *info), tables)
    return path
