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
    """A comment value: ``value`` itself when unambiguous, else a JSON string literal."""
    plain = (
        value != "" and value == value.strip() and value.isprintable() and not value.startswith('"')
    )
    return value if plain else json.dumps(value, ensure_ascii=True)


def decode_text(text: str, *, file: str | os.PathLike[str], key: str) -> str:
    """Inverse of :func:`encode_text` (``text`` already stripped of surrounding blanks)."""
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
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, PurePath):
        return str(obj)
    raise TypeError(f"{type(obj).__name__} is not JSON-serialisable")


def dumps_meta(meta: Mapping[str, Any]) -> str:
    """Free-form metadata as one line of JSON (numpy values become plain numbers)."""
    try:
        text = json.dumps(dict(meta), ensure_ascii=False, default=_default)
    except (TypeError, ValueError) as exc:
        raise ConfigError(
            f"meta must be JSON-serialisable to be written to a file: {exc}"
        ) from None
    # readable unicode, but escape what could break a line or the UTF-8 encoding
    return text if text.isprintable() else json.dumps(dict(meta), default=_default)


def loads_meta(text: str, *, file: str | os.PathLike[str]) -> dict[str, Any]:
    """Parse the free-form metadata written by :func:`dumps_meta`."""
    try:
        meta = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        raise DataError(f"metadata 'meta' is not valid JSON: {exc}", file=file) from None
    if not isinstance(meta, dict):
        raise DataError(f"metadata 'meta' must be a JSON object, got {meta!r}", file=file)
    return meta
