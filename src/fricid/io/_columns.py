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
    """A column found in a file.

    Parameters
    ----------
    label : str
        The label as written in the file, e.g. ``"velocity [deg/s]"``.
    unit : str or None
        Its unit, None for a dimensionless column.
    quantity : str or None
        Its quantity (a key of :data:`fricid.units.UNITS`), None for a dimensionless column.
    """

    label: str
    unit: str | None
    quantity: str | None  # None: dimensionless

    def to_si(self, values: np.ndarray) -> np.ndarray:
        """Convert values from this column's unit to SI.

        Parameters
        ----------
        values : ndarray
            The column as read.

        Returns
        -------
        ndarray
            The values in SI units; ``values`` itself for a dimensionless column.
        """
        if self.quantity is None or self.unit is None:
            return values
        return np.asarray(to_si(values, self.unit, self.quantity), dtype=float)


def split_label(label: str) -> tuple[str, str | None]:
    """Split a column label into its name and its unit.

    Parameters
    ----------
    label : str
        A label such as ``"velocity [deg/s]"`` or ``"count"``.

    Returns
    -------
    name : str
        The name, stripped.
    unit : str or None
        The unit in brackets, stripped; None when there are no brackets.

    Examples
    --------
    >>> split_label("velocity [deg/s]"), split_label("count")
    (('velocity', 'deg/s'), ('count', None))
    """
    m = _LABEL.match(label)
    if m is None:
        return label.strip(), None
    unit = m.group("unit")
    return m.group("name"), None if unit is None else unit.strip()


def check_unit(
    unit: str, quantity: str, *, file: str | os.PathLike[str] | None, column: str
) -> None:
    """Check that a column's unit is a known spelling for its quantity.

    Parameters
    ----------
    unit : str
        The unit as written.
    quantity : str
        A key of :data:`fricid.units.UNITS`.
    file : str or os.PathLike or None
        The file (for messages).
    column : str
        The column's label (for messages).

    Raises
    ------
    DataError
        An unknown unit; the message lists the accepted spellings.
    """
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
    """Match a file's columns to a schema and check their units.

    Columns may come in any order; names are case-insensitive; columns not in the schema are
    ignored. A unit comes from the label (``"velocity [deg/s]"``) or, failing that, from
    ``units`` (Parquet schema metadata).

    Parameters
    ----------
    labels : list of str
        The file's column labels, in file order.
    schema : mapping of str to str or None
        Column name -> its quantity, None for a dimensionless column.
    required : tuple of str
        The names that must be present.
    file : str or os.PathLike
        The file (for messages).
    units : mapping of str to str, optional
        Column name -> unit, for labels without one.

    Returns
    -------
    dict of str to Column
        The columns found, by lower-case name.

    Raises
    ------
    DataError
        A missing required column, a duplicate, a unit on a dimensionless column, a missing
        or unknown unit; the file and column named.
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
                + (", ".join(repr(label) for label in labels) or "none")
                + _delimiter_hint(labels),
                file=file,
                column=key,
            )
    return found


def _delimiter_hint(labels: list[str]) -> str:
    """A hint when one column label holds several (a header split at the wrong delimiter)."""
    for mark, name in ((";", "';'"), ("\t", "tab"), (",", "','")):
        if any(mark in label for label in labels):
            return f"; the header looks delimited by {name}: give fricid --delimiter {name}"
    return ""
