"""The columns of fricid's two data types, their units and physically possible ranges, and
the column checks both types run on construction (each error naming its row and column).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import DataError

#: Model inputs a :class:`FrictionSamples` may lack (not measured: all NaN).
OPTIONAL_INPUTS: tuple[str, ...] = ("load", "temperature")

#: Columns of a :class:`FrictionSamples` table and their units.
SAMPLE_COLUMNS: dict[str, str] = {
    "velocity": "rad/s",
    "load": "N m",
    "temperature": "degC",
    "friction": "N m",
    "direction": "1",
    "count": "1",
    "std": "N m",
}

#: Columns of a :class:`RawLog` and their units (``torque`` or ``current``, or both, present).
RAWLOG_COLUMNS: dict[str, str] = {
    "time": "s",
    "position": "rad",
    "velocity": "rad/s",
    "torque": "N m",
    "current": "A",
    "temperature": "degC",
}


#: Physically possible range of each column, ``(low, high, unit)`` in SI. Values outside it
#: are not measurements (a unit mistake, a corrupt file, an overflow): absolute zero below,
#: and above, bounds no joint reaches (1e6 rad/s is about 10 million rpm) that still leave
#: products such as friction x velocity far from floating-point overflow.
LIMITS: dict[str, tuple[float, float, str]] = {
    "time": (-1e10, 1e10, "s"),
    "position": (-1e12, 1e12, "rad"),
    "velocity": (-1e6, 1e6, "rad/s"),
    "acceleration": (-1e12, 1e12, "rad/s^2"),
    "torque": (-1e9, 1e9, "N m"),
    "current": (-1e6, 1e6, "A"),
    "temperature": (-273.15, 1e4, "degC"),
    "load": (-1e9, 1e9, "N m"),
    "friction": (-1e9, 1e9, "N m"),
    "count": (1.0, 2.0**53, "1"),
    "std": (0.0, 1e9, "N m"),
    "torque_constant": (0.0, 1e6, "N m/A"),
}


#: Speed [rad/s] below which a velocity's sign is not taken to contradict a row's direction
#: (a rounding residue, not a motion).
DIRECTION_TOLERANCE = 1e-9


def _check_range(name: str, arr: np.ndarray, source: str | None) -> None:
    """Raise :class:`DataError` for the first value of column ``name`` outside :data:`LIMITS`."""
    low, high, unit = LIMITS[name]
    u = "" if unit == "1" else f" {unit}"
    bad = (arr < low) | (arr > high)
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        what = "below absolute zero" if name == "temperature" and arr[row] < low else "impossible"
        raise DataError(
            f"{what} value {float(arr[row])!r}{u}; {name} must lie in [{low:g}, {high:g}]{u} "
            "(a unit mistake or a corrupt file?)",
            file=source,
            row=row,
            column=name,
        )


def _as_column(name: str, values: Any, n: int | None, source: str | None) -> np.ndarray:
    """``values`` as a finite float column of ``n`` rows (a scalar is broadcast).

    Raises
    ------
    DataError
        Not one-dimensional, the wrong length, or a non-finite value (its row named).
    """
    arr = np.asarray(values, dtype=float)
    if arr.ndim == 0:
        arr = np.full(n if n is not None else 1, float(arr))
    if arr.ndim != 1:
        raise DataError(f"must be one-dimensional, got shape {arr.shape}", file=source, column=name)
    if n is not None and arr.shape[0] != n:
        raise DataError(f"has {arr.shape[0]} values, expected {n}", file=source, column=name)
    bad = ~np.isfinite(arr)
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise DataError(f"non-finite value {float(arr[row])!r}", file=source, row=row, column=name)
    if name in LIMITS and name not in ("count", "std"):  # checked after their own rules
        _check_range(name, arr, source)
    return arr


def _optional_column(name: str, values: Any, n: int, source: str | None) -> np.ndarray:
    """An optional input of :class:`FrictionSamples`: None or all NaN -> all NaN (not
    measured), else a finite column (:func:`_as_column`)."""
    if values is None:
        return np.full(n, np.nan)
    arr = np.asarray(values, dtype=float)
    if arr.size and np.isnan(arr).all():
        shape_checked = _as_column(name, np.zeros_like(arr), n, source)
        return np.full_like(shape_checked, np.nan)
    return _as_column(name, values, n, source)
