"""Operating points in, friction out: the table side of ``fricid predict``.

A file of points is a CSV (header line, optional leading ``#`` lines) or Parquet table with a
``velocity`` column and optional ``load`` and ``temperature`` columns (names
case-insensitive, other columns ignored). Each column's unit is written in its name
(``velocity [deg/s]``) or given by the caller (``--velocity-unit``); when both are given they
must agree, so a file is never read in mixed units by accident. Without either, the SI unit
is assumed (rad/s, N m, degC).
"""

from __future__ import annotations

import io
import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ..fitted import FittedModel
from ..io._columns import split_label
from ..io._csv import read_numeric, read_preamble
from ..io._parquet import open_parquet, read_columns, schema_meta
from ..models import get_model
from ..units import SI_UNITS, UNITS, from_si, to_si

__all__ = [
    "INPUT_QUANTITY",
    "default_filled",
    "model_inputs",
    "points_matrix",
    "points_table",
    "read_points",
]

#: The model inputs and the physical quantity of each (for unit conversion).
INPUT_QUANTITY: dict[str, str] = {
    "velocity": "velocity",
    "load": "torque",
    "temperature": "temperature",
}


def _leaves(state: Any) -> list[dict]:
    """The networks or processes of a learned model's state that name their own inputs (a
    direction's, a hybrid's residual's), not the containers of two of them."""
    out, todo = [], [state]
    while todo:
        node = todo.pop()
        if not isinstance(node, dict):
            continue
        kids = [node.get(k) for k in ("pos", "neg", "residual") if isinstance(node.get(k), dict)]
        if kids:
            todo.extend(kids)
        elif isinstance(node.get("inputs"), list | tuple):
            out.append(node)
    return out


def model_inputs(fitted: FittedModel) -> tuple[str, ...]:
    """The inputs the model uses: a learned model's networks' or processes' own (an input
    each dropped for not varying is not used; a hybrid's backbone's added), else those its
    state names, else all three; an analytic model's ``inputs``."""
    if fitted.kind != "rbf":
        return tuple(fitted.friction_model().inputs)
    state = fitted.state or {}
    leaves = _leaves(state)
    names: set[str] = set()
    for leaf in leaves:
        names.update(str(n) for n in leaf["inputs"])
    backbone = state.get("backbone") if isinstance(state, dict) else None
    if isinstance(backbone, dict) and isinstance(backbone.get("model"), str):
        try:
            names.update(get_model(backbone["model"]).inputs)
        except ConfigError:
            names.update(INPUT_QUANTITY)
    if leaves and names <= set(INPUT_QUANTITY):
        return tuple(n for n in INPUT_QUANTITY if n in names)
    top = state.get("inputs") if isinstance(state, dict) else None
    if isinstance(top, list | tuple) and all(n in INPUT_QUANTITY for n in top):
        return tuple(top)
    return tuple(INPUT_QUANTITY)


def _dropped_value(fitted: FittedModel, name: str) -> float | None:
    """The value at which every network or process that dropped ``name`` saw it constant,
    when they agree (the point the model was identified at), else None."""
    seen = {
        float(leaf["dropped_inputs"][name])
        for leaf in _leaves(fitted.state or {})
        if isinstance(leaf.get("dropped_inputs"), dict) and name in leaf["dropped_inputs"]
    }
    return seen.pop() if len(seen) == 1 else None


def default_filled(fitted: FittedModel, name: str) -> bool:
    """Whether :func:`points_matrix` fills input ``name`` (load or temperature), when it is not
    given, with its fixed default (0 N m, 25 degC) rather than a value of the model's: the model
    does not use it and, for a learned model, dropped it at no value of its own. Such a value is
    no measurement, and the friction does not depend on it."""
    if name in model_inputs(fitted):
        return False
    return fitted.kind != "rbf" or _dropped_value(fitted, name) is None


def _unit_of(name: str, label: str, given: str | None, path: Path, meta_units) -> str:
    quantity = INPUT_QUANTITY[name]
    in_label = split_label(label)[1]
    if in_label is None and isinstance(meta_units, dict):
        in_label = meta_units.get(label) or meta_units.get(name)
    if given is not None and in_label is not None and given.strip() != in_label.strip():
        raise DataError(
            f"mixed units: the column says {quantity} is in '{in_label}', but "
            f"--{name}-unit says '{given}'; give one unit",
            file=path,
            column=label,
        )
    unit = (given or in_label or SI_UNITS[quantity]).strip()
    if unit not in UNITS[quantity]:
        raise DataError(
            f"unknown {quantity} unit '{unit}'; use one of: {', '.join(UNITS[quantity])}",
            file=path,
            column=label,
        )
    return unit


