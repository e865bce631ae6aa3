"""Wide CSV and Parquet tables of a robot: one time column, per-joint columns with units.

Read: the columns are recognised by name (:func:`fricid.io._robot_map.parse_name`: ``q1``,
``dq1``, ``tau1``, ``elbow.position``, ``position_elbow``, ...) with their units in brackets
(``q1 [deg]``) or, in Parquet, in fricid's schema metadata; anything not in SI is converted
here (:data:`fricid.units.UNITS`, plus m, mm, m/s, mm/s, m/s^2 and N for prismatic joints).
Columns of other names are ignored. Written: ``time [s]`` then ``<joint>.<quantity> [unit]``
per quantity and joint, in SI, with the source, the torque constants and ``meta`` in the
comment lines (CSV) or the schema metadata (Parquet), as fricid's other tables.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from ..errors import ConfigError, DataError
from ..samples import ROBOT_COLUMNS, RobotLog
from ..samples.robot_log import joint_column
from ..units import SI_UNITS, UNITS, to_si
from ._columns import check_unit, split_label
from ._csv import (
    csv_preamble,
    preamble_fields,
    read_numeric,
    read_preamble,
    record_line,
    write_csv,
)
from ._parquet import open_parquet, parquet_doc, read_columns, schema_meta, write_parquet
from ._robot_map import constants_for, match_joints, parse_name, velocity_from_position
from ._tablefile import _csv_info, _parquet_info, _torque_constant, meta_of, table_format

__all__ = ["ROBOTLOG_FORMAT", "read_robot_table", "write_robot_table"]

#: Format tag of the robot-log tables fricid writes.
ROBOTLOG_FORMAT = "fricid-robotlog/1"

#: The quantity of :data:`fricid.units.UNITS` whose spellings each column's unit takes.
_UNIT_OF = {**{q: q for q in ROBOT_COLUMNS}, "load": "torque", "time": "time"}

#: Units of prismatic joints (SI: m, m/s, m/s^2, N), beside the rotary ones of UNITS.
_LINEAR: dict[str, dict[str, float]] = {
    "position": {"m": 1.0, "mm": 1e-3},
    "velocity": {"m/s": 1.0, "mm/s": 1e-3},
    "acceleration": {"m/s^2": 1.0},
    "torque": {"N": 1.0},
    "load": {"N": 1.0},
}

#: Characters a joint name cannot have in a written table's header.
_UNWRITABLE = set(',;\t"[]\r\n#')


@dataclass
class _Found:
    """The columns recognised in a table: the time's label, ``{joint: {quantity: label}}``,
    and the label's unit."""

    time: str | None = None
    joints: dict[str | None, dict[str, str]] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)


def _unit(label: str, quantity: str, units: dict[str, Any], path: Path) -> str:
    """The unit of a column: in its label's brackets, else in the Parquet metadata."""
    name, unit = split_label(label)
    if unit is None:
        meta = units.get(name, units.get(label))
        unit = meta if isinstance(meta, str) else None
    if unit is None:
        kind = _UNIT_OF[quantity]
        raise DataError(
            f"column '{name}' has no unit; write it as '{name} [{SI_UNITS[kind]}]' (or another "
            f"{quantity} unit: {', '.join(UNITS[kind])})",
            file=path,
            column=label,
        )
    if unit.strip() not in _LINEAR.get(quantity, {}):
        check_unit(unit, _UNIT_OF[quantity], file=path, column=label)
    return unit.strip()


def _si(values: np.ndarray, quantity: str, unit: str) -> np.ndarray:
    """Values of a column in SI."""
    linear = _LINEAR.get(quantity, {})
    if unit in linear:
        return values * linear[unit]
    return np.asarray(to_si(values, unit, _UNIT_OF[quantity]), dtype=float)


def _recognise(labels: list[str], units: dict[str, Any], path: Path) -> _Found:
    """The table's time and per-joint columns; a DataError for a column given twice."""
    found = _Found()
    seen: dict[tuple[str, str | None], str] = {}
    for label in labels:
        parsed = parse_name(split_label(label)[0])
        if parsed is None:
            continue
        if parsed in seen:
            quantity, joint = parsed
            what = quantity if joint is None else f"the {quantity} of joint '{joint}'"
            raise DataError(
                f"{what} is given twice ('{seen[parsed]}' and '{label}')", file=path, column=label
            )
        seen[parsed] = label
        quantity, joint = parsed
        found.units[label] = _unit(label, quantity, units, path)
        if quantity == "time":
            found.time = label
        else:
            found.joints.setdefault(joint, {})[quantity] = label
    if found.time is None:
        raise DataError(
            "no time column (e.g. 'time [s]'); columns found: "
            + (", ".join(repr(a) for a in labels) or "none"),
            file=path,
            column="time",
        )
    return found


