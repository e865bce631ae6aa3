"""The Maxon EPOS Studio data-recorder CSV as text: its ``key:;value`` header, its data rows
(padding, decimal commas and bad rows of spreadsheet re-saves) and the recording they make.
:mod:`fricid.io.epos` turns a recording into a :class:`~fricid.samples.RawLog`.
"""

from __future__ import annotations

import logging
import re
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..errors import DataError, DataQualityWarning, user_stacklevel
from ._files import read_capped

logger = logging.getLogger("fricid.io.epos")

FORMAT = "maxon-epos-recorder"

_HEADER = re.compile(r"^(?P<key>[^;]*?):(?:;(?P<value>.*))?$")
_NUMBER_START = r"^\s*[+-]?(?:\d|\.\d)"
# torque as a fraction of the nominal torque
_TORQUE_FRACTION = {"%": 1e-2, "‰": 1e-3, "permille": 1e-3, "per mille": 1e-3}
_COUNT_UNITS = ("qc", "inc", "counts")
_TIME_ALIASES = {"µs": "us", "μs": "us", "sec": "s"}
_QUANTITIES = ("position", "velocity", "torque", "current")
_NOT_ACTUAL = ("demand", "target", "command", "setpoint", "set value", "window")


@dataclass(frozen=True)
class _Recording:
    """An EPOS export as text: header, channel names, units and the numeric block."""

    header: dict[str, Any]
    channels: list[str]  # [time, channel 1, ...]
    units: list[str]
    units_line: int
    data: np.ndarray  # (n, channels)
    lines: np.ndarray  # (n,) 1-based line number of each data row
    skipped: list[dict[str, Any]]  # bad rows dropped by skip_bad_rows


def _read_text(path: Path) -> list[str]:
    raw = read_capped(path, what="EPOS recording")
    for encoding in ("utf-8-sig", "cp1252"):
        try:
            text = raw.decode(encoding)
            break
        except UnicodeDecodeError:
            continue
    else:  # pragma: no cover - cp1252 fails only on five undefined bytes
        text = raw.decode("latin-1")
    return _unpad([line.rstrip("\r") for line in text.split("\n")])


_PADDING = re.compile(r"(?:\s*[;,])+\s*$")


def _unpad(lines: list[str]) -> list[str]:
    """Undo a spreadsheet's re-save: ``,`` as the only separator becomes ``;``, and when the
    channel line ends in empty fields (``...averaged,,``) every line loses its trailing empty
    fields (``-1200,,`` -> ``-1200``). A comma inside a value (``12,5``) is kept, and so
    reported as a malformed number."""
    if not any(";" in line for line in lines) and any(line.startswith(",") for line in lines):
        lines = [line.replace(",", ";") for line in lines]
    channel = next((line for line in lines if line.startswith(";")), "")
    if channel.rstrip().endswith(","):
        lines = [_PADDING.sub("", line) for line in lines]
    return lines


def _fields(line: str) -> list[str]:
    """``;``-separated fields, trailing empty ones dropped."""
    fields = [f.strip() for f in line.split(";")]
    while len(fields) > 1 and fields[-1] == "":
        fields.pop()
    return fields


#: Skipped lines quoted in the one warning per file.
_SKIPPED_SHOWN = 3


def _warn_skipped(path: Path, what: str, skipped: list[tuple[int, str]]) -> None:
    """One warning line for all the lines of one kind skipped in a file: count, first ones."""
    if not skipped:
        return
    shown = "; ".join(f"line {n}: {text[:60]!r}" for n, text in skipped[:_SKIPPED_SHOWN])
    more = f"; and {len(skipped) - _SKIPPED_SHOWN} more" if len(skipped) > _SKIPPED_SHOWN else ""
    plural = "s" if len(skipped) > 1 else ""
    logger.warning("%s: skipped %d %s line%s (%s%s)", path, len(skipped), what, plural, shown, more)


def _parse_header(lines: list[str], path: Path) -> tuple[dict[str, Any], int]:
    """The ``Key:;value`` block as a dict, and the index of the channel line."""
    header: dict[str, Any] = {}
    skipped: list[tuple[int, str]] = []
    for i, line in enumerate(lines):
        if line.startswith(";"):
            _warn_skipped(path, "unrecognised header", skipped)
            return header, i
        m = _HEADER.match(line.strip())
        if m and m.group("key").strip():
            key, value = m.group("key").strip(), (m.group("value") or "").strip()
            if key in header:  # repeated keys (Scale:) collect into a list
                old = header[key]
                header[key] = [*old, value] if isinstance(old, list) else [old, value]
            else:
                header[key] = value
        elif line.strip():
            skipped.append((i + 1, line))
    raise DataError(
        "no channel line (';<channel name>;...', naming the recorded channels) found; "
        "is this an EPOS Studio data-recorder export?",
        file=path,
    )


_COMMA_NUMBER = r"^\s*[+-]?\d*,\d+(?:[eE][+-]?\d+)?\s*$"