def read_points(
    path: str | os.PathLike[str], units: Mapping[str, str | None] | None = None
) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """Read a file of operating points.

    Parameters
    ----------
    path : ``.csv``, ``.parquet`` or ``.pq``.
    units : input name -> unit given by the caller (None: from the column name, else SI).

    Returns
    -------
    (columns, units)
        SI arrays of the inputs present (velocity always), and the unit each was read in.

    Raises
    ------
    DataError
        No velocity column (the columns found are listed), a column whose unit disagrees
        with ``units`` (mixed units), an unknown unit, a non-numeric or non-finite value
        (file, line, column).
    """
    path = Path(path)
    units = dict(units or {})
    suffix = path.suffix.lower()
    meta_units = None
    if suffix == ".csv":
        pre = read_preamble(path)
        labels = pre.labels
    elif suffix in (".parquet", ".pq"):
        pf = open_parquet(path)
        labels = pf.schema_arrow.names
        meta_units = schema_meta(pf, path).get("units")
    else:
        raise ConfigError(f"cannot read '{path}': use a .csv, .parquet or .pq file of points")
    found: dict[str, str] = {}
    for label in labels:
        name = split_label(label)[0].lower()
        if name in INPUT_QUANTITY:
            if name in found:
                raise DataError(
                    f"column '{name}' appears twice ('{found[name]}' and '{label}')",
                    file=path,
                    column=label,
                )
            found[name] = label
    if "velocity" not in found:
        raise DataError(
            "missing column 'velocity' (e.g. 'velocity [rad/s]'); columns found: "
            + (", ".join(repr(x) for x in labels) or "none"),
            file=path,
            column="velocity",
        )
    used = {
        name: _unit_of(name, label, units.get(name), path, meta_units)
        for name, label in found.items()
    }
    wanted = list(found.values())
    raw = read_numeric(pre, wanted) if suffix == ".csv" else read_columns(pf, wanted, path)
    cols = {
        name: np.asarray(to_si(raw[label], used[name], INPUT_QUANTITY[name]), dtype=float)
        for name, label in found.items()
    }
    return cols, used


def points_matrix(
    fitted: FittedModel,
    velocity,
    load=None,
    temperature=None,
) -> np.ndarray:
    """Model inputs ``(n, 3)`` from SI values (arrays that broadcast, or None).

    An input the model uses must be given; one it ignores defaults to the constant value a
    learned model dropped it at, else 0 N m (load) or 25 degC (temperature).

    Raises
    ------
    ConfigError
        A needed input missing, or lengths that do not broadcast.
    """
    needed = model_inputs(fitted)
    values = {"velocity": velocity, "load": load, "temperature": temperature}
    defaults = {"load": 0.0, "temperature": 25.0}
    for name in ("load", "temperature"):
        if values[name] is None:
            if name in needed:
                raise ConfigError(
                    f"model '{fitted.model}' depends on {name}; give --{name} (or a {name} "
                    "column in the input file)"
                )
            dropped = _dropped_value(fitted, name) if fitted.kind == "rbf" else None
            values[name] = defaults[name] if dropped is None else dropped
    try:
        v, lo, t = np.broadcast_arrays(
            *(np.atleast_1d(np.asarray(values[k], dtype=float)) for k in INPUT_QUANTITY)
        )
    except ValueError:
        sizes = {k: np.size(values[k]) for k in INPUT_QUANTITY}
        raise ConfigError(
            "velocity, load and temperature must have one value each or the same number of "
            f"values; got {sizes}"
        ) from None
    X = np.column_stack([v.ravel(), lo.ravel(), t.ravel()])
    if not np.isfinite(X).all():
        raise ConfigError("operating points must be finite numbers")
    return X


def points_table(
    X: np.ndarray,
    friction: np.ndarray,
    units: Mapping[str, str],
    extra: Mapping[str, np.ndarray] | None = None,
    digits: int | None = None,
    without: Iterable[str] = (),
) -> str:
    """CSV text of points and friction, each column in ``units`` (SI where not given) and
    labelled with it. ``extra`` columns (e.g. a prediction interval's ends) are torques [N m],
    written after the friction in its unit; the inputs named in ``without`` are not written
    (a value the model neither uses nor was given).

    ``digits`` None writes every number exactly in the fewest digits that read back to the
    same float (``0.2``, not ``0.20000000000000001``); an int rounds to that many significant
    digits (``%.{digits}g``), for reading by eye."""
    out_units = {
        "velocity": units.get("velocity") or SI_UNITS["velocity"],
        "load": units.get("load") or SI_UNITS["torque"],
        "temperature": units.get("temperature") or SI_UNITS["temperature"],
        "friction": units.get("friction") or SI_UNITS["torque"],
    }
    quantity = {**INPUT_QUANTITY, "friction": "torque"}
    data = {"velocity": X[:, 0], "load": X[:, 1], "temperature": X[:, 2], "friction": friction}
    for name in without:
        del data[name]
    for name, col in (extra or {}).items():
        data[name] = col
        out_units[name] = out_units["friction"]
        quantity[name] = "torque"
    cols = [np.asarray(from_si(data[k], out_units[k], quantity[k]), dtype=float) for k in data]
    buf = io.StringIO()
    buf.write(",".join(f"{k} [{out_units[k]}]" for k in data) + "\n")
    if digits is not None:
        np.savetxt(buf, np.column_stack(cols), delimiter=",", fmt=f"%.{int(digits)}g")
        return buf.getvalue()
    text = [[_shortest(x) for x in col.tolist()] for col in cols]  # Python's round-trip repr
    buf.writelines(",".join(row) + "\n" for row in zip(*text, strict=True))
    return buf.getvalue()


def _shortest(x: float) -> str:
    """``x`` in the fewest digits that read back to the same float; whole numbers without
    ``.0`` (``25``, as ``%g`` writes them)."""
    return str(int(x)) if x.is_integer() and abs(x) < 1e16 else repr(x)
