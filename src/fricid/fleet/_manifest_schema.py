"""The fleet manifest's columns and their checks, from its JSON Schema.

``fricid/schemas/manifest.schema.json`` (:data:`SCHEMA`) is the one description of the
manifest: every column (:data:`FIELDS`), its type, range or choices, its group (``core``,
``fit``, ``extract``, ``reader``, ``robot``), the quantity of its unit (``x-quantity``), how a
text cell is read (``x-text``), the reader option a ``reader`` column fills (``x-option``,
default its name; every option of :data:`fricid.io.READER_OPTIONS` has its column, which a
test checks) and the message of a bad value (``x-message``); and the document's shape.
This module reads a cell into the JSON value it writes (through :mod:`fricid.io.options`,
the parsers the command line uses), validates a joint with ``jsonschema`` and turns the first
error into one :class:`~fricid.errors.DataError` naming the manifest, the row and the column.
What a schema cannot say is done here too: units in column labels, and model and method names
(their registries). :mod:`fricid.fleet.manifest` reads the files and builds the joints.
"""

from __future__ import annotations

import datetime as _dt
import functools
import json
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ..io.options import (
    parse_assignments,
    parse_grid,
    parse_number,
    parse_pairs,
    parse_ranges,
    split_list,
)
from ..units import UNITS, to_si

__all__ = [
    "FIELDS",
    "SCHEMA",
    "Entry",
    "Field",
    "describe_columns",
    "manifest_path",
    "read_entry",
    "resolve_key",
    "row_kind",
    "to_values",
    "validate",
    "validator",
]

_LABEL = re.compile(r"^\s*(?P<name>[^\[\]]*?)\s*(?:\[(?P<unit>[^\[\]]*)\])?\s*$")
_BOOLEANS = {"true": True, "yes": True, "1": True, "on": True}
_BOOLEANS.update({"false": False, "no": False, "0": False, "off": False})


@functools.cache
def _schema() -> dict[str, Any]:
    text = resources.files("fricid").joinpath("schemas", "manifest.schema.json").read_text("utf-8")
    return json.loads(text)


@functools.cache
def validator(part: str | None = None):
    """The schema's validator (``part`` None) or that of ``$defs/<part>``."""
    from jsonschema import Draft202012Validator as Validator

    root = Validator(_schema(), format_checker=Validator.FORMAT_CHECKER)
    return root if part is None else root.evolve(schema=_schema()["$defs"][part])


#: The manifest's JSON Schema (a dict; the file ``fricid/schemas/manifest.schema.json``).
SCHEMA: dict[str, Any] = _schema()


@dataclass(frozen=True)
class Field:
    """A manifest column, from the schema: its group, help, unit quantity and text form."""

    name: str
    group: str  # "core", "fit", "extract", "reader" or "robot"
    help: str
    quantity: str | None = None  # a unit is required in the column name
    text: str | None = None  # how a text cell is read (the schema's x-text)
    choices: tuple[str, ...] = ()
    option: str = ""  # the reader option it fills (the schema's x-option; default its name)


#: Every manifest column, by name (built from :data:`SCHEMA`).
FIELDS: dict[str, Field] = {
    name: Field(
        name,
        spec["x-group"],
        spec["description"],
        spec.get("x-quantity"),
        spec.get("x-text"),
        tuple(spec.get("enum", ())),
        spec.get("x-option", name),
    )
    for name, spec in SCHEMA["$defs"]["fields"]["properties"].items()
}

_GROUPS = {
    "core": "the joint",
    "fit": "fitting (fricid fit)",
    "extract": "extraction (fricid extract)",
    "reader": "reader options (fricid extract --format ...)",
    "robot": "a whole robot (fricid robot fit; a row with a urdf)",
}


def describe_columns() -> str:
    """The manifest's columns as text, one paragraph per group, from :data:`SCHEMA`: each
    column's name, its unit quantity (a unit in the column label) and its description. It is
    the ``fricid fleet --help`` text, so the help cannot drift from the schema."""
    paragraphs = []
    for group, title in _GROUPS.items():
        items = []
        for fld in FIELDS.values():
            if fld.group != group:
                continue
            unit = ""
            if fld.quantity:
                unit = f" [{fld.quantity} unit, e.g. {next(iter(UNITS[fld.quantity]))}]"
            items.append(f"{fld.name}{unit}: {fld.help}")
        paragraphs.append(f"Columns, {title}: " + "; ".join(items) + ".")
    return "\n\n".join(paragraphs)


_ALIASES = {"models": "model", "robot_id": "robot", "log_path": "log", "path": "log"}