def _decimal_comma(text: pd.DataFrame) -> bool:
    """Whether the data cells write a decimal comma: no cell holds a point, and a cell reads
    as a number with a comma for it ('0,000', '-32,6'). The fields are ';'-separated, so a
    comma within one is no separator (a spreadsheet in a European locale re-saves EPOS Studio's
    '51.200' as '51,200')."""
    cells = text.stack().astype(str)
    return not cells.str.contains(".", regex=False).any() and bool(
        cells.str.match(_COMMA_NUMBER).any()
    )


def _parse_data(
    lines: list[str],
    start: int,
    channels: list[str],
    path: Path,
    skip_bad_rows: bool,
    quiet: bool = False,
) -> tuple[np.ndarray, np.ndarray, list[dict[str, Any]]]:
    """Numeric rows from ``lines[start:]``, their line numbers, and the bad rows skipped.

    Text lines are skipped with a warning (none when ``quiet``: a look before the read). A row
    of the wrong width or with a malformed cell is an error naming its line and column, or with
    ``skip_bad_rows`` dropped and listed as ``{"line", "column", "text"}``.
    """
    body = pd.Series(lines[start:], index=np.arange(start + 1, len(lines) + 1), dtype=object)
    body = body[body.str.strip() != ""].str.strip().str.rstrip(";").str.strip()
    is_row = body.str.match(_NUMBER_START)
    if not quiet:
        _warn_skipped(path, "non-numeric", list(body[~is_row].items()))
    rows = body[is_row]
    if rows.empty:
        raise DataError("no data rows after the units line", file=path)
    k = len(channels)
    skipped: list[dict[str, Any]] = []
    widths = rows.str.count(";").to_numpy() + 1
    if (widths != k).any():
        i = int(np.flatnonzero(widths != k)[0])
        if not skip_bad_rows:
            raise DataError(
                f"row has {widths[i]} fields, expected {k} ({', '.join(channels)})",
                file=path,
                row=int(rows.index[i]),
            )
        for line_no, text in rows[widths != k].items():
            skipped.append({"line": int(line_no), "column": None, "text": str(text)})
        rows = rows[widths == k]
    text = rows.str.split(";", expand=True)
    if _decimal_comma(text):  # a spreadsheet's European re-save: ';' between, ',' within
        text = text.apply(lambda column: column.str.replace(",", ".", regex=False))
    data = np.empty((len(rows), k))
    for j in range(k):
        data[:, j] = pd.to_numeric(text[j].str.strip(), errors="coerce").to_numpy(float)
    bad = ~np.isfinite(data)
    if bad.any() and not skip_bad_rows:
        i = int(np.flatnonzero(bad.any(axis=1))[0])
        j = int(np.flatnonzero(bad[i])[0])
        raise DataError(
            f"malformed number {text.iat[i, j]!r}",
            file=path,
            row=int(rows.index[i]),
            column=channels[j],
        )
    for i in np.flatnonzero(bad.any(axis=1)):
        j = int(np.flatnonzero(bad[i])[0])
        skipped.append(
            {"line": int(rows.index[i]), "column": channels[j], "text": str(text.iat[i, j])}
        )
    good = ~bad.any(axis=1)
    if not good.any():
        raise DataError("no readable data rows after the units line", file=path)
    skipped.sort(key=lambda item: item["line"])
    return data[good], rows.index.to_numpy()[good], skipped


def _warn_bad_rows(path: Path, skipped: list[dict[str, Any]]) -> None:
    """One :class:`~fricid.errors.DataQualityWarning` counting and listing skipped rows."""
    if not skipped:
        return
    listed = "; ".join(
        f"line {s['line']}"
        + (f", column '{s['column']}'" if s["column"] else "")
        + f": {s['text']!r}"
        for s in skipped
    )
    warnings.warn(
        f"{path}: skipped {len(skipped)} bad row{'s' if len(skipped) > 1 else ''} "
        f"(--skip-bad-rows): {listed}",
        DataQualityWarning,
        stacklevel=user_stacklevel(),
    )


def _parse(path: Path, skip_bad_rows: bool = False, quiet: bool = False) -> _Recording:
    lines = _read_text(path)
    if not any(line.strip() for line in lines):
        raise DataError("empty file", file=path)
    header, at = _parse_header(lines, path)
    names = _fields(lines[at])
    channels = ["time", *names[1:]]
    if len(channels) < 2:
        raise DataError("the channel line names no channels", file=path, row=at + 1)
    if at + 1 >= len(lines) or re.match(_NUMBER_START, lines[at + 1]):
        raise DataError(
            "no units line (e.g. 'ms;rpm;%') after the channel line; units must be explicit",
            file=path,
            row=at + 2,
        )
    units = _fields(lines[at + 1])
    if len(units) < len(channels):
        raise DataError(
            f"the units line has {len(units)} units for {len(channels)} columns",
            file=path,
            row=at + 2,
        )
    data, line_numbers, skipped = _parse_data(lines, at + 2, channels, path, skip_bad_rows, quiet)
    return _Recording(header, channels, units[: len(channels)], at + 2, data, line_numbers, skipped)
