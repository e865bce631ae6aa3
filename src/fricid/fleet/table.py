"""The fleet's results table: one row per joint and model, as a Parquet dataset and a CSV.

Columns (SI units; each parameter's unit in ``units``):

- identity: ``robot``, ``joint``, ``date`` (measurement date), ``model``;
- outcome: ``status`` (``ok`` or ``failed``), ``stage`` and ``error`` of a failure;
- inputs: ``log``, ``reader``, ``method``, ``seed``, ``input_hash`` (SHA-256 of the log),
  ``settings_hash``, ``n_samples``, ``directions``, the operating range ``speed_min``,
  ``speed_max`` [rad/s], ``load_min``, ``load_max`` [N m], ``temperature_min``,
  ``temperature_max`` [degC];
- verdict (issue 11; :func:`fricid.fleet.job.verdict_columns`): ``trust`` (``yes``,
  ``with caveats``, ``no``), ``converged``, ``heldout_ratio`` (RMSE over the measurement
  scatter), ``heldout_source`` (``lovo run here``, ``the fit's --validate``, ``the learned
  model's own CV`` or ``in-sample only``), ``heldout_scheme``, ``verdict`` (within noise, or
  misses by a factor), ``n_not_determined``, ``not_bounded`` (the parameters whose interval
  an end of the search range closes, as the verdict names them),
  ``extrapolation_free_range`` (the operating range, as text); for a whole robot's joints,
  ``reasons`` (why the verdict is not yes, as the identification gave them);
- fit: ``fitness`` (R^2), ``sse`` [N^2 m^2], ``rmse``, ``mae``, ``max_abs_error`` [N m],
  ``rmspe`` (a fraction: 0.021 is 2.1 %, as in the model file; commands and reports print
  it in percent), ``nfev``, ``at_bound``, ``fixed``, ``units``, ``model_file``;
  ``param_<name>``, ``stderr_<name>``, ``ci95_low_<name>`` and ``ci95_high_<name>`` (the
  ends of the model file's 95 % interval, empty where an end is open: the data do not bound
  the parameter on that side) and ``ci95_<name>`` (its half-width, empty where an end is
  open: a symmetric width would misstate it);
- run: ``time_extract_s``, ``time_fit_s``, ``time_total_s`` [s], ``worker``,
  ``peak_rss_mb`` [MB], ``fricid_version``.

In ``results.csv`` every column with a unit says it in its header, as every fricid table
does (``rmse [N m]``, ``speed_min [rad/s]``, ``time_fit_s [s]``; a parameter's column when
every row gives it the same unit, ``param_tau_c [N m]``): :data:`CSV_UNITS`. The Parquet
dataset keeps the bare names (its schema is the type) and :func:`read_results` reads both,
and CSV files written before the units were added.

Every column but the run columns (:data:`RUN_COLUMNS`) is the same, bit for bit, whichever
executor computed the rows. The Parquet dataset (``results/``) is partitioned by robot and
date (hive style, ``robot=<r>/date=<d>/part-0.parquet``): each file is written atomically
(:mod:`fricid.io.atomic`) into a temporary folder, which is then swapped in; the CSV is
written atomically too, so a reader never sees a half-written table.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import pandas as pd
import pyarrow as pa
import pyarrow.dataset as ds
import pyarrow.parquet as pq

from ..errors import DataError
from ..io.atomic import atomic_dir, atomic_path, atomic_write
from ._fs import partition_dir, require_real

__all__ = [
    "CSV_UNITS",
    "PARTITIONS",
    "RUN_COLUMNS",
    "VERDICT_COLUMNS",
    "read_results",
    "results_table",
    "row_problem",
    "write_results",
]

#: Partition columns of the Parquet dataset.
PARTITIONS = ("robot", "date")

_STRINGS = (
    "robot",
    "joint",
    "date",
    "model",
    "chosen",
    "status",
    "stage",
    "error",
    "log",
    "reader",
    "method",
    "input_hash",
    "settings_hash",
    "directions",
    "at_bound",
    "fixed",
    "units",
    "model_file",
    "worker",
    "fricid_version",
    "trust",
    "heldout_source",
    "heldout_scheme",
    "verdict",
    "extrapolation_free_range",
    "not_bounded",
    "reasons",
)
_INTS = ("seed", "n_samples", "nfev", "n_not_determined")
_BOOLS = ("converged",)
#: The verdict columns, after the identity and outcome columns.
VERDICT_COLUMNS = (
    "trust",
    "converged",
    "heldout_ratio",
    "heldout_source",
    "heldout_scheme",
    "verdict",
    "n_not_determined",
    "not_bounded",
    "extrapolation_free_range",
)
_FLOATS = (
    "speed_min",
    "speed_max",
    "load_min",
    "load_max",
    "temperature_min",
    "temperature_max",
    "fitness",
    "sse",
    "rmse",
    "rmspe",
    "mae",
    "max_abs_error",
)
#: Columns that describe the run rather than the result (timing, process, memory).
RUN_COLUMNS = ("time_extract_s", "time_fit_s", "time_total_s", "worker", "peak_rss_mb")
_ORDER = (
    "robot",
    "joint",
    "date",
    "model",
    "chosen",
    "status",
    "stage",
    "error",
    *VERDICT_COLUMNS,
    "log",
    "reader",
    "method",
    "seed",
    "input_hash",
    "settings_hash",
    "n_samples",
    "directions",
    *_FLOATS,
    "nfev",
    "at_bound",
    "fixed",
    "units",
    "model_file",
)
#: The per-parameter column prefixes, in the table's order; a column takes the first it starts with.
_PREFIXES = ("param_", "stderr_", "ci95_low_", "ci95_high_", "ci95_")

#: The unit of each results column that has one, as written in ``results.csv``'s header.
CSV_UNITS = {
    "speed_min": "rad/s",
    "speed_max": "rad/s",
    "load_min": "N m",
    "load_max": "N m",
    "temperature_min": "degC",
    "temperature_max": "degC",
    "sse": "N^2 m^2",
    "rmse": "N m",
    "mae": "N m",
    "max_abs_error": "N m",
    "rmspe": "fraction",  # 0.021 is 2.1 % (commands print it in percent)
    "time_extract_s": "s",
    "time_fit_s": "s",
    "time_total_s": "s",
    "peak_rss_mb": "MB",
}


def _type(name: str) -> pa.DataType:
    if name in _STRINGS:
        return pa.string()
    if name in _INTS:
        return pa.int64()
    if name in _BOOLS:
        return pa.bool_()
    return pa.float64()


def _columns(rows: list[dict[str, Any]]) -> list[str]:
    seen: dict[str, None] = {}
    for row in rows:
        seen.update(dict.fromkeys(row))
    params: dict[str, list[str]] = {p: [] for p in _PREFIXES}
    for c in seen:
        if prefix := _prefix(c):
            params[prefix].append(c)
    tail = [*RUN_COLUMNS, "fricid_version"]
    return [
        *(c for c in _ORDER if c in seen or c in ("robot", "joint", "date", "model", "status")),
        *(c for p in _PREFIXES for c in params[p]),
        *(c for c in seen if c not in _ORDER and not c.startswith(_PREFIXES) and c not in tail),
        *(c for c in tail if c in seen),
    ]


def results_table(records: Iterable[dict[str, Any]]) -> pa.Table:
    """The results table of joint records (their rows, in order), with explicit types."""
    rows = [row for record in records for row in record.get("rows", [])]
    names = _columns(rows)
    schema = pa.schema([(n, _type(n)) for n in names])
    return pa.Table.from_pylist([{n: row.get(n) for n in names} for row in rows], schema=schema)


#: The largest integer an int64 column holds, and the largest a float64 column holds.
_INT64 = 2**63 - 1
_FLOAT_MAX = int(sys.float_info.max)


def _value_problem(name: str, value: Any) -> str | None:
    kind = _type(name)
    if value is None:
        return None
    if kind == pa.string():
        ok = isinstance(value, str)
    elif kind == pa.bool_():
        ok = isinstance(value, bool)
    elif kind == pa.int64():
        ok = isinstance(value, int) and not isinstance(value, bool) and abs(value) <= _INT64
    else:
        ok = isinstance(value, int | float) and not isinstance(value, bool)
        ok = ok and (not isinstance(value, int) or abs(value) <= _FLOAT_MAX)
    return None if ok else f"its row's {name[:80]!r} is not a {kind}"


def row_problem(row: dict[str, Any]) -> str | None:
    """Why ``row`` (a record's row, as read from a file) cannot enter the results table
    (:func:`results_table` gives every column one type), or None."""
    for name, value in row.items():
        if not isinstance(name, str):
            return "its row has a column name that is not text"
        why = _value_problem(name, value)
        if why is not None:
            return why
    return None


def _write_partitions(table: pa.Table, folder: Path) -> None:
    """Write ``table`` under ``folder`` as a hive-partitioned dataset (:data:`PARTITIONS`),
    one ``part-0.parquet`` per partition, each through :func:`fricid.io.atomic.atomic_path`,
    rows in table order."""
    if not table.num_rows:
        return
    keys = list(zip(*(table.column(p).to_pylist() for p in PARTITIONS), strict=True))
    data = table.drop_columns(list(PARTITIONS))
    for key in dict.fromkeys(keys):
        rows = data.filter(pa.array([k == key for k in keys]))
        where = folder.joinpath(
            *(f"{p}={partition_dir(v)}" for p, v in zip(PARTITIONS, key, strict=True))
        )
        with atomic_path(where / "part-0.parquet") as part:
            pq.write_table(rows, part)


def write_results(table: pa.Table, root: str | os.PathLike[str]) -> tuple[Path, Path]:
    """Write ``table`` as ``root/results/`` (Parquet, partitioned by robot and date) and
    ``root/results.csv``. Returns both paths. A symbolic link at either, or something of
    another kind, is refused (:func:`._fs.require_real`)."""
    root = Path(root)
    root.mkdir(parents=True, exist_ok=True)
    dataset = require_real(root, ["results"], folder=True)
    csv_path = require_real(root, ["results.csv"])
    with atomic_dir(dataset) as tmp:
        _write_partitions(table, tmp)
    frame = table.to_pandas()
    with atomic_write(csv_path, "w") as fh:
        frame.rename(columns=csv_labels(frame)).to_csv(fh, index=False)
    return dataset, csv_path


def _param_units(frame: pd.DataFrame) -> dict[str, str]:
    """Parameter name -> its unit, for the parameters every row that has one agrees on (the
    rows' ``units`` column, ``name=unit;...``)."""
    seen: dict[str, set[str]] = {}
    for text in frame.get("units", pd.Series(dtype=object)).dropna():
        for item in str(text).split(";"):
            name, sep, unit = item.partition("=")
            if sep:
                seen.setdefault(name, set()).add(unit)
    return {name: units.pop() for name, units in seen.items() if len(units) == 1}


def csv_labels(frame: pd.DataFrame) -> dict[str, str]:
    """Column -> its header in ``results.csv``: ``name [unit]`` where it has a unit
    (:data:`CSV_UNITS`; ``param_``, ``stderr_``, ``ci95_`` columns in their parameter's
    unit), the bare name where it has none or is dimensionless text."""
    units = dict(CSV_UNITS)
    per_param = _param_units(frame)
    for column in frame.columns:
        prefix = _prefix(column)
        if prefix and column[len(prefix) :] in per_param:
            units[column] = per_param[column[len(prefix) :]]
    return {c: f"{c} [{units[c]}]" for c in frame.columns if c in units}


def _prefix(column: str) -> str:
    """The per-parameter prefix ``column`` starts with (:data:`_PREFIXES`), else ``""``."""
    return next((p for p in _PREFIXES if column.startswith(p)), "")


def _bare(label: str) -> str:
    """``rmse [N m]`` -> ``rmse`` (a header from before the units is left as it is)."""
    name, bracket, _ = label.partition(" [")
    return name if bracket and label.endswith("]") else label


def _read_csv(path: Path) -> pd.DataFrame:
    dtypes = {name: "string" for name in _STRINGS}
    frame = pd.read_csv(path, dtype=dtypes)
    frame = frame.rename(columns=_bare)
    for name in _INTS:
        if name in frame:
            frame[name] = frame[name].astype("Int64")
    for name in _BOOLS:
        if name in frame:
            frame[name] = frame[name].astype("boolean")
    return frame


def read_results(path: str | os.PathLike[str]) -> pd.DataFrame:
    """Read a results table: an output folder of ``fricid fleet``, its ``results/`` dataset,
    a ``results.csv`` or one Parquet file.

    Returns a DataFrame sorted by robot, joint and model, with string identity columns.
    """
    path = Path(path)
    if path.is_dir() and (path / "results").is_dir():
        path = path / "results"
    elif path.is_dir() and not any(path.rglob("*.parquet")) and (path / "results.csv").exists():
        path = path / "results.csv"
    if path.suffix.lower() == ".csv":
        try:
            frame = _read_csv(path)
        except (OSError, ValueError, pd.errors.ParserError) as exc:
            raise DataError(f"cannot read the results table: {exc}", file=path) from None
    else:
        if not path.exists():
            raise DataError("no such results table (folder, results.csv or .parquet)", file=path)
        try:
            if path.is_dir():
                part = ds.partitioning(
                    pa.schema([(p, pa.string()) for p in PARTITIONS]), flavor="hive"
                )
                table = ds.dataset(path, format="parquet", partitioning=part).to_table()
            else:
                table = pq.read_table(path)
        except (OSError, pa.ArrowException) as exc:
            raise DataError(f"cannot read the results table: {exc}", file=path) from None
        frame = table.to_pandas()
        for name in _STRINGS:
            if name in frame:
                frame[name] = frame[name].astype("string")
        for name in _INTS:
            if name in frame:
                frame[name] = frame[name].astype("Int64")
        for name in _BOOLS:
            if name in frame:
                frame[name] = frame[name].astype("boolean")
    for name in ("robot", "joint", "model"):
        if name not in frame:
            raise DataError(f"not a fleet results table: no column '{name}'", file=path)
    order = [c for c in _columns([dict.fromkeys(frame.columns)]) if c in frame]
    frame = frame[order]
    return frame.sort_values(["robot", "joint", "model"], kind="stable").reset_index(drop=True)
