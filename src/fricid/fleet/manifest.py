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

A ROS 2 bag (``reader`` ``rosbag``: a bag folder, or an ``.mcap`` or ``.db3`` file) is read
for the joint named by the ``joint`` column, or by ``log_joint`` when the bag names it
otherwise; ``topic``, ``temperature_topic``, ``effort`` (torque or current),
``effort_unit``, ``position_unit``, ``velocity_unit`` and ``time_source`` are its reader's
options, as for ``fricid extract --format rosbag``.

Every dimensional value names its unit in the column name, as fricid's tables do:
``positions [deg]``, ``bin_halfwidth [deg]``, ``settle_time [s]``, ``temperature [degC]``,
``torque_constant [N m/A]``, ``nominal_torque [mN m]``, ``load [N m]``. Log paths are relative
to the manifest's folder. Every error names the manifest, the row (its line) and the column.

A whole robot
    A row with ``urdf`` (the robot's URDF, relative to the manifest) is a whole robot: its
    ``log`` holds every joint (a CSV or Parquet table with per-joint columns, a ROS 2 bag,
    a folder of per-channel files: :func:`fricid.io.read_robot_log`), and its joints are
    identified together as ``fricid robot fit`` does (:func:`fricid.workflow.run_robot`).
    It takes the columns ``joints`` (default: the URDF's movable joints) and ``friction``
    (one family for every joint), and ``joint`` names its record (default ``arm``); the
    results table gets one row per joint of the robot. A column of a single joint's
    extraction, fit or reader given on a robot row (or a robot column on another row) is an
    error; one inherited from ``defaults`` does not apply to the other kind of row.

This module is longer than 500 lines because the joint's spec, its names' checks and the
reading of both kinds of row are one reader; the cell-level rules live in
:mod:`._manifest_schema`.

How a manifest is read
    The columns, their types, ranges and choices, and the document's shape are the JSON
    Schema ``fricid/schemas/manifest.schema.json`` (:data:`SCHEMA`; :data:`FIELDS` is built
    from it in :mod:`._manifest_schema`). A column label is split into its name and
    ``[unit]``; a text cell is read as the value it writes (the schema's ``x-text``: a
    number, ``NAME=VALUE`` items, ... through :mod:`fricid.io.options`, the parsers the
    command line uses too); then the joint is validated against the schema, and the first
    error becomes one :class:`~fricid.errors.DataError`. Code does only what a schema cannot:
    units (:func:`fricid.units.to_si`), model and method names (their registries), options
    of another reader (:data:`fricid.io.READER_OPTIONS`), a joint listed twice, and paths
    relative to the manifest.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ConfigError, DataError
from ..io.registry import READER_OPTIONS
from ._fs import NAME_MAX, PATH_MAX, fs_limits, joint_names
from ._manifest_schema import (
    FIELDS,
    SCHEMA,
    Entry,
    Field,
    manifest_path,
    read_entry,
    row_kind,
    to_values,
    validate,
    validator,
)
from ._manifest_text import MAX_MANIFEST_BYTES, _csv_entries, _read_text, _yaml_lines, _yaml_load
from .hashing import input_hash

__all__ = [
    "FIELDS",
    "MAX_MANIFEST_BYTES",
    "SCHEMA",
    "Field",
    "JointSpec",
    "Manifest",
    "check_names",
    "read_manifest",
]

#: A robot or joint name, whole (the schema's pattern, anchored at the very end: a
#: JSON Schema ``$`` also matches before a final line break).
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]*")

_DEFAULTS: dict[str, Any] = {
    "reader": "table",
    "model": ("stribeck",),
    "method": "lm",
    "seed": 0,
    "direction": "all",
    "samples": "auto",
    "loss": "l2",
    "weights": "none",
    "intervals": "auto",
}


# --------------------------------------------------------------------------- the joint spec


@dataclass(frozen=True, eq=False)
class JointSpec:
    """One joint of the fleet: where its log is and how to identify it.

    Attributes
    ----------
    robot, joint : str
        Its names (``key`` is ``"robot/joint"``).
    log : Path
        Absolute path of the log (the manifest's relative path resolved).
    log_text : str
        The path as the manifest writes it.
    row : int or None
        The manifest line of the joint, for messages.
    date : str or None
        Measurement date (ISO), or None for the run's date.
    reader, reader_options : str, dict
        See :func:`fricid.workflow.load_joint` (SI units).
    extract_options : dict
        Options of :func:`fricid.extract.extract` (SI units).
    models, method, seed, max_evals, samples, direction, fixed, bounds
        See :func:`fricid.workflow.run_joint`.
    validate, loss, f_scale, weights, intervals
        As ``fricid fit`` takes them (:func:`fricid.workflow.run_joint`; ``f_scale`` in N m).
    chunk_rows : int
        Rows read at a time (memory, not results).
    urdf, urdf_text : Path or None, str or None
        A whole robot's URDF (absolute) and as the manifest writes it; None for one joint.
    arm_joints, friction : tuple of str or None, str
        A whole robot's joints to identify (None: the URDF's movable joints) and the
        friction family of every joint (:func:`fricid.workflow.run_robot`).
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
    validate: str | None = None
    loss: str = "l2"
    f_scale: float | None = None
    weights: str = "none"
    intervals: str = "auto"
    chunk_rows: int = 1_000_000
    urdf: Path | None = None
    urdf_text: str | None = None
    arm_joints: tuple[str, ...] | None = None
    friction: str = "stribeck_asym"

    @property
    def key(self) -> str:
        return f"{self.robot}/{self.joint}"

    @property
    def is_robot(self) -> bool:
        """Whether the row is a whole robot (it has a URDF)."""
        return self.urdf is not None

    def _robot_settings(self) -> dict[str, Any]:
        try:
            urdf_hash: str | None = input_hash(self.urdf, "table", {})
        except OSError:  # the job fails at reading it, and a failed row always runs again
            urdf_hash = None
        return {
            "kind": "robot",
            "urdf_hash": urdf_hash,
            "joints": None if self.arm_joints is None else list(self.arm_joints),
            "friction": self.friction,
        }

    def robot_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :func:`fricid.workflow.run_robot` for a robot row."""
        return {
            "joints": self.arm_joints,
            "friction": self.friction,
        }

    def settings(self) -> dict[str, Any]:
        """Everything that decides the results, JSON-ready (hashed to decide re-runs).

        The log's path, the date and ``chunk_rows`` are not settings: the log's content is
        hashed separately, and the others do not change the numbers. A robot row's are its
        URDF's content hash, its joints and its friction family.
        """
        if self.is_robot:
            return self._robot_settings()
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
            "validate": self.validate,
            "loss": self.loss,
            "f_scale": self.f_scale,
            "weights": self.weights,
            "intervals": self.intervals,
        }

    def run_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :func:`fricid.workflow.run_joint` for this joint."""
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
            "validate": self.validate,
            "loss": self.loss,
            "f_scale": self.f_scale,
            "weights": self.weights,
            "intervals": self.intervals,
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


# --------------------------------------------------------------------------- names


def _short(text: str, n: int = 48) -> str:
    """``text``, or its start and end when longer than ``n`` characters."""
    return text if len(text) <= n else f"{text[: n - 20]}...{text[-16:]}"


def check_names(
    spec: JointSpec,
    file: str | os.PathLike[str],
    *,
    out: str | os.PathLike[str] | None = None,
    labels: Mapping[str, str] | None = None,
) -> None:
    """Refuse a joint whose names the file system cannot hold, before any work.

    Every name the fleet derives from the joint's robot, joint and model names (its folders,
    its record and model files, their temporary names, its partition of the results table;
    :func:`fricid.fleet._fs.joint_names`) must fit in ``NAME_MAX`` bytes, and with ``out``
    (the output folder) every path in ``PATH_MAX``: the limits of the file system holding
    ``out`` (``os.pathconf``), else 255 and 4096. A robot or joint name must also match
    the manifest's name pattern whole (letters, digits, ``.``, ``_``, ``-``).

    Parameters
    ----------
    spec : JointSpec
        The joint.
    file : path-like
        The manifest, for the message.
    out : path-like, optional
        The output folder; without it only names are checked (against 255 bytes).
    labels : Mapping[str, str], optional
        The columns' labels as the manifest writes them, for the message.

    Raises
    ------
    DataError
        Naming the manifest, the joint's row and the column.
    """
    labels = labels or {}
    for column, value in (("robot", spec.robot), ("joint", spec.joint)):
        if not _NAME.fullmatch(value):
            raise DataError(
                f"{_short(value)!r} is not a usable name: letters, digits, '.', '_' and '-' "
                "only, starting with a letter or digit (it names files)",
                file=file,
                row=spec.row,
                column=labels.get(column, column),
            )
    name_max, path_max = fs_limits(out) if out is not None else (NAME_MAX, PATH_MAX)
    base = len(os.fsencode(os.path.abspath(out))) + 1 if out is not None else 0
    for got in joint_names(spec.robot, spec.joint, spec.models):
        value = spec.robot if got.column == "robot" else spec.joint
        column = labels.get(got.column, got.column)
        if got.name_bytes > name_max:
            raise DataError(
                f"'{_short(value)}' ({len(value)} characters) is too long: fricid names "
                f"'{_short(got.name)}' after it, {got.name_bytes} bytes"
                f"{' as the temporary file it writes first' if got.temporary else ''}, over "
                f"the file system's limit of {name_max} bytes per name",
                file=file,
                row=spec.row,
                column=column,
            )
        if out is not None and base + got.path_bytes >= path_max:
            raise DataError(
                f"'{_short(value)}' makes a path of {base + got.path_bytes} bytes under the "
                f"output folder {out}, over the file system's limit of {path_max - 1}: use "
                "a shorter output folder or shorter names",
                file=file,
                row=spec.row,
                column=column,
            )


# --------------------------------------------------------------------------- reading


def _robot_spec(entry: Entry, got: dict[str, Any], file: Path) -> JointSpec:
    """A validated robot row -> its :class:`JointSpec`."""
    spec = JointSpec(
        robot=got["robot"],
        joint=got["joint"],
        log=manifest_path(got["log"], entry, "log", file),
        log_text=got["log"],
        row=entry.row,
        date=got.get("date"),
        reader="robot",
        models=("arm",),
        urdf=manifest_path(got["urdf"], entry, "urdf", file),
        urdf_text=got["urdf"],
        arm_joints=tuple(got["joints"]) if "joints" in got else None,
        friction=got.get("friction", "stribeck_asym"),
    )
    check_names(spec, file, labels=entry.labels)
    return spec


def _spec(entry: Entry, file: Path, own: set[str] | None = None) -> JointSpec:
    """A joint entry (defaults merged; ``own``: the columns the row gives itself, default
    all) -> its :class:`JointSpec`, validated."""
    robot = row_kind(entry, set(entry.values) if own is None else own, file)
    validate(entry, "joint", file)
    got = to_values(entry, file)
    if robot:
        return _robot_spec(entry, got, file)
    reader = got.get("reader", _DEFAULTS["reader"])
    reader_options: dict[str, Any] = {}
    extract_options: dict[str, Any] = {}
    for name, value in got.items():
        group = FIELDS[name].group
        if group == "reader":
            option = FIELDS[name].option
            if option not in READER_OPTIONS[reader]:
                users = [r for r, opts in READER_OPTIONS.items() if option in opts]
                raise DataError(
                    f"'{name}' is an option of reader {' or '.join(users)}; this joint's "
                    f"reader is '{reader}'",
                    file=file,
                    row=entry.row,
                    column=entry.labels[name],
                )
            reader_options[option] = value
        elif group == "extract":
            extract_options[name] = value
    if "joint" in READER_OPTIONS[reader] and "joint" not in reader_options:
        reader_options["joint"] = got["joint"]  # a bag's joint: the joint column by default
    log_text = got["log"]
    spec = JointSpec(
        robot=got["robot"],
        joint=got["joint"],
        log=manifest_path(log_text, entry, "log", file),
        log_text=log_text,
        row=entry.row,
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
        validate=got.get("validate"),
        loss=got.get("loss", _DEFAULTS["loss"]),
        f_scale=got.get("f_scale"),
        weights=got.get("weights", _DEFAULTS["weights"]),
        intervals=got.get("intervals", _DEFAULTS["intervals"]),
        chunk_rows=got.get("chunk_rows", 1_000_000),
    )
    check_names(spec, file, labels=entry.labels)
    return spec


def _document_error(doc: Any, path: Path, lines: list[int | None]) -> DataError | None:
    """The first error of the document's shape (joints, defaults), as a DataError."""
    error = next(iter(validator().iter_errors(doc)), None)
    if error is None:
        return None
    where = list(error.path)
    spec = error.schema
    messages = spec.get("x-message") if isinstance(spec.get("x-message"), Mapping) else {}
    if error.validator == "additionalProperties":
        key = next(k for k in doc if k not in SCHEMA["properties"])
        return DataError(messages["additionalProperties"].format(key=key), file=path)
    if isinstance(spec.get("x-message"), str):
        message = spec["x-message"]
    else:
        message = messages.get(error.validator, error.message)
    row = lines[where[1]] if len(where) == 2 and where[1] < len(lines) else None
    return DataError(message, file=path, row=row)


