"""The fleet manifest: one row per joint, CSV or YAML, validated before any work starts.

CSV
    A header row, then one row per joint; ``#`` lines and blank lines are skipped, an empty
    cell takes the default. A cell with several values separates them with ``;`` (models may
    also use spaces): ``model`` ``msk;vlt``, ``fix`` ``delta=1;xi=2``, ``bound``
    ``w_s=0.001:1``, ``columns`` ``time=t;velocity=dq;torque=tau``, ``positions``
    ``-60:-20:4`` (START:STOP:STEP, stop included) or ``-60;-40;-20``.
YAML
    A mapping with ``joints:`` (a list of mappings, one per joint) and optionally
    ``defaults:`` (a mapping applied to every joint), or just the list. Lists and mappings
    are written natively.

Every dimensional value names its unit in the column name, as fricid's tables do:
``positions [deg]``, ``bin_halfwidth [deg]``, ``settle_time [s]``, ``temperature [degC]``,
``torque_constant [N m/A]``, ``nominal_torque [mN m]``, ``load [N m]``. Log paths are relative
to the manifest's folder. Every error names the manifest, the row (its line) and the column.
"""

from __future__ import annotations

import csv
import datetime as _dt
import io
import math
import os
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ..pipeline import DIRECTIONS, READER_OPTIONS, READERS, SAMPLE_SETS
from ..units import UNITS, to_si

__all__ = ["FIELDS", "Field", "JointSpec", "Manifest", "read_manifest"]

_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")
_LABEL = re.compile(r"^\s*(?P<name>[^\[\]]*?)\s*(?:\[(?P<unit>[^\[\]]*)\])?\s*$")
_TRUE = ("true", "yes", "1", "on")
_FALSE = ("false", "no", "0", "off")


# --------------------------------------------------------------------------- value parsers


def _text(value: Any) -> str:
    if isinstance(value, bool | int | float | str):
        return str(value).strip()
    raise ValueError(f"expected a single value, got {type(value).__name__}")


def _items(value: Any, spaces: bool = False) -> list[Any]:
    """A YAML list as is; a text cell split on ';' (or ',', and spaces if ``spaces``)."""
    if isinstance(value, list | tuple):
        return list(value)
    pattern = r"[;,\s]+" if spaces else r"[;,]"
    return [p.strip() for p in re.split(pattern, _text(value)) if p.strip()]


def _pairs(value: Any) -> dict[str, Any]:
    """``{"a": 1}`` (YAML) or ``"a=1; b=2"`` (a cell) -> dict."""
    if isinstance(value, Mapping):
        return {str(k).strip(): v for k, v in value.items()}
    out: dict[str, Any] = {}
    for part in _text(value).split(";"):
        if not part.strip():
            continue
        name, sep, rest = part.partition("=")
        if not sep or not name.strip() or not rest.strip():
            raise ValueError(f"expected NAME=VALUE items separated by ';', got '{part.strip()}'")
        out[name.strip()] = rest.strip()
    return out


def _float(value: Any) -> float:
    try:
        x = float(value) if not isinstance(value, bool) else math.nan
    except (TypeError, ValueError):
        raise ValueError(f"'{value}' is not a number") from None
    if not math.isfinite(x):
        raise ValueError(f"'{value}' is not a finite number")
    return x


def _positive(value: Any) -> float:
    x = _float(value)
    if x <= 0:
        raise ValueError(f"must be > 0, got {value!r}")
    return x


def _int(value: Any, low: int) -> int:
    if isinstance(value, bool):
        raise ValueError(f"'{value}' is not an integer")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"'{value}' is not an integer") from None
    if not x.is_integer() or x < low:
        raise ValueError(f"must be an integer >= {low}, got {value!r}")
    return int(x)


def _bool(value: Any) -> bool:
    if isinstance(value, bool):
        return value
    text = _text(value).lower()
    if text in _TRUE:
        return True
    if text in _FALSE:
        return False
    raise ValueError(f"expected true or false, got '{value}'")


def _choice(choices: tuple[str, ...]) -> Callable[[Any], str]:
    def parse(value: Any) -> str:
        text = _text(value).lower()
        if text not in choices:
            raise ValueError(f"must be one of: {', '.join(choices)}; got '{value}'")
        return text

    return parse


def _identifier(value: Any) -> str:
    text = _text(value)
    if not _ID.match(text):
        raise ValueError(
            f"'{text}' is not a usable name: letters, digits, '.', '_' and '-' only, "
            "starting with a letter or digit (it names files)"
        )
    return text


