"""Option values written as text: ``NAME=VALUE``, ``NAME=LOW:HIGH`` and position grids.

The one parser of each, used by the command line (``fricid fit --fix/--bound``, ``fricid
extract --positions/--map``) and by the fleet manifest (``fix``, ``bound``, ``positions``,
``columns``, ``units``), so a value means the same, and is refused for the same reasons,
wherever it is written.

Every parser raises :class:`~fricid.errors.ConfigError` with a message that names the item
and says what was expected; the caller adds where it stood (a flag, or a manifest's file, row
and column). Numbers must be finite; a range needs ``LOW < HIGH``; a name may be given once.

>>> parse_assignments(["delta=1", "xi = 2"])
{'delta': 1.0, 'xi': 2.0}
>>> parse_ranges("w_s=0.001:1; v_s=0:2")
{'w_s': (0.001, 1.0), 'v_s': (0.0, 2.0)}
>>> parse_grid("-60:-20:20")
[-60.0, -40.0, -20.0]
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping
from typing import Any

from ..errors import ConfigError

__all__ = [
    "MAX_GRID",
    "parse_assignments",
    "parse_grid",
    "parse_number",
    "parse_pairs",
    "parse_range",
    "parse_ranges",
    "split_list",
]

#: The most points a position grid may have (a typo such as a step of 1e-9 would otherwise
#: ask for a billion position bins).
MAX_GRID = 100_000

_NAME = re.compile(r"^[^\s=;,:]+$")


def split_list(value: Any, *, spaces: bool = False) -> list[Any]:
    """A list as is; a text split on ``;`` and ``,`` (and white space if ``spaces``).

    Empty items are dropped: ``"a;;b"`` gives ``["a", "b"]``.
    """
    if isinstance(value, list | tuple):
        return list(value)
    if not isinstance(value, str | int | float) or isinstance(value, bool):
        raise ConfigError(f"expected a value or a list, got {type(value).__name__}")
    pattern = r"[;,\s]+" if spaces else r"[;,]"
    return [p.strip() for p in re.split(pattern, str(value)) if p.strip()]


def parse_number(value: Any) -> float:
    """A finite number from a number or its text.

    Raises
    ------
    ConfigError
        For text that is not a number, for NaN and infinities, and for booleans.
    """
    if isinstance(value, bool):
        raise ConfigError(f"'{value}' is not a number")
    try:
        x = float(value.strip() if isinstance(value, str) else value)
    except (TypeError, ValueError):
        raise ConfigError(f"'{value}' is not a number") from None
    if not math.isfinite(x):
        raise ConfigError(f"'{value}' is not a finite number")
    return x


def _items(items: str | Iterable[str] | None) -> list[str]:
    if items is None:
        return []
    if isinstance(items, str):
        return [p for p in items.split(";") if p.strip()]
    return [str(item) for item in items]


def parse_pairs(
    items: str | Iterable[str] | Mapping[Any, Any] | None, *, form: str = "NAME=VALUE"
) -> dict[str, Any]:
    """``NAME=VALUE`` items to a dict of text values, names stripped, each name once.

    Parameters
    ----------
    items : str, iterable of str or Mapping
        One text with items separated by ``;`` (a manifest cell), the items themselves (a
        repeated flag), or a mapping (YAML), whose values are kept as they are.
    form : str
        How an item is written, for the message.

    Raises
    ------
    ConfigError
        For an item without ``=``, with an empty name or value, with a name holding white
        space, ``=``, ``;``, ``,`` or ``:``, or for a name given twice.
    """
    out: dict[str, Any] = {}
    if isinstance(items, Mapping):
        pairs = [(str(k).strip(), v, f"{k}={v}") for k, v in items.items()]
    else:
        pairs = []
        for item in _items(items):
            name, sep, value = item.partition("=")
            if not sep or not name.strip() or not value.strip():
                raise ConfigError(f"expected {form}, got '{item.strip()}'")
            pairs.append((name.strip(), value.strip(), item.strip()))
    for name, value, item in pairs:
        if not _NAME.match(name):
            raise ConfigError(f"'{name}' is not a name (in '{item}')")
        if name in out:
            raise ConfigError(f"'{name}' is given twice")
        out[name] = value
    return out


def parse_assignments(items: str | Iterable[str] | Mapping[Any, Any] | None) -> dict[str, float]:
    """``NAME=VALUE`` items with finite numbers: ``["delta=1"]`` -> ``{"delta": 1.0}``.

    ``items`` as in :func:`parse_pairs`. Raises :class:`~fricid.errors.ConfigError`.
    """
    out: dict[str, float] = {}
    for name, value in parse_pairs(items).items():
        try:
            out[name] = parse_number(value)
        except ConfigError as exc:
            raise ConfigError(f"{exc} (in '{name}={_show(value)}')") from None
    return out


def _show(value: Any) -> str:
    """A value as written: a pair as ``LOW:HIGH``."""
    if isinstance(value, list | tuple):
        return ":".join(str(v) for v in value)
    return str(value)


def parse_range(value: Any) -> tuple[float, float]:
    """``"LOW:HIGH"`` (or a pair of numbers) to ``(low, high)``, finite, ``low < high``.

    Raises
    ------
    ConfigError
        For anything but two finite numbers in increasing order.
    """
    if isinstance(value, list | tuple):
        parts = list(value)
    elif isinstance(value, str):
        parts = value.split(":")
    else:
        parts = [value]
    if len(parts) != 2:
        raise ConfigError(f"expected LOW:HIGH, got '{value}'")
    low, high = parse_number(parts[0]), parse_number(parts[1])
    if not low < high:
        raise ConfigError(f"needs LOW < HIGH, got {low:g} and {high:g}")
    return low, high


def parse_ranges(
    items: str | Iterable[str] | Mapping[Any, Any] | None,
) -> dict[str, tuple[float, float]]:
    """``NAME=LOW:HIGH`` items: ``["w_s=0.001:1"]`` -> ``{"w_s": (0.001, 1.0)}``.

    ``items`` as in :func:`parse_pairs` (a mapping's values may be pairs of numbers). Raises
    :class:`~fricid.errors.ConfigError`.
    """
    out: dict[str, tuple[float, float]] = {}
    for name, value in parse_pairs(items, form="NAME=LOW:HIGH").items():
        try:
            out[name] = parse_range(value)
        except ConfigError as exc:
            raise ConfigError(f"{exc} (in '{name}={_show(value)}')") from None
    return out


def parse_grid(value: Any) -> list[float]:
    """Points from ``"START:STOP:STEP"`` (STOP included when on the grid) or a list.

    A list is a YAML list or a text separated by ``;``, ``,`` or white space. Every point is a
    finite number; a grid needs ``STEP > 0`` and ``STOP >= START`` and at most
    :data:`MAX_GRID` points.

    Raises
    ------
    ConfigError
        For a malformed grid or list, or an empty list.
    """
    if isinstance(value, str) and ":" in value:
        parts = value.split(":")
        if len(parts) != 3:
            raise ConfigError(f"expected START:STOP:STEP or a list, got '{value}'")
        try:
            start, stop, step = (parse_number(p) for p in parts)
        except ConfigError as exc:
            message = f"expected START:STOP:STEP or a list, got '{value}' ({exc})"
            raise ConfigError(message) from None
        if not (step > 0 and stop >= start):
            raise ConfigError(f"START:STOP:STEP needs step > 0 and stop >= start, got '{value}'")
        span = (stop - start) / step  # infinite for -1e308:1e308:1 or a step of 1e-320
        if not math.isfinite(span) or span + 1 > MAX_GRID:
            raise ConfigError(f"'{value}' gives {span + 1:.3g} points; at most {MAX_GRID}")
        count = math.floor(span + 1e-9) + 1
        return [start + step * i for i in range(count)]
    points = [parse_number(v) for v in split_list(value, spaces=True)]
    if not points:
        raise ConfigError("names no position")
    return points
