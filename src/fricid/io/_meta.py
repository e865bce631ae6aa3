"""Metadata text: ``# key: value`` comment values and the JSON that carries free-form meta.

A comment value is written as plain text when that is unambiguous (printable, no leading or
trailing space, not starting with a double quote) and as a JSON string otherwise, so any
string, including newlines and lone surrogates, survives a write and read unchanged.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import PurePath
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError

__all__ = ["decode_text", "dumps_meta", "encode_text", "loads_meta"]


def encode_text(value: str) -> str:
    """A string as the value of a ``# key: value`` comment line.

    Parameters
    ----------
    value : str
        Any string.

    Returns
    -------
    str
        ``value`` itself when unambiguous (non-empty, printable, no surrounding blanks, not
        starting with a double quote), else its JSON string literal (ASCII only).

    Examples
    --------
    >>> encode_text("paper1"), encode_text("two\\nlines")
    ('paper1', '"two\\\\nlines"')
    """
    plain = (
        value != "" and value == value.strip() and value.isprintable() and not value.startswith('"')
    )
    return value if plain else json.dumps(value, ensure_ascii=True)


def decode_text(text: str, *, file: str | os.PathLike[str], key: str) -> str:
    """The string a comment value stands for: the inverse of :func:`encode_text`.

    Parameters
    ----------
    text : str
        The value, already stripped of surrounding blanks.
    file : str or os.PathLike
        The file it was read from (for messages).
    key : str
        The metadata key (for messages).

    Returns
    -------
    str
        ``text`` itself, or the string its JSON literal encodes when it starts with ``"``.

    Raises
    ------
    DataError
        A quoted value that is not a valid JSON string.
    """
    if not text.startswith('"'):
        return text
    try:
        value = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        raise DataError(
            f"metadata '{key}' is not a valid quoted string: {exc}", file=file
        ) from None
    if not isinstance(value, str):
        raise DataError(f"metadata '{key}' must be a string, got {value!r}", file=file)
    return value


def _default(obj: Any) -> Any:
    """JSON for what :mod:`json` does not know: numpy scalars and arrays, paths."""
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, PurePath):
        return str(obj)
    raise TypeError(f"{type(obj).__name__} is not JSON-serialisable")


def dumps_meta(meta: Mapping[str, Any]) -> str:
    """Free-form metadata as one line of JSON.

    Parameters
    ----------
    meta : mapping
        JSON-serialisable values; numpy scalars and arrays become plain numbers and lists,
        paths become strings.

    Returns
    -------
    str
        One line: readable unicode where every character is printable, else ASCII escapes.

    Raises
    ------
    ConfigError
        A value that cannot be written as JSON.
    """
    try:
        text = json.dumps(dict(meta), ensure_ascii=False, default=_default)
    except (TypeError, ValueError) as exc:
        raise ConfigError(
            f"meta must be JSON-serialisable to be written to a file: {exc}"
        ) from None
    # readable unicode, but escape what could break a line or the UTF-8 encoding
    return text if text.isprintable() else json.dumps(dict(meta), default=_default)


def loads_meta(text: str, *, file: str | os.PathLike[str]) -> dict[str, Any]:
    """Parse the free-form metadata written by :func:`dumps_meta`.

    Parameters
    ----------
    text : str
        One line of JSON.
    file : str or os.PathLike
        The file it was read from (for messages).

    Returns
    -------
    dict
        The metadata.

    Raises
    ------
    DataError
        Invalid JSON, or JSON that is not an object.
    """
    try:
        meta = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        raise DataError(f"metadata 'meta' is not valid JSON: {exc}", file=file) from None
    if not isinstance(meta, dict):
        raise DataError(f"metadata 'meta' must be a JSON object, got {meta!r}", file=file)
    return meta