def _date(value: Any) -> str:
    if isinstance(value, _dt.date):
        return value.isoformat()[:10]
    try:
        return _dt.date.fromisoformat(_text(value)).isoformat()
    except ValueError:
        raise ValueError(f"'{value}' is not a date YYYY-MM-DD") from None


def _models(value: Any) -> tuple[str, ...]:
    from ..models import get_model

    names = [str(n).strip().lower() for n in _items(value, spaces=True)]
    if not names:
        raise ValueError("names no model")
    for name in names:
        get_model(name)  # ConfigError lists the models
    return tuple(dict.fromkeys(names))


def _method(value: Any) -> str:
    from ..optim import METHODS

    text = _text(value).lower()
    if text not in METHODS:
        raise ValueError(f"unknown method '{value}'; choose one of: {', '.join(METHODS)}")
    return text


def _assignments(value: Any) -> dict[str, float]:
    return {name: _float(v) for name, v in _pairs(value).items()}


def _ranges(value: Any) -> dict[str, list[float]]:
    out: dict[str, list[float]] = {}
    for name, v in _pairs(value).items():
        parts = v if isinstance(v, list | tuple) else str(v).split(":")
        if len(parts) != 2:
            raise ValueError(f"expected NAME=LOW:HIGH, got '{name}={v}'")
        lo, hi = _float(parts[0]), _float(parts[1])
        if not lo < hi:
            raise ValueError(f"'{name}' needs LOW < HIGH, got {lo} and {hi}")
        out[name] = [lo, hi]
    return out


def _mapping(value: Any) -> dict[str, str]:
    out = {name: _text(v) for name, v in _pairs(value).items()}
    if not out:
        raise ValueError("is empty")
    return out


def _positions(value: Any) -> list[float]:
    """``"-60:-20:4"`` (start:stop:step, stop included), a ';' list, or a YAML list."""
    if isinstance(value, str) and ":" in value:
        try:
            start, stop, step = (float(p) for p in value.split(":"))
        except ValueError:
            raise ValueError(f"expected START:STOP:STEP or a list, got '{value}'") from None
        if not (step > 0 and stop >= start):
            raise ValueError(f"START:STOP:STEP needs step > 0 and stop >= start, got '{value}'")
        n = (stop - start) / step + 1e-9 + 1
        if not n <= 10_000:  # checked before allocating (NaN and inf included)
            raise ValueError(f"START:STOP:STEP gives more than 10000 positions, got '{value}'")
        return [start + step * i for i in range(math.floor(n))]
    values = [_float(v) for v in _items(value, spaces=True)]
    if not values:
        raise ValueError("names no position")
    return values


# --------------------------------------------------------------------------- the fields


@dataclass(frozen=True)
class Field:
    """A manifest column: how to parse it, where it goes, and the quantity of its unit."""

    name: str
    parse: Callable[[Any], Any]
    group: str  # "core", "fit", "extract" or "reader"
    help: str
    quantity: str | None = None  # a unit is required in the column name


def _f(name: str, parse: Callable[[Any], Any], group: str, doc: str, quantity: str | None = None):
    return Field(name, parse, group, doc, quantity)


