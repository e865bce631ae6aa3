"""The JSON Schema of the model file (``fricid/schemas/model.schema.json``).

``FittedModel.load`` validates every file against it; these helpers expose the schema to
users and tools (editors, CI checks of model files written by hand).
"""

from __future__ import annotations

import json
from importlib.resources import as_file, files
from pathlib import Path
from typing import Any

from ..fitted import SCHEMA_VERSION, _validate_schema

__all__ = ["SCHEMA_VERSION", "model_schema", "schema_path", "validate_model_dict"]


def model_schema() -> dict[str, Any]:
    """The model file's JSON Schema (draft 2020-12) as a dict."""
    text = files("fricid").joinpath("schemas", "model.schema.json").read_text(encoding="utf-8")
    return json.loads(text)


def schema_path() -> Path:
    """A filesystem path of the schema file (inside the installed package)."""
    with as_file(files("fricid").joinpath("schemas", "model.schema.json")) as path:
        return Path(path)


def validate_model_dict(d: dict[str, Any], source: str | None = None) -> None:
    """Raise :class:`~fricid.errors.DataError` naming ``source`` and the first failing field
    if ``d`` does not match the schema."""
    _validate_schema(d, source)
