"""Any CSV or Parquet joint log, read through an explicit column mapping and explicit units."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..errors import ConfigError, DataError
from ..samples import RawLog, constant_temperature
from ..units import UNITS, to_si
from ._columns import split_label
from ._csv import read_numeric, read_preamble, record_line
from ._parquet import open_parquet, read_columns

__all__ = ["read_table_log"]

#: Quantities a generic log can map, with the physical quantity of their unit.
_QUANTITIES = ("time", "position", "velocity", "torque", "current", "temperature")


def _check_mapping(
    columns: Mapping[str, str], units: Mapping[str, str], temperature: float | None
) -> None:
    """Check that the mapping names known quantities, the required ones, and one source of
    temperature; a :class:`ConfigError` otherwise."""
    unknown = [q for q in columns if q not in _QUANTITIES]
    if unknown:
        raise ConfigError(
            f"unknown quantity {unknown[0]!r} in columns; map any of: {', '.join(_QUANTITIES)}"
        )
    extra = [q for q in units if q not in columns]
    if extra:
        raise ConfigError(f"units given for {extra[0]!r}, which columns= does not map")
    for q in ("time", "velocity"):
        if q not in columns:
            raise ConfigError(f"columns must map '{q}' (a column of the file)")
    if "torque" not in columns and "current" not in columns:
        raise ConfigError("columns must map 'torque' or 'current' (with torque_constant)")
    if "temperature" in columns and temperature is not None:
        raise ConfigError(
            "give the temperature either as a column (columns={'temperature': ...}) or as a "
            "constant (temperature=...) [degC], not both"
        )


def _same_unit(quantity: str, a: str, b: str) -> bool:
    """Whether two spellings of a unit convert alike (``Nm`` and ``N m`` do)."""
    table = UNITS[quantity]
    return a.strip() == b.strip() or (
        a.strip() in table and b.strip() in table and table[a.strip()] == table[b.strip()]
    )


def _unit(quantity: str, label: str, units: Mapping[str, str]) -> str:
    """The unit of a mapped column: from ``units``, else from its label ``"dq [deg/s]"``."""
    given = units.get(quantity)
    in_label = split_label(label)[1]
    allowed = ", ".join(UNITS[quantity])
    if given is not None and in_label is not None and not _same_unit(quantity, given, in_label):
        raise ConfigError(
            f"column '{label}' says its unit is '{in_label}', but units= (--map) says "
            f"'{given}' for {quantity}; give one unit (allowed: {allowed})"
        )
    unit = given if given is not None else in_label
    if unit is None:
        raise ConfigError(
            f"no unit for {quantity} (column '{label}'); pass units={{'{quantity}': ...}} "
            f"with one of: {allowed}"
        )
    if unit.strip() not in UNITS[quantity]:
        raise ConfigError(f"unknown {quantity} unit '{unit}'; allowed units: {allowed}")
    return unit.strip()


def _find_column(label: str, quantity: str, available: list[str], path: Path) -> str:
    """The file's column that ``label`` names: the label itself (blanks around it tolerated),
    else the one column whose name without its bracketed unit is ``label`` (``t`` finds
    ``t [s]``, whose unit then comes from the bracket).

    Raises
    ------
    DataError
        No such column (listing the file's columns), or two columns of that name.
    """
    if label in available:
        return label
    by_name = {a.strip(): a for a in reversed(available)}  # tolerate blanks around names
    if label.strip() in by_name:
        return by_name[label.strip()]
    if split_label(label)[1] is None:
        named = [a for a in available if split_label(a)[0] == label.strip()]
        if len(named) == 1:
            return named[0]
        if len(named) > 1:
            raise DataError(
                f"'{label}' (mapped to {quantity}) names {len(named)} columns: "
                + ", ".join(repr(a) for a in named)
                + "; map one of them by its full label",
                file=path,
                column=label,
            )
    raise DataError(
        f"no column '{label}' (mapped to {quantity}); the file has: "
        + ", ".join(repr(a) for a in available),
        file=path,
        column=label,
    )


def integrate_velocity(time: np.ndarray, velocity: np.ndarray) -> np.ndarray:
    """Position [rad] as the trapezoidal integral of velocity, starting at 0 (for logs that
    record no position: the readers of generic tables, per-channel files and MATLAB files)."""
    with np.errstate(over="ignore", invalid="ignore"):  # RawLog reports absurd velocities
        steps = 0.5 * (velocity[1:] + velocity[:-1]) * np.diff(time)
        return np.concatenate([[0.0], np.cumsum(steps)])


def read_table_log(
    path: str | os.PathLike[str],
    columns: Mapping[str, str],
    units: Mapping[str, str] | None = None,
    *,
    torque_constant: float | None = None,
    temperature: float | None = None,
    joint: str = "joint",
) -> RawLog:
    """Read a joint log from any CSV or Parquet table, given which column is what.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.csv`` file (comma-separated, a header line, optional leading ``#`` lines) or a
        ``.parquet`` / ``.pq`` file.
    columns : mapping of str to str
        Quantity -> column name in the file. Quantities: time and velocity (required),
        torque or current (one required), position and temperature (optional), e.g.
        ``{"time": "t", "position": "q", "velocity": "dq", "torque": "tau"}``.
    units : mapping of str to str, optional
        Quantity -> unit, e.g. ``{"velocity": "deg/s"}``. A unit may instead be written in
        the column name (``"dq [deg/s]"``); every mapped column needs one or the other.
    torque_constant : float, optional
        K [N m/A] for a current column (tau = K I, eq. 13 of the BAS-RBFNN paper).
    temperature : float, optional
        Constant temperature [degC] when the file has no temperature column. Without a column
        and without this, the log records none (``meta["temperature_source"]``:
        :data:`fricid.samples.NO_TEMPERATURE_SOURCE`), nor do the samples extracted from it.
    joint : str, default "joint"
        The joint's name in the log.

    Returns
    -------
    RawLog
        In SI. Without a position column, position is the trapezoidal integral of velocity
        starting at 0.

    Raises
    ------
    ConfigError
        An unknown quantity or unit (listing the allowed ones), conflicting units, a missing
        unit, or an incomplete mapping.
    DataError
        A mapped column missing from the file (listing the file's columns), a non-numeric or
        non-finite value (file, line, column), time not increasing.

    See Also
    --------
    fricid.io.read_rawlog : fricid's own raw-log tables, whose columns need no mapping.

    Examples
    --------
    >>> log = read_table_log(  # doctest: +SKIP
    ...     "vendor.csv",
    ...     {"time": "t", "velocity": "dq", "torque": "tau"},
    ...     {"time": "ms", "velocity": "deg/s", "torque": "N m"},
    ...     temperature=25.0,
    ... )
    """
    path = Path(path)
    columns = dict(columns)
    units = dict(units or {})
    _check_mapping(columns, units, temperature)
    suffix = path.suffix.lower()
    if suffix == ".csv":
        pre = read_preamble(path)
        available = pre.labels
    elif suffix in (".parquet", ".pq"):
        pf = open_parquet(path)
        available = pf.schema_arrow.names
    else:
        raise ConfigError(f"cannot read '{path}': use a .csv, .parquet or .pq file")
    for quantity, label in columns.items():
        columns[quantity] = _find_column(label, quantity, available, path)
    unit_of = {q: _unit(q, label, units) for q, label in columns.items()}
    labels = list(dict.fromkeys(columns.values()))
    raw = read_numeric(pre, labels) if suffix == ".csv" else read_columns(pf, labels, path)
    si = {
        q: np.asarray(to_si(raw[label], unit_of[q], q), dtype=float) for q, label in columns.items()
    }
    time, velocity = si["time"], si["velocity"]
    if len(time) == 0:
        raise DataError("no data rows after the header", file=path)
    constant, source = constant_temperature(temperature)
    try:
        return RawLog(
            time=time,
            position=si["position"] if "position" in si else integrate_velocity(time, velocity),
            velocity=velocity,
            temperature=si.get("temperature", constant),
            torque=si.get("torque"),
            current=si.get("current"),
            torque_constant=torque_constant,
            joint=joint,
            source=str(path),
            meta={
                "columns": columns,
                "units": unit_of,
                "position_source": "channel" if "position" in si else "integrated velocity",
                **({} if "temperature" in si else {"temperature_source": source}),
            },
        )
    except DataError as err:
        row = err.row
        if row is not None and suffix == ".csv":
            row = record_line(pre, row)
        column = columns.get(err.column, err.column) if err.column else None
        raise DataError(err.message, file=path, row=row, column=column) from None