#: Every manifest column, by name.
FIELDS: dict[str, Field] = {
    f.name: f
    for f in (
        _f("robot", _identifier, "core", "robot id (required)"),
        _f("joint", _identifier, "core", "joint name (required)"),
        _f("log", _text, "core", "log path, relative to the manifest (required)"),
        _f("date", _date, "core", "measurement date YYYY-MM-DD (default: the run's date)"),
        _f("reader", _choice(READERS), "core", "table (default), generic or epos"),
        _f("model", _models, "fit", "model name(s) (default stribeck)"),
        _f("method", _method, "fit", "optimiser (default lm)"),
        _f("seed", lambda v: _int(v, 0), "fit", "random seed (default 0)"),
        _f("max_evals", lambda v: _int(v, 1), "fit", "budget in model evaluations"),
        _f("direction", _choice(tuple(DIRECTIONS)), "fit", "samples kept (default all)"),
        _f("samples", _choice(SAMPLE_SETS), "fit", "auto, combined or by_direction"),
        _f("fix", _assignments, "fit", "NAME=VALUE (SI) held fixed"),
        _f("bound", _ranges, "fit", "NAME=LOW:HIGH (SI) search ranges"),
        _f("chunk_rows", lambda v: _int(v, 1), "core", "rows read at a time"),
        _f("positions", _positions, "extract", "position bin centres", "position"),
        _f("bin_halfwidth", _positive, "extract", "half width of a bin", "position"),
        _f("median_window", lambda v: _int(v, 1), "extract", "odd running-median window"),
        _f("gravity", _choice(("fit", "none")), "extract", "fit or none"),
        _f("velocity_tolerance", _positive, "extract", "relative steady band"),
        _f("settle_time", _float, "extract", "time trimmed at each end", "time"),
        _f("min_samples", lambda v: _int(v, 1), "extract", "shortest steady part"),
        _f("velocity_rtol", _positive, "extract", "relative set-point gap"),
        _f("temperature_atol", _positive, "extract", "set-point gap [degC, a difference]"),
        _f("columns", _mapping, "reader", "generic: quantity=column"),
        _f("units", _mapping, "reader", "generic: quantity=unit"),
        _f("torque_constant", _positive, "reader", "K for a current", "torque_constant"),
        _f("temperature", _float, "reader", "constant temperature", "temperature"),
        _f("flip_sign", _bool, "reader", "epos: negate motion and effort"),
        _f("nominal_torque", _positive, "reader", "epos: reference of %", "torque"),
        _f("counts_per_turn", _positive, "reader", "epos: encoder counts"),
        _f("pattern", _text, "reader", "epos folder: file pattern"),
        _f("load", _float, "reader", "epos folder: constant load", "torque"),
    )
}

_ALIASES = {"models": "model", "robot_id": "robot", "log_path": "log", "path": "log"}
_REQUIRED = ("robot", "joint", "log")
_DEFAULTS: dict[str, Any] = {
    "reader": "table",
    "model": ("stribeck",),
    "method": "lm",
    "seed": 0,
    "direction": "all",
    "samples": "auto",
}


# --------------------------------------------------------------------------- the joint spec


