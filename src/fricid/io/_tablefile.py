"""Opening a fricid table file for reading: format by suffix, format tag, metadata, columns.

Shared by the readers of :mod:`fricid.io.tables`: :func:`open_table` checks a CSV or Parquet
file against a column schema and returns an :class:`Opened` with the columns resolved, the
metadata decoded and the data accessors; :func:`relocate` puts the file's row and column
into a validation error of the data types.
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ..units import SI_UNITS, to_si
from ._columns import Column, check_unit, resolve_columns
from ._csv import iter_numeric, read_numeric, read_preamble, record_line
from ._meta import decode_text, loads_meta
from ._parquet import iter_columns, open_parquet, read_columns, schema_meta

__all__ = ["Info", "Opened", "meta_of", "open_table", "relocate", "table_format"]

PathLike = str | os.PathLike[str]


def table_format(path: PathLike) -> str:
    """``"csv"`` or ``"parquet"`` from the suffix; a ConfigError for any other suffix."""
    suffix = Path(path).suffix.lower()
    if suffix == ".csv":
        return "csv"
    if suffix in (".parquet", ".pq"):
        return "parquet"
    raise ConfigError(
        f"cannot tell the file format of '{path}' from its suffix '{suffix}'; "
        "use one of: .csv, .parquet, .pq"
    )


@dataclass
class Info:
    """Metadata found in a file."""

    format: str | None = None
    source: str | None = None
    joint: str | None = None
    torque_constant: float | None = None
    meta: dict[str, Any] = field(default_factory=dict)


@dataclass
class Opened:
    """A table file opened for reading: resolved columns, metadata and data accessors."""

    path: Path
    columns: dict[str, Column]
    info: Info
    read_all: Callable[[], dict[str, np.ndarray]]
    iterate: Callable[[int], Iterator[tuple[int, dict[str, np.ndarray]]]]
    to_row: Callable[[int], int | None]  # record index -> row number for messages

    def si(self, raw: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """File columns (keyed by label) to SI arrays keyed by column name."""
        return {name: col.to_si(raw[col.label]) for name, col in self.columns.items()}


def _csv_info(comments: dict[str, tuple[str | None, str]], path: Path) -> Info:
    """The metadata of a CSV file's ``# key: value`` lines (torque constant in SI)."""
    info = Info()
    for key in ("format", "source", "joint"):
        if key in comments:
            setattr(info, key, decode_text(comments[key][1], file=path, key=key))
    if "torque_constant" in comments:
        unit, text = comments["torque_constant"]
        unit = unit or SI_UNITS["torque_constant"]
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


def _parquet_info(doc: dict[str, Any], path: Path) -> Info:
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
    info = Info(format=doc.get("format"), source=doc.get("source"), joint=doc.get("joint"))
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
    """A DataError if the file's format tag is another kind or version (the reader named)."""
    if found is None or found == expected:
        return
    kind = found.split("/")[0]
    if kind == expected.split("/")[0]:
        raise DataError(
            f"file format '{found}' is not supported by this fricid (reads '{expected}')",
            file=path,
        )
    what = {
        "fricid-samples": "friction samples: fricid fit, evaluate and report take them "
        "(Python: read_samples)",
        "fricid-rawlog": "a raw log: fricid extract, or fricid fit --trajectory, takes it "
        "(Python: read_rawlog)",
    }.get(kind, "read by another command")
    raise DataError(f"this is a '{found}' file, not '{expected}': {what}", file=path)


def open_table(
    path: PathLike, schema: dict[str, str | None], required: tuple[str, ...], expected: str
) -> Opened:
    """Open a table file, check its format tag, resolve its columns against ``schema``."""
    path = Path(path)
    if table_format(path) == "csv":
        pre = read_preamble(path)
        info = _csv_info(pre.comments, path)
        _check_format(info.format, expected, path)
        columns = resolve_columns(pre.labels, schema, required, file=path)
        labels = [c.label for c in columns.values()]
        return Opened(
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
    units = doc.get("units")
    columns = resolve_columns(
        pf.schema_arrow.names,
        schema,
        required,
        file=path,
        units=units if isinstance(units, dict) else None,
    )
    labels = [c.label for c in columns.values()]
    return Opened(
        path,
        columns,
        info,
        read_all=lambda: read_columns(pf, labels, path),
        iterate=lambda n: iter_columns(pf, labels, path, n),
        to_row=lambda record: record,
    )


def meta_of(info: Info, path: Path) -> dict[str, Any]:
    """The file's meta, plus the source recorded in it (``recorded_source``) when that is not
    the file itself: a reader's ``source`` is the file read, which messages must name."""
    meta = dict(info.meta)  # one copy per chunk
    if info.source is not None and info.source != str(path):
        meta["recorded_source"] = info.source
    return meta


def relocate(err: DataError, opened: Opened, first_record: int) -> DataError:
    """Re-issue a validation error of the data types with this file's row and column."""
    row = None if err.row is None else opened.to_row(first_record + err.row)
    col = opened.columns.get(err.column) if err.column else None
    column = col.label if col is not None else err.column
    return DataError(err.message, file=opened.path, row=row, column=column)