# --------------------------------------------------------------------------- cells to values


def _read_cell(fld: Field, raw: Any) -> Any:
    """The JSON value a cell (text) or a YAML value writes, before validation.

    Raises ConfigError for a malformed list, grid or NAME=VALUE item (the parsers of
    :mod:`fricid.io.options`); anything else that is not of the column's type is left for the
    schema to refuse.
    """
    if isinstance(raw, _dt.date):
        return raw.isoformat()[:10]
    if isinstance(raw, str):
        raw = raw.strip()
        if fld.choices or fld.name in ("model", "method", "validate"):
            raw = raw.lower()
    kind = fld.text
    if kind == "number" and not isinstance(raw, bool):
        return parse_number(raw)
    if kind == "integer" and isinstance(raw, str):
        try:
            x = float(raw)
        except ValueError:
            return raw
        return int(x) if x.is_integer() else raw
    if kind == "boolean" and isinstance(raw, str):
        return _BOOLEANS.get(raw.lower(), raw)
    if kind == "list":
        return [str(v).strip().lower() for v in split_list(raw, spaces=True)]
    if kind == "names":  # names as written (a URDF's joint names are case-sensitive)
        items = split_list(raw, spaces=True)
        return [str(v).strip() if isinstance(v, str | int) else v for v in items]
    if kind == "grid":
        return parse_grid(raw)
    if kind == "assignments":
        return parse_assignments(raw)
    if kind == "ranges":
        return {k: list(v) for k, v in parse_ranges(raw).items()}
    if kind == "pairs":
        return {k: str(v).strip() for k, v in parse_pairs(raw).items()}
    return raw


def resolve_key(label: Any, file: Path, row: int | None) -> tuple[Field, str | None, str]:
    """A column label -> (field, unit, label); DataError for unknown names and bad units."""
    text = str(label)
    m = _LABEL.match(text)
    name = (m.group("name") if m else text).strip().lower()
    unit = m.group("unit").strip() if m and m.group("unit") is not None else None
    name = _ALIASES.get(name, name)
    if name not in FIELDS:
        raise DataError(
            f"unknown manifest column; known columns: {', '.join(FIELDS)}",
            file=file,
            row=row,
            column=text,
        )
    fld = FIELDS[name]
    if fld.quantity is None and unit is not None:
        raise DataError(f"'{name}' takes no unit, got [{unit}]", file=file, row=row, column=text)
    if fld.quantity is not None:
        allowed = ", ".join(UNITS[fld.quantity])
        if unit is None:
            raise DataError(
                f"'{name}' needs its unit in the column name, e.g. '{name} "
                f"[{next(iter(UNITS[fld.quantity]))}]' (units: {allowed})",
                file=file,
                row=row,
                column=text,
            )
        if unit not in UNITS[fld.quantity]:
            raise DataError(
                f"unknown {fld.quantity} unit '{unit}'; use one of: {allowed}",
                file=file,
                row=row,
                column=text,
            )
    return fld, unit, text


@dataclass
class Entry:
    """One mapping of a manifest (a joint, or the defaults) on its way to a spec."""

    row: int | None
    values: dict[str, Any] = field(default_factory=dict)  # name -> value read from the cell
    raw: dict[str, Any] = field(default_factory=dict)  # name -> the cell as written
    labels: dict[str, str] = field(default_factory=dict)  # name -> column label
    units: dict[str, str] = field(default_factory=dict)  # name -> unit of the label


def read_entry(mapping: Mapping[Any, Any], file: Path, row: int | None, into: Entry) -> Entry:
    """Read one mapping of column labels to cells into ``into`` (later values win)."""
    seen: dict[str, str] = {}
    for label, raw in mapping.items():
        if raw is None or (isinstance(raw, str) and not raw.strip()):
            continue
        fld, unit, text = resolve_key(label, file, row)
        if fld.name in seen:
            raise DataError(
                f"'{fld.name}' is given twice ('{seen[fld.name]}' and '{text}')",
                file=file,
                row=row,
                column=text,
            )
        seen[fld.name] = text
        try:
            into.values[fld.name] = _read_cell(fld, raw)
        except ConfigError as exc:
            raise DataError(str(exc), file=file, row=row, column=text) from None
        into.raw[fld.name], into.labels[fld.name] = raw, text
        if unit is None:
            into.units.pop(fld.name, None)
        else:
            into.units[fld.name] = unit
    return into