def _yaml_entries(path: Path, text: str) -> tuple[dict[str, Any], list[tuple[int | None, Any]]]:
    doc, node = _yaml_load(path, text)
    where = ["joints"] if isinstance(doc, Mapping) else []
    if not isinstance(doc, Mapping):
        doc = {"joints": doc}
    if doc.get("defaults") is None:
        doc = {**doc, "defaults": {}}
    joints = doc.get("joints")
    lines: list[int | None] = []
    if isinstance(joints, list):
        lines = _yaml_lines(node, where) or [None] * len(joints)
    error = _document_error(doc, path, lines)
    if error is not None:
        raise error
    return dict(doc["defaults"]), list(zip(lines, doc["joints"], strict=True))


def read_manifest(path: str | os.PathLike[str]) -> Manifest:
    """Read and validate a fleet manifest (``.csv``, ``.yaml`` or ``.yml``).

    Parameters
    ----------
    path : str or path-like
        The manifest. Log paths in it are relative to its folder.

    Returns
    -------
    Manifest
        The joints in file order, every value checked and converted to SI.

    Raises
    ------
    DataError
        Naming the manifest, the row (line) and the column: an unknown column, a missing unit,
        a bad value (unknown model, method or reader, a non-number, ...), a missing required
        value (robot, joint, log), an option of another reader, a joint listed twice. Every
        row is checked: problems in several rows are told at once, in one error listing
        each (its ``problems`` attribute holds them).
    ConfigError
        A file whose suffix is not ``.csv``, ``.yaml`` or ``.yml``.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".yaml", ".yml"):
        raise ConfigError(
            f"cannot tell the manifest format of '{path}' from its suffix; use .csv, .yaml or .yml"
        )
    text = _read_text(path)
    defaults = Entry(None)
    if suffix == ".csv":
        entries: list[tuple[int | None, Any]] = list(_csv_entries(path, text))
    else:
        raw_defaults, entries = _yaml_entries(path, text)
        read_entry(raw_defaults, path, None, defaults)
        validate(defaults, "defaults", path)
    if not entries:
        raise DataError("the manifest lists no joints", file=path)
    joints: list[JointSpec] = []
    first_row: dict[str, int | None] = {}
    problems: list[DataError] = []
    for row, mapping in entries:
        entry = Entry(row, dict(defaults.values), dict(defaults.raw), dict(defaults.labels))
        entry.units = dict(defaults.units)
        try:
            own = set(read_entry(mapping, path, row, Entry(row)).values)
            spec = _spec(read_entry(mapping, path, row, entry), path, own)
        except DataError as exc:  # every row is checked: all problems are told at once
            problems.append(exc)
            continue
        if spec.key in first_row:
            problems.append(
                DataError(
                    f"joint {spec.key} is listed twice (also at row {first_row[spec.key]})",
                    file=path,
                    row=row,
                    column="joint",
                )
            )
            continue
        first_row[spec.key] = row
        joints.append(spec)
    if problems:
        raise _all_problems(problems, path)
    return Manifest(path, tuple(joints))


def _all_problems(problems: list[DataError], path: Path) -> DataError:
    """One error for the rows' problems: the problem itself when there is one, else one
    naming the manifest and listing each (row, column, what), in file order, in its
    ``problems`` attribute too."""
    if len(problems) == 1:
        return problems[0]
    parts = []
    for p in problems:
        where = [f"row {p.row}"] if p.row is not None else []
        where += [f"column '{p.column}'"] if p.column is not None else []
        parts.append(f"{', '.join(where)}: {p.message}" if where else p.message)
    error = DataError(f"{len(problems)} problems: " + "; ".join(parts), file=path)
    error.problems = list(problems)
    return error
