"""Strict reading of JSON files that may come from strangers (model files).

A JSON file travels between people (a colleague's fit, a fleet's results), so reading one
must neither crash nor be steered by its content. :func:`read_json` reads at most
:data:`MAX_BYTES`, refuses text that is not UTF-8, nesting deeper than :data:`MAX_DEPTH`
(measured by an iterative scan of the bytes before the parser, which recurses, sees them),
the constants ``NaN``/``Infinity``, numbers that overflow double precision (``1e400``) or
exceed :data:`MAX_MAGNITUDE`, and repeated keys in one object; :func:`check_document` then
bounds the sizes of the parsed document (items per array, properties per object,
characters per string, values in all) and refuses text that is not valid Unicode (lone
surrogates). Every failure is one :class:`~fricid.errors.DataError` line naming the file
given and, where known, the line or the field.

The limits are generous for any file fricid writes (a model file is kilobytes to a few
megabytes) and small enough that a hostile file cannot exhaust memory or time.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import DataError
from ._files import read_capped

__all__ = [
    "MAX_BYTES",
    "MAX_DEPTH",
    "MAX_ITEMS",
    "MAX_MAGNITUDE",
    "MAX_PROPERTIES",
    "MAX_STRING",
    "MAX_VALUES",
    "check_document",
    "one_line",
    "read_json",
    "write_json",
]

#: Largest file read: 64 MiB.
MAX_BYTES = 64 * 2**20
#: Deepest nesting of arrays and objects (the top-level object is level 1).
MAX_DEPTH = 64
#: Most items in one array.
MAX_ITEMS = 1_000_000
#: Most properties (keys) in one object.
MAX_PROPERTIES = 10_000
#: Longest string or key, in characters.
MAX_STRING = 1_000_000
#: Most values (numbers, strings, booleans, nulls, arrays, objects) in one document.
MAX_VALUES = 4_000_000
#: Largest magnitude of a number: finite, with room to compute with it.
MAX_MAGNITUDE = 1e300

# A JSON string (escapes included), for the depth scan: brackets inside strings do not nest.
_STRING = re.compile(rb'"[^"\\]*(?:\\.[^"\\]*)*"', re.DOTALL)
# Every byte except the four brackets, deleted before the depth scan.
_NOT_BRACKETS = bytes(b for b in range(256) if b not in b"[]{}")
_CHUNK = 1 << 20
# Characters that would break a one-line message.
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u2028\u2029]")


class _Refused(ValueError):
    """Raised by the parser's hooks; its text becomes the DataError's message."""


class _BadNumber(str):
    """The text of a number the parser refused, kept to name its field after parsing."""

    __slots__ = ()


def one_line(text: str) -> str:
    """``text`` with control characters and line separators written as escapes."""
    return _CONTROL.sub(lambda m: repr(m.group())[1:-1], text)


def _max_depth(data: bytes) -> int:
    """The deepest nesting of ``[`` and ``{`` outside strings, by a scan without recursion."""
    brackets = _STRING.sub(b"", data).translate(None, _NOT_BRACKETS)
    codes = np.frombuffer(brackets, dtype=np.uint8)
    level, deepest = 0, 0
    for start in range(0, codes.size, _CHUNK):
        chunk = codes[start : start + _CHUNK]
        steps = np.where((chunk == ord("[")) | (chunk == ord("{")), 1, -1).astype(np.int64)
        levels = level + np.cumsum(steps)
        deepest = max(deepest, int(levels.max()))
        level = int(levels[-1])
    return deepest


def _float(text: str) -> float | _BadNumber:
    value = float(text)
    return value if abs(value) <= MAX_MAGNITUDE else _BadNumber(text)


def _int(text: str) -> int | _BadNumber:
    # int() of thousands of digits is slow or refused; anything past 300 digits is out of range
    if len(text) > 302:
        return _BadNumber(text[:20] + "...")
    value = int(text)
    return value if abs(value) <= MAX_MAGNITUDE else _BadNumber(text)


def _object(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out = dict(pairs)
    if len(out) != len(pairs):
        seen: set[str] = set()
        dup = next(k for k, _ in pairs if k in seen or seen.add(k))  # type: ignore[func-returns-value]
        raise _Refused(f"the key {one_line(repr(dup))[:80]} appears twice in one object")
    return out


def write_json(path: str | PathLike[str], doc: Any) -> Path:
    """Write ``doc`` as indented JSON with a final newline, atomically
    (:func:`fricid.io.atomic.atomic_write`); the counterpart of :func:`read_json`."""
    from .atomic import atomic_write

    path = Path(path)
    with atomic_write(path, "w") as fh:
        json.dump(doc, fh, indent=2)
        fh.write("\n")
    return path


def read_json(path: str | PathLike[str], *, what: str = "JSON file") -> Any:
    """Read and parse a JSON file strictly (see the module notes).

    Parameters
    ----------
    path : str or os.PathLike
        The file, named in every error as given.
    what : str, default "JSON file"
        What the file is, for messages ("the model file").

    Returns
    -------
    object
        The parsed document, checked by :func:`check_document`.

    Raises
    ------
    DataError
        The file cannot be read or is not a regular file (a folder, a device, a FIFO),
        exceeds a limit, is not UTF-8 or not valid JSON, or holds a
        value that is not finite in double precision.
    """
    data = read_capped(path, MAX_BYTES, what=what)
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    depth = _max_depth(data)
    if depth > MAX_DEPTH:
        raise DataError(
            f"not a {what}: arrays and objects nested {depth} deep (at most {MAX_DEPTH})",
            file=path,
        )
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise DataError(
            f"not UTF-8 text: byte 0x{data[exc.start]:02x} at offset {exc.start}",
            file=path,
            row=data.count(b"\n", 0, exc.start) + 1,
        ) from None
    try:
        doc = json.loads(
            text,
            parse_float=_float,
            parse_int=_int,
            parse_constant=_BadNumber,
            object_pairs_hook=_object,
        )
    except json.JSONDecodeError as exc:
        raise DataError(
            f"not valid JSON: {exc.msg}: character {exc.colno} of the line",
            file=path,
            row=exc.lineno,
        ) from None
    except _Refused as exc:
        raise DataError(f"not a valid {what}: {exc}", file=path) from None
    except (ValueError, RecursionError) as exc:  # int() limits; nesting the scan missed
        raise DataError(f"not valid JSON: {one_line(str(exc))[:200]}", file=path) from None
    check_document(doc, path)
    return doc


def _field(path: tuple[Any, ...]) -> str:
    text = "/".join(str(p) for p in path) or "(top level)"
    return one_line(text if len(text) <= 120 else text[:117] + "...")


def check_document(doc: Any, source: str | PathLike[str] | None = None) -> None:
    """Check the sizes and the values of a parsed JSON document, without recursion.

    Parameters
    ----------
    doc : object
        The document: dicts, lists (or tuples), strings, numbers, booleans and None.
    source : str or os.PathLike, optional
        The file it came from, named in the error.

    Raises
    ------
    DataError
        Naming the first field that is nested deeper than :data:`MAX_DEPTH`, has more than
        :data:`MAX_ITEMS` items, :data:`MAX_PROPERTIES` keys or :data:`MAX_STRING`
        characters, holds a number that is not finite or exceeds :data:`MAX_MAGNITUDE`, or
        text that is not valid Unicode; or when the document holds more than
        :data:`MAX_VALUES` values.
    """
    stack: list[tuple[Any, tuple[Any, ...]]] = [(doc, ())]
    count = 0
    while stack:
        value, path = stack.pop()
        count += 1
        if count > MAX_VALUES:
            raise DataError(f"more than {MAX_VALUES} values in one file", file=source)
        if len(path) >= MAX_DEPTH and isinstance(value, Mapping | list | tuple):
            raise DataError(
                f"field '{_field(path[:8])}/...': nested deeper than {MAX_DEPTH} levels",
                file=source,
            )
        problem = None
        if isinstance(value, _BadNumber):
            if value in ("NaN", "Infinity", "-Infinity"):
                problem = f"{value} is not a finite number"
            else:
                problem = f"the number {value[:40]} exceeds {MAX_MAGNITUDE:g} in magnitude"
        elif isinstance(value, str):
            problem = _text_problem(value)
        elif isinstance(value, bool) or value is None:
            pass
        elif isinstance(value, int | float | np.integer | np.floating):
            if not math.isfinite(value) or abs(value) > MAX_MAGNITUDE:
                problem = f"the number {value!r} is not finite or exceeds {MAX_MAGNITUDE:g}"
        elif isinstance(value, Mapping):
            if len(value) > MAX_PROPERTIES:
                problem = f"more than {MAX_PROPERTIES} properties"
            else:
                for key, item in value.items():
                    if not isinstance(key, str):
                        problem = f"a key that is not text: {one_line(repr(key))[:40]}"
                        break
                    key_problem = _text_problem(key)
                    if key_problem:
                        problem = f"a key: {key_problem}"
                        break
                    stack.append((item, (*path, key)))
        elif isinstance(value, list | tuple):
            if len(value) > MAX_ITEMS:
                problem = f"more than {MAX_ITEMS} items"
            else:
                stack.extend((item, (*path, i)) for i, item in enumerate(value))
        else:
            problem = f"a {type(value).__name__}, not a JSON value"
        if problem:
            raise DataError(f"field '{_field(path)}': {problem}", file=source)


def _text_problem(text: str) -> str | None:
    if len(text) > MAX_STRING:
        return f"text longer than {MAX_STRING} characters"
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return "text that is not valid Unicode (a lone surrogate)"
    return None