def _shared_columns(found: _Found, single: str, path: Path) -> dict[str, str]:
    """Put the columns of no joint in place: a one-joint table's joint (named ``single``),
    else a temperature shared by every joint; anything else is a DataError."""
    shared = found.joints.pop(None, {})
    if not found.joints:
        if shared:
            found.joints[single] = shared
        return {}
    other = [label for quantity, label in shared.items() if quantity != "temperature"]
    if other:
        raise DataError(
            f"column '{other[0]}' names no joint, but the table has columns of joints "
            f"{', '.join(repr(j) for j in found.joints)}: name its joint (e.g. 'q1', "
            "'position_<joint>')",
            file=path,
            column=other[0],
        )
    return shared


def _matrix(
    quantity: str, columns: list[dict[str, str]], names: list[str], path: Path
) -> list[str] | None:
    """The labels of ``quantity`` for every joint, None if no joint has it; a DataError
    naming the first joint without it when only some have it."""
    labels = [c.get(quantity) for c in columns]
    if all(label is None for label in labels):
        return None
    missing = [n for n, label in zip(names, labels, strict=True) if label is None]
    if missing:
        raise DataError(
            f"joint '{missing[0]}' has no {quantity} column, while other joints have one; "
            f"every joint needs it (or none does)",
            file=path,
            column=joint_column(missing[0], quantity),
        )
    return labels  # type: ignore[return-value]


def _efforts(columns: list[dict[str, str]], names: list[str], path: Path) -> tuple[str, ...]:
    """The effort columns to read: torque if every joint has one (current too if every joint
    has one), else current if every joint has one; else a DataError naming the first joint
    without torque."""
    has_t = ["torque" in c for c in columns]
    has_i = ["current" in c for c in columns]
    if all(has_t):
        return ("torque", "current") if all(has_i) else ("torque",)
    if all(has_i):
        return ("current",)
    name = names[has_t.index(False)]
    raise DataError(
        f"joint '{name}' has no torque column (tau, torque, effort), and not every joint has a "
        "current column; fricid needs the torque, or the current with a torque constant, of "
        "every joint",
        file=path,
        column=joint_column(name, "torque"),
    )


def _constants(pre: dict[str, Any], info_k: float | None, path: Path, n: int) -> np.ndarray | None:
    """Torque constants recorded in the file (``torque_constants``, one per joint in file
    order, or a one-joint table's ``torque_constant``) [N m/A]."""
    value, unit = pre.get("value"), pre.get("unit") or SI_UNITS["torque_constant"]
    if value is None:
        return None if info_k is None or n != 1 else np.array([info_k])
    if not isinstance(value, list) or len(value) != n:
        raise DataError(
            f"metadata 'torque_constants' must list one K per joint ({n}), got {value!r}",
            file=path,
        )
    return np.array([_torque_constant(v, unit, path) for v in value])