@dataclass(frozen=True, eq=False)
class JointSpec:
    """One joint of the fleet: where its log is and how to identify it.

    Attributes
    ----------
    robot, joint : its names (``key`` is ``"robot/joint"``).
    log : absolute path of the log (the manifest's relative path resolved).
    log_text : the path as the manifest writes it.
    row : the manifest line of the joint, for messages.
    date : measurement date (ISO), or None for the run's date.
    reader, reader_options : see :func:`fricid.pipeline.load_joint` (SI units).
    extract_options : options of :func:`fricid.extract.extract` (SI units).
    models, method, seed, max_evals, samples, direction, fixed, bounds : see
        :func:`fricid.pipeline.run_joint`.
    chunk_rows : rows read at a time (memory, not results).
    """

    robot: str
    joint: str
    log: Path
    log_text: str
    row: int | None = None
    date: str | None = None
    reader: str = "table"
    reader_options: dict[str, Any] = field(default_factory=dict)
    extract_options: dict[str, Any] = field(default_factory=dict)
    models: tuple[str, ...] = ("stribeck",)
    method: str = "lm"
    seed: int = 0
    max_evals: int | None = None
    samples: str = "auto"
    direction: str = "all"
    fixed: dict[str, float] = field(default_factory=dict)
    bounds: dict[str, list[float]] = field(default_factory=dict)
    chunk_rows: int = 1_000_000

    @property
    def key(self) -> str:
        return f"{self.robot}/{self.joint}"

    def settings(self) -> dict[str, Any]:
        """Everything that decides the results, JSON-ready (hashed to decide re-runs).

        The log's path, the date and ``chunk_rows`` are not settings: the log's content is
        hashed separately, and the others do not change the numbers.
        """
        return {
            "reader": self.reader,
            "reader_options": self.reader_options,
            "extract_options": self.extract_options,
            "models": list(self.models),
            "method": self.method,
            "seed": self.seed,
            "max_evals": self.max_evals,
            "samples": self.samples,
            "direction": self.direction,
            "fixed": self.fixed,
            "bounds": self.bounds,
        }

    def run_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :func:`fricid.pipeline.run_joint` for this joint."""
        return {
            "reader": self.reader,
            "reader_options": self.reader_options,
            "extract_options": self.extract_options,
            "models": self.models,
            "method": self.method,
            "seed": self.seed,
            "max_evals": self.max_evals,
            "samples": self.samples,
            "direction": self.direction,
            "fixed": self.fixed,
            "bounds": {k: (v[0], v[1]) for k, v in self.bounds.items()},
            "chunk_rows": self.chunk_rows,
        }


@dataclass(frozen=True, eq=False)
class Manifest:
    """A parsed manifest: its path and its joints, in file order."""

    path: Path
    joints: tuple[JointSpec, ...]

    def __len__(self) -> int:
        return len(self.joints)

    def __iter__(self):
        return iter(self.joints)


# --------------------------------------------------------------------------- parsing


def _resolve_key(label: Any, file: Path, row: int | None) -> tuple[Field, str | None, str]:
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


def _value(fld: Field, unit: str | None, raw: Any, file: Path, row: int | None, label: str):
    try:
        value = fld.parse(raw)
        if unit is not None:
            converted = to_si(np.asarray(value, dtype=float), unit, fld.quantity)
            value = np.asarray(converted, dtype=float).tolist()
    except (ValueError, ConfigError) as exc:
        raise DataError(str(exc), file=file, row=row, column=label) from None
    return value


def _parse_entry(
    entry: Mapping[Any, Any], file: Path, row: int | None, into: dict[str, Any]
) -> dict[str, Any]:
    """Parse one mapping of column labels to raw values into ``into`` (name -> value)."""
    seen: dict[str, str] = {}
    for label, raw in entry.items():
        if raw is None or (isinstance(raw, str) and not raw.strip()):
            continue
        fld, unit, text = _resolve_key(label, file, row)
        if fld.name in seen:
            raise DataError(
                f"'{fld.name}' is given twice ('{seen[fld.name]}' and '{text}')",
                file=file,
                row=row,
                column=text,
            )
        seen[fld.name] = text
        into[fld.name] = (_value(fld, unit, raw, file, row, text), text)
    return into


def _spec(values: dict[str, tuple[Any, str]], file: Path, row: int | None) -> JointSpec:
    for name in _REQUIRED:
        if name not in values:
            raise DataError(f"missing required value '{name}'", file=file, row=row, column=name)
    got = {name: v for name, (v, _) in values.items()}
    label = {name: text for name, (_, text) in values.items()}
    reader = got.get("reader", _DEFAULTS["reader"])
    reader_options: dict[str, Any] = {}
    extract_options: dict[str, Any] = {}
    for name, value in got.items():
        group = FIELDS[name].group
        if group == "reader":
            if name not in READER_OPTIONS[reader]:
                users = [r for r, opts in READER_OPTIONS.items() if name in opts]
                raise DataError(
                    f"'{name}' is an option of reader {' or '.join(users)}; this joint's "
                    f"reader is '{reader}'",
                    file=file,
                    row=row,
                    column=label[name],
                )
            reader_options[name] = value
        elif group == "extract":
            extract_options[name] = value
    if reader == "generic" and "columns" not in reader_options:
        raise DataError(
            "reader 'generic' needs 'columns' (quantity=column name, e.g. "
            "'time=t;velocity=dq;torque=tau')",
            file=file,
            row=row,
            column="columns",
        )
    log_text = str(got["log"])
    log = Path(log_text).expanduser()
    if not log.is_absolute():
        log = file.parent / log
    return JointSpec(
        robot=got["robot"],
        joint=got["joint"],
        log=Path(os.path.abspath(log)),
        log_text=log_text,
        row=row,
        date=got.get("date"),
        reader=reader,
        reader_options=reader_options,
        extract_options=extract_options,
        models=got.get("model", _DEFAULTS["model"]),
        method=got.get("method", _DEFAULTS["method"]),
        seed=got.get("seed", _DEFAULTS["seed"]),
        max_evals=got.get("max_evals"),
        samples=got.get("samples", _DEFAULTS["samples"]),
        direction=got.get("direction", _DEFAULTS["direction"]),
        fixed=got.get("fix", {}),
        bounds=got.get("bound", {}),
        chunk_rows=got.get("chunk_rows", 1_000_000),
    )


def _read_text(path: Path) -> str:
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise DataError(f"cannot read the manifest: {exc.strerror}", file=path) from None
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise DataError("the manifest is not UTF-8 text", file=path, row=line) from None


def _csv_entries(path: Path, text: str) -> list[tuple[int, dict[str, Any]]]:
    reader = csv.reader(io.StringIO(text, newline=""))
    header: list[str] | None = None
    header_line = 0
    entries: list[tuple[int, dict[str, Any]]] = []
    try:
        for cells in reader:
            line = reader.line_num
            if not cells or all(not c.strip() for c in cells) or cells[0].lstrip().startswith("#"):
                continue
            if header is None:
                header, header_line = [c.strip() for c in cells], line
                for label in header:
                    _resolve_key(label, path, line)
                blank = [i for i, c in enumerate(header) if not c]
                if blank:
                    raise DataError(f"column {blank[0] + 1} has no name", file=path, row=line)
                continue
            if len(cells) > len(header):
                extra = [c for c in cells[len(header) :] if c.strip()]
                if extra:
                    raise DataError(
                        f"{len(cells)} cells but the header (line {header_line}) names "
                        f"{len(header)} columns",
                        file=path,
                        row=line,
                    )
            entries.append((line, dict(zip(header, cells, strict=False))))
    except csv.Error as exc:
        raise DataError(f"not valid CSV: {exc}", file=path, row=reader.line_num) from None
    if header is None:
        raise DataError("the manifest is empty (no header row)", file=path)
    return entries


def _yaml_lines(text: str, key_path: list[Any]) -> list[int] | None:
    """1-based lines of the items of the YAML sequence at ``key_path`` (None if unknown)."""
    import yaml

    node = yaml.compose(text, Loader=yaml.SafeLoader)
    for key in key_path:
        if not isinstance(node, yaml.MappingNode):
            return None
        found = [v for k, v in node.value if getattr(k, "value", None) == key]
        if not found:
            return None
        node = found[0]
    if not isinstance(node, yaml.SequenceNode):
        return None
    return [item.start_mark.line + 1 for item in node.value]


def _yaml_entries(path: Path, text: str) -> tuple[dict[str, Any], list[tuple[int, Any]]]:
    import yaml

    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        row = None if mark is None else mark.line + 1
        problem = " ".join(str(getattr(exc, "problem", None) or exc).split())  # one line
        raise DataError(f"not valid YAML: {problem}", file=path, row=row) from None
    defaults: Any = {}
    if isinstance(doc, Mapping):
        unknown = [k for k in doc if k not in ("joints", "defaults")]
        if unknown:
            raise DataError(
                f"unknown top-level key '{unknown[0]}'; a manifest has 'joints' and "
                "optionally 'defaults'",
                file=path,
            )
        defaults = doc.get("defaults") or {}
        joints, where = doc.get("joints"), ["joints"]
    else:
        joints, where = doc, []
    if not isinstance(defaults, Mapping):
        raise DataError("'defaults' must be a mapping of column to value", file=path)
    if not isinstance(joints, list) or not joints:
        raise DataError("the manifest lists no joints (a 'joints:' list of mappings)", file=path)
    lines = _yaml_lines(text, where) or [None] * len(joints)
    return dict(defaults), list(zip(lines, joints, strict=True))


def read_manifest(path: str | os.PathLike[str]) -> Manifest:
    """Read and validate a fleet manifest (``.csv``, ``.yaml`` or ``.yml``).

    Parameters
    ----------
    path : the manifest. Log paths in it are relative to its folder.

    Returns
    -------
    Manifest
        The joints in file order, every value checked and converted to SI.

    Raises
    ------
    DataError
        Naming the manifest, the row (line) and the column: an unknown column, a missing unit,
        a bad value (unknown model, method or reader, a non-number, ...), a missing required
        value (robot, joint, log), an option of another reader, a joint listed twice.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".yaml", ".yml"):
        raise ConfigError(
            f"cannot tell the manifest format of '{path}' from its suffix; use .csv, .yaml or .yml"
        )
    text = _read_text(path)
    if suffix == ".csv":
        defaults: dict[str, tuple[Any, str]] = {}
        entries: list[tuple[int | None, Any]] = list(_csv_entries(path, text))
    else:
        raw_defaults, entries = _yaml_entries(path, text)
        defaults = _parse_entry(raw_defaults, path, None, {})
        for name in ("robot", "joint", "log"):
            if name in defaults:
                raise DataError(f"'{name}' cannot have a default", file=path, column=name)
    if not entries:
        raise DataError("the manifest lists no joints", file=path)
    joints: list[JointSpec] = []
    first_row: dict[str, int | None] = {}
    for row, entry in entries:
        if not isinstance(entry, Mapping):
            raise DataError("a joint must be a mapping of column to value", file=path, row=row)
        spec = _spec(_parse_entry(entry, path, row, dict(defaults)), path, row)
        if spec.key in first_row:
            raise DataError(
                f"joint {spec.key} is listed twice (also at row {first_row[spec.key]})",
                file=path,
                row=row,
                column="joint",
            )
        first_row[spec.key] = row
        joints.append(spec)
    return Manifest(path, tuple(joints))
