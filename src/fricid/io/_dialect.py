"""The delimiter and the decimal mark of a CSV file: detected from its header and first data
line, or given (``fricid --delimiter ';' --decimal ,``, or :func:`csv_dialect` in Python).

Spreadsheets set to a European locale write ``;`` between fields and a decimal comma
(``0,25;1,5``); some tools write tabs. A file is read with the delimiter that splits its
header into the most columns and its first data line into as many; with ``;`` or a tab, a
decimal comma is recognised when a data field reads as a number with it (``0,25``,
``-1,5e-3``) and none is written with a point.
"""

from __future__ import annotations

import contextlib
import csv
import re
from collections.abc import Iterator
from contextvars import ContextVar
from dataclasses import dataclass

from ..errors import ConfigError

__all__ = ["DELIMITERS", "Dialect", "csv_dialect", "detect_dialect", "parse_delimiter"]

#: The delimiters tried, in order of preference when they split a file alike.
DELIMITERS = (",", ";", "\t")

#: A number written with a decimal comma (and no point).
_COMMA_NUMBER = re.compile(r"^\s*[+-]?\d*,\d+(?:[eE][+-]?\d+)?\s*$")
#: A number written with a decimal point.
_POINT_NUMBER = re.compile(r"^\s*[+-]?(?:\d+\.\d*|\.\d+)(?:[eE][+-]?\d+)?\s*$")

#: Names of delimiters on the command line (a tab is hard to type).
_NAMES = {"comma": ",", "semicolon": ";", "tab": "\t", "\\t": "\t"}


@dataclass(frozen=True)
class Dialect:
    """How a CSV file separates fields and writes decimals.

    Attributes
    ----------
    delimiter : str
        ``","``, ``";"`` or a tab.
    decimal : str
        ``"."`` or ``","`` (only with a delimiter other than a comma).
    """

    delimiter: str = ","
    decimal: str = "."


#: What the user asked for (None: detect), set by :func:`csv_dialect`.
_GIVEN: ContextVar[tuple[str | None, str | None]] = ContextVar("fricid_csv", default=(None, None))


def parse_delimiter(text: str) -> str:
    """A delimiter as given on the command line: ``,``, ``;``, a tab, or the names
    ``comma``, ``semicolon``, ``tab`` (``\\t``).

    Raises
    ------
    ConfigError
        Anything else.
    """
    value = _NAMES.get(text.strip().lower(), text)
    if value not in DELIMITERS:
        raise ConfigError(
            f"--delimiter must be one of ',', ';', tab (or comma, semicolon, tab); got {text!r}"
        )
    return value


@contextlib.contextmanager
def csv_dialect(delimiter: str | None = None, decimal: str | None = None) -> Iterator[None]:
    """Read every CSV file inside the block with this delimiter and decimal mark (None:
    detected per file).

    Parameters
    ----------
    delimiter : str, optional
        ``","``, ``";"`` or a tab (names as :func:`parse_delimiter` accepts).
    decimal : str, optional
        ``"."`` or ``","``.

    Raises
    ------
    ConfigError
        An unknown delimiter or decimal mark, or a decimal comma with a comma delimiter.

    Examples
    --------
    >>> from fricid.io import csv_dialect
    >>> with csv_dialect(delimiter=";", decimal=","):
    ...     pass  # read_samples("werte.csv") here reads 0,25;1,5
    """
    delim = parse_delimiter(delimiter) if delimiter is not None else None
    if decimal is not None and decimal not in (".", ","):
        raise ConfigError(f"--decimal must be '.' or ','; got {decimal!r}")
    if decimal == "," and delim == ",":
        raise ConfigError("a decimal comma needs another delimiter (--delimiter ';' or tab)")
    token = _GIVEN.set((delim, decimal))
    try:
        yield
    finally:
        _GIVEN.reset(token)


def _fields(line: str, delimiter: str) -> list[str]:
    try:
        return next(csv.reader([line], delimiter=delimiter), [])
    except csv.Error:
        return []


def _decimal(data: list[str]) -> str:
    """``","`` when some field reads as a number with a decimal comma and none with a point."""
    comma = any(_COMMA_NUMBER.match(f) for f in data)
    point = any(_POINT_NUMBER.match(f) for f in data)
    return "," if comma and not point else "."


def detect_dialect(header: str, data: str | None) -> Dialect:
    """The dialect of a file from its header line and first data line (None: no data).

    What :func:`csv_dialect` gave is used as given; the rest is detected: the delimiter of
    :data:`DELIMITERS` that splits the header into the most fields, with the first data line
    split into as many (a decimal comma splits it into more with ``,``), and ``;`` for a single
    column written with a decimal comma; then the decimal mark (:func:`_decimal`).
    """
    delim, decimal = _GIVEN.get()
    if delim is None:
        best, width = ",", len(_fields(header, ","))
        for cand in DELIMITERS[1:]:
            n = len(_fields(header, cand))
            fits = data is None or len(_fields(data, cand)) == n
            if n > width and fits:
                best, width = cand, n
        if width == 1 and data is not None and _COMMA_NUMBER.match(data) and decimal != ".":
            best = ";"  # one column of decimal-comma numbers: no field is split at a comma
        delim = best
    if decimal is None:
        decimal = "." if delim == "," or data is None else _decimal(_fields(data, delim))
    return Dialect(delim, decimal)
