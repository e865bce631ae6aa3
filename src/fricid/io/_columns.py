"""Column labels with units, ``"velocity [deg/s]"``, and their resolution against a schema."""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import DataError
from ..units import SI_UNITS, UNITS, to_si

__all__ = ["Column", "check_unit", "resolve_columns", "split_label"]

_LABEL = re.compile(r"^\s*(?P<name>[^\[\]]*?)\s*(?:\[(?P<unit>[^\[\]]*)\])?\s*$")

#: Spellings of "no unit" for dimensionless columns (direction, count).
_DIMENSIONLESS = ("", "1", "-")


@dataclass(frozen=True)
class Column:
    """A column found in a file: its label as written, its unit and its quantity."""

    label: str
    unit: str | None
    quantity: str | None  # None: dimensionless

    def to_si(self, values: np.ndarray) -> np.ndarray:
        """``values`` converted from this column's unit to SI."""
        if self.quantity is None or self.unit is None:
            return values
        return np.asarray(to_si(values, self.unit, self.quantity), dtype=float)


def split_label(label: str) -> tuple[str, str | None]:
    """``"velocity [deg/s]"`` -> ``("velocity", "deg/s")``; ``"count"`` -> ``("count", None)``."""
    m = _LABEL.match(label)
    if m is None:
        return label.strip(), None
    unit = m.group("unit")
    return m.group("name"), None if unit is None else unit.strip()


def check_unit(
    unit: str, quantity: str, *, file: str | os.PathLike[str] | None, column: str
) -> None:
    """Raise :class:`DataError` unless ``unit`` is a known spelling for ``quantity``."""
    if unit.strip() not in UNITS[quantity]:
        raise DataError(
            f"unknown {quantity} unit '{unit}'; use one of: {', '.join(UNITS[quantity])}",
            file=file,
            column=column,
        )


def resolve_columns(
    labels: list[str],
    schema: Mapping[str, str | None],
    required: tuple[str, ...],
    *,
    file: str | os.PathLike[str],
    units: Mapping[str, str] | None = None,
) -> dict[str, Column]:
    """Match file columns to a schema ``{name: quantity or None}`` and check their units.

    Columns may come in any order; names are case-insensitive; columns not in the schema are
    ignored. A unit comes from the label (``"velocity [deg/s]"``) or, failing that, from
    ``units`` (Parquet schema metadata). Raises :class:`DataError` naming the file and column
    for a missing required column, a duplicate, a missing or unknown unit.
    """
    found: dict[str, Column] = {}
    for label in labels:
        name, unit = split_label(label)
        key = name.lower()
        if key not in schema:
            continue
        if key in found:
            raise DataError(
                f"column '{key}' appears twice ('{found[key].label}' and '{label}')",
                file=file,
                column=label,
            )
        quantity = schema[key]
        if unit is None and units is not None:
            unit = units.get(key)
        if quantity is None:
            if unit is not None and unit not in _DIMENSIONLESS:
                raise DataError(
                    f"column '{key}' is dimensionless, but has unit '{unit}'",
                    file=file,
                    column=label,
                )
        elif unit is None:
            raise DataError(
                f"column '{key}' has no unit; write it as '{key} [{SI_UNITS[quantity]}]' "
                f"(or another {quantity} unit: {', '.join(UNITS[quantity])})",
                file=file,
                column=label,
            )
        else:
            check_unit(unit, quantity, file=file, column=label)
        found[key] = Column(label=label, unit=unit, quantity=quantity)
    for key in required:
        if key not in found:
            quantity = schema[key]
            want = key if quantity is None else f"{key} [{SI_UNITS[quantity]}]"
            raise DataError(
                f"missing required column '{key}' (e.g. '{want}'); columns found: "
                + (", ".join(repr(label) for label in labels) or "none"),
                file=file,
                column=key,
            )
    return found