def read_robot_table(
    path: str | os.PathLike[str],
    joints: list[str] | None,
    torque_constants: Any,
    temperature: float | None,
) -> RobotLog:
    """Read a wide CSV or Parquet table (the module docstring); see
    :func:`fricid.io.read_robot_log`."""
    path = Path(path)
    if table_format(path) == "csv":
        pre = read_preamble(path)
        labels, units, info = pre.labels, {}, _csv_info(pre.comments, path)
        unit, text = pre.comments.get("torque_constants", (None, None))
        recorded = {"unit": unit, "value": None if text is None else _json(text, path)}
    else:
        pf = open_parquet(path)
        doc = schema_meta(pf, path)
        labels, info = pf.schema_arrow.names, _parquet_info(doc, path)
        units = doc.get("units") if isinstance(doc.get("units"), dict) else {}
        recorded = {"unit": units.get("torque_constants"), "value": doc.get("torque_constants")}
    found = _recognise(labels, units, path)
    single = joints[0] if joints is not None and len(joints) == 1 else (info.joint or "joint")
    shared = _shared_columns(found, single, path)
    ids = [j for j in found.joints if j is not None]
    order, names = match_joints(ids, joints, file=path)
    columns = [found.joints[j] for j in order]
    for name, cols in zip(names, columns, strict=True):
        if "position" not in cols:
            raise DataError(
                f"joint '{name}' has no position column (q, pos, position)",
                file=path,
                column=joint_column(name, "position"),
            )
    efforts = _efforts(columns, names, path)
    want = {
        q: _matrix(q, columns, names, path)
        if q not in ("torque", "current") or q in efforts
        else None
        for q in ROBOT_COLUMNS
    }
    if want["temperature"] is None and "temperature" in shared:
        want["temperature"] = [shared["temperature"]] * len(names)
    if want["temperature"] is not None and temperature is not None:
        raise ConfigError(
            "the table has temperature columns and temperature= was given: give one or the "
            "other [degC]"
        )
    used = [found.time, *(label for ls in want.values() if ls for label in ls)]
    used = list(dict.fromkeys(used))
    raw = read_numeric(pre, used) if table_format(path) == "csv" else read_columns(pf, used, path)
    data = {
        q: np.column_stack([_si(raw[label], q, found.units[label]) for label in ls])
        for q, ls in want.items()
        if ls is not None
    }
    time = _si(raw[found.time], "time", found.units[found.time])
    if len(time) == 0:
        raise DataError("no data rows after the header", file=path)
    k_file = _constants(recorded, info.torque_constant, path, len(ids))
    if torque_constants is None and k_file is not None:
        torque_constants = k_file[[ids.index(j) for j in order]]
    meta = meta_of(info, path)
    if "velocity" not in data:
        data["velocity"] = velocity_from_position(data["position"], time, path)
        meta["velocity_from"] = "position (central difference)"
    if order != names:
        meta["joint_map"] = dict(zip(order, names, strict=True))
    if temperature is not None:
        data["temperature"] = temperature
    labels_of = {
        joint_column(n, q): ls[i] for q, ls in want.items() if ls for i, n in enumerate(names)
    }
    try:
        return RobotLog(
            time=time,
            joints=names,
            torque_constants=constants_for(names, torque_constants),
            source=str(path),
            meta=meta,
            **data,
        )
    except DataError as err:
        row = err.row
        if row is not None and table_format(path) == "csv":
            row = record_line(pre, row)
        column = {"time": found.time, **labels_of}.get(err.column or "", err.column)
        raise DataError(err.message, file=path, row=row, column=column) from None


def _json(text: str, path: Path) -> Any:
    """A comment line's JSON value (a DataError naming the file if it is not JSON)."""
    try:
        return json.loads(text)
    except (json.JSONDecodeError, RecursionError):
        raise DataError(
            f"metadata 'torque_constants' is not JSON: {text[:80]!r}", file=path
        ) from None


def write_robot_table(log: RobotLog, path: str | os.PathLike[str]) -> Path:
    """Write a robot log as a wide table (the module docstring); see
    :func:`fricid.io.write_robot_log`."""
    if not isinstance(log, RobotLog):
        raise ConfigError(f"write_robot_log(log, path) needs a RobotLog, got {type(log).__name__}")
    path = Path(path)
    fmt = table_format(path)
    for name in log.joints:
        bad = sorted(set(name) & _UNWRITABLE)
        if bad or name != name.strip():
            raise ConfigError(
                f"joint name {name!r} cannot be written in a table header ("
                + ("characters " + " ".join(repr(c) for c in bad) if bad else "blanks around it")
                + "); rename it first (RobotLog.rename)"
            )
    units = {"time": SI_UNITS["time"]}
    cols: dict[str, np.ndarray] = {"time": log.time}
    for quantity, unit in ROBOT_COLUMNS.items():
        values = getattr(log, quantity)
        if values is None:
            continue
        for j, name in enumerate(log.joints):
            units[joint_column(name, quantity)] = unit
            cols[joint_column(name, quantity)] = values[:, j]
    table = pa.table(cols)
    k = None if log.torque_constants is None else [float(v) for v in log.torque_constants]
    if fmt == "csv":
        fields = preamble_fields(ROBOTLOG_FORMAT, log.source, None, None, log.meta)
        if k is not None:
            fields.insert(-1, (f"torque_constants [{SI_UNITS['torque_constant']}]", json.dumps(k)))
        write_csv(path, csv_preamble(fields, units), [table])
    else:
        doc = json.loads(parquet_doc(ROBOTLOG_FORMAT, units, log.source, None, None, log.meta))
        if k is not None:
            doc["torque_constants"] = k
            doc["units"]["torque_constants"] = SI_UNITS["torque_constant"]
        write_parquet(path, json.dumps(doc, ensure_ascii=True).encode("ascii"), [table])
    return path