def _message(error: Any, entry: Entry, part: str) -> tuple[str, str]:
    """A schema error -> (message, column name): the schema's ``x-message`` for it."""
    instance, raw = entry.values, entry.raw
    where = list(error.path)
    name = str(where[0]) if where else ""
    if name in FIELDS:
        spec = SCHEMA["$defs"]["fields"]["properties"][name]
        return spec["x-message"].format(value=raw.get(name, error.instance)), name
    messages = SCHEMA["$defs"][part]["x-message"]
    if "then" in error.schema_path:
        return messages.get("then", error.message), "columns"
    if error.validator == "required":
        missing = next(r for r in error.validator_value if r not in instance)
        return messages.get("required", error.message).format(missing=missing), missing
    if error.validator == "not":
        name = next(n for n in ("robot", "joint", "log") if n in instance)
        return messages["not"].format(name=name), name
    return messages.get(error.validator, error.message), name


def validate(entry: Entry, part: str, file: Path) -> None:
    """Validate ``entry`` against ``$defs/<part>``; the first error (in column order, values
    before missing ones) as a DataError naming file, row and column."""
    errors = list(validator(part).iter_errors(entry.values))
    if not errors:
        return
    order = list(entry.values)

    def key(error: Any) -> tuple[int, int]:
        name = str(error.path[0]) if error.path else None
        return (0, order.index(name)) if name in entry.values else (1, 0)

    message, column = _message(min(errors, key=key), entry, part)
    label = entry.labels.get(column, column)
    raise DataError(message, file=file, row=entry.row, column=label)


def to_values(entry: Entry, file: Path) -> dict[str, Any]:
    """The entry's values with units applied, model and method names checked."""
    from ..models import get_model
    from ..optim import METHODS

    got = dict(entry.values)
    for name, unit in entry.units.items():
        converted = to_si(np.asarray(got[name], dtype=float), unit, FIELDS[name].quantity)
        got[name] = np.asarray(converted, dtype=float).tolist()
    try:
        if "model" in got:
            column = "model"
            for name in got["model"]:
                if name.strip().lower() != "auto":  # auto: the selection, as fricid fit does
                    get_model(name)  # ConfigError lists the models
            got["model"] = tuple(dict.fromkeys(got["model"]))
        if "method" in got and got["method"] not in METHODS:
            column = "method"
            raise ConfigError(
                f"unknown method '{entry.raw['method']}'; choose one of: {', '.join(METHODS)}"
            )
    except ConfigError as exc:
        raise DataError(str(exc), file=file, row=entry.row, column=entry.labels[column]) from None
    for name in ("seed", "max_evals", "chunk_rows", "median_window", "min_samples"):
        if name in got:
            got[name] = int(got[name])
    for name in ("robot", "joint", "log", "log_joint", "urdf"):
        if name in got:
            got[name] = str(got[name])
    return got


# --------------------------------------------------------------------------- kinds of row


#: The columns a robot row takes (the others are one joint's extraction, fit and reader).
_ROBOT_COLUMNS = frozenset(
    ("robot", "joint", "log", "date", *(n for n, f in FIELDS.items() if f.group == "robot"))
)


def row_kind(entry: Entry, own: set[str], file: Path) -> bool:
    """Whether ``entry`` is a robot row (it has a ``urdf``). The columns of the other kind of
    row are dropped when inherited from the defaults and refused when the row gives them
    (``own``); a robot row's ``joint`` (its record's name) defaults to ``arm``."""
    robot = "urdf" in entry.values
    for name in list(entry.values):
        if (name in _ROBOT_COLUMNS) if robot else FIELDS[name].group != "robot":
            continue
        if name not in own:
            for values in (entry.values, entry.raw, entry.labels, entry.units):
                values.pop(name, None)
            continue
        raise DataError(
            f"'{name}' is a column of one joint's identification; a robot row (one with a "
            f"'urdf') takes only: {', '.join(sorted(_ROBOT_COLUMNS))}"
            if robot
            else f"'{name}' is a column of a whole robot's row: give the row its 'urdf'",
            file=file,
            row=entry.row,
            column=entry.labels.get(name, name),
        )
    if robot and "joint" not in entry.values:
        entry.values["joint"] = entry.raw["joint"] = "arm"
        entry.labels["joint"] = "joint"
    return robot


def manifest_path(text: str, entry: Entry, column: str, file: Path) -> Path:
    """A path of the manifest (``log``, ``urdf``), absolute: relative to its folder."""
    if "\0" in text:
        raise DataError(
            "a path cannot hold a NUL character",
            file=file,
            row=entry.row,
            column=entry.labels.get(column, column),
        )
    path = Path(text).expanduser()
    if not path.is_absolute():
        path = file.parent / path
    return Path(os.path.abspath(path))
