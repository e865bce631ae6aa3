"""MATLAB ``.mat`` files: a joint's log, or per-direction mean tables read straight into samples.

Version 5 files (MATLAB's default before 7.3) are read with :func:`scipy.io.loadmat`, version
7.3 files (HDF5) with ``h5py``; which one is found from the file. Variables are chosen by name,
a field of a struct as ``a.b``, and several variables joined end to end with ``,`` (the
forward and the backward table of a lab's per-direction means)::

    read_mat("sweep.mat", {"time": "t", "velocity": "qd", "torque": "tau"},
             {"time": "s", "velocity": "rad/s", "torque": "N m"}, temperature=25.0)
    read_mat("means.mat", {"velocity": "fwd.v,bwd.v", "friction": "fwd.tau,bwd.tau"},
             {"velocity": "rad/s", "friction": "N m"}, joint="2")

A variable with one column per joint (``(n, J)``) needs ``joint``, the 1-based column. Every
variable needs a unit (DESIGN.md, "Units"): MATLAB files do not carry one.
"""

from __future__ import annotations

import os
import warnings
import zlib
from collections.abc import Collection, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ..samples import FrictionSamples, RawLog, constant_temperature, drop_standstill
from ..units import UNITS, to_si
from ._files import check_input
from ._mat73 import h5_child, h5_kind, h5_values
from ._matv5 import V5Bad, check_v5
from .generic import integrate_velocity

__all__ = [
    "LOG_VARIABLES",
    "MAX_BYTES",
    "NUMERIC_CLASSES",
    "SAMPLE_VARIABLES",
    "mat_variables",
    "read_mat",
]

#: Quantities of a log read from a ``.mat`` file (time, velocity and torque or current needed).
LOG_VARIABLES: tuple[str, ...] = (
    "time",
    "position",
    "velocity",
    "torque",
    "current",
    "temperature",
)

#: Quantities of a table of means read as samples (velocity and friction needed).
SAMPLE_VARIABLES: tuple[str, ...] = ("velocity", "friction", "load", "temperature")

_QUANTITY = {"friction": "torque", "load": "torque"}  # unit kind of a samples quantity


#: The largest array read from a MATLAB file, and the most data a file may hold once
#: inflated [bytes]: what a file declares is checked against it before anything is read.
MAX_BYTES = 2 * 2**30

#: MATLAB classes read as numbers (converted to float64).
NUMERIC_CLASSES = frozenset(
    ("double", "single", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64")
)

#: What to do with an array of a class that is not numbers, by the start of its class name.
_ADVICE = (
    ("logical", "is logical (true/false), not numbers; store the {q} values as double"),
    (
        "complex",
        "is complex; store the {q} values as real doubles (fricid drops no imaginary "
        "part silently)",
    ),
    ("sparse", "is a sparse matrix; store the {q} values as a full double array (full(x))"),
    ("char", "is text (char), not numbers; store the {q} values as double"),
    ("cell", "is a cell array; store the {q} values as one double array (cell2mat(x))"),
    ("struct", "is an array of structs; store the {q} values as one double array"),
)

#: Most names listed by :func:`mat_variables`, and the deepest struct nesting walked.
_MAX_LISTED, _MAX_DEPTH = 100_000, 32


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())[:300] or type(exc).__name__


@dataclass
class _Root:
    """An open MATLAB file: its variables (a dict, or an ``h5py.File`` for v7.3) and, for a
    v5 file, each array's class as its structure declares it (``a.b`` -> ``"logical"``)."""

    node: Any
    kinds: dict[str, str]

    def close(self) -> None:
        if hasattr(self.node, "close"):
            self.node.close()


def _load(path: Path, wanted: Collection[str] | None = None) -> _Root:
    """Open a MATLAB file, its structure checked (:data:`MAX_BYTES`); ``wanted``: the
    top-level variables to read from a v5 file (default all), each one there."""
    import h5py

    size = check_input(path, what="MATLAB file").st_size
    try:
        hdf5 = h5py.is_hdf5(path)
    except (OSError, ValueError, RuntimeError) as exc:
        raise DataError(f"cannot read the MATLAB file: {_one_line(exc)}", file=path) from None
    if hdf5:
        try:
            return _Root(h5py.File(path, "r"), {})
        except (OSError, ValueError, RuntimeError, KeyError, TypeError) as exc:
            raise DataError(
                f"not a readable MATLAB v7.3 (HDF5) file: {_one_line(exc)}", file=path
            ) from None
    try:
        with open(path, "rb") as fh:
            names, kinds = check_v5(fh, size, MAX_BYTES)
    except V5Bad as bad:
        raise DataError(str(bad), file=path, column=bad.where) from None
    if wanted is not None:
        for name in wanted:
            if name not in names:
                raise DataError(
                    f"no variable '{name}': the file has "
                    + (", ".join(repr(n) for n in sorted(names)) or "no variables"),
                    file=path,
                    column=name,
                )
    return _Root(_loadmat(path, None if wanted is None else sorted(set(wanted))), kinds)


def _loadmat(path: Path, names: list[str] | None) -> dict[str, Any]:
    """scipy's reading of a checked v5 file; its warnings and errors as one DataError."""
    import scipy.io
    from scipy.io.matlab import MatReadError

    errors = (
        ValueError,
        TypeError,
        OSError,
        NotImplementedError,
        MatReadError,
        zlib.error,
        KeyError,
        IndexError,
        EOFError,
        OverflowError,
        UnicodeError,
        AttributeError,
        RecursionError,
        Warning,  # a duplicate name, an unreadable variable: scipy warns and goes on
    )
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            return scipy.io.loadmat(path, simplify_cells=True, variable_names=names)
    except errors as exc:
        raise DataError(f"not a readable MATLAB file: {_one_line(exc)}", file=path) from None


def _names(node: Any) -> list[str]:
    if isinstance(node, Mapping) or hasattr(node, "keys"):
        try:
            keys = list(node.keys())
        except (OSError, KeyError, RuntimeError, ValueError):
            return []
        return sorted(str(k) for k in keys if not str(k).startswith(("__", "#")))
    return []


def _child(node: Any, part: str, name: str, path: Path) -> Any:
    """``node[part]``, a v7.3 link to another file or to nothing refused."""
    return h5_child(node, part, name, path) if hasattr(node, "id") else node[part]


def mat_variables(path: str | os.PathLike[str]) -> list[str]:
    """The variables of a ``.mat`` file, struct fields as ``a.b``.

    Parameters
    ----------
    path : str or os.PathLike
        A version 5 or 7.3 file.

    Returns
    -------
    list of str
        Sorted names, for messages and discovery.

    Raises
    ------
    DataError
        Not a readable MATLAB file, or one that declares more than :data:`MAX_BYTES`.
    """
    path = Path(path)
    root = _load(path)
    try:
        out: list[str] = []

        def walk(node: Any, prefix: str, depth: int) -> None:
            if depth > _MAX_DEPTH:
                raise DataError(f"structs nested more than {_MAX_DEPTH} deep", file=path)
            for name in _names(node):
                if len(out) >= _MAX_LISTED:
                    raise DataError(f"more than {_MAX_LISTED} variables", file=path)
                try:
                    child = _child(node, name, prefix + name, path)
                except DataError:
                    out.append(prefix + name)
                    continue
                if _names(child) and _kind_of(child, prefix + name, root) == "struct":
                    walk(child, f"{prefix}{name}.", depth + 1)
                else:
                    out.append(prefix + name)

        walk(root.node, "", 0)
        return out
    finally:
        root.close()


def _kind_of(node: Any, name: str, root: _Root) -> str:
    """The MATLAB class of a variable: ``struct``, ``double``, ``logical``, ``cell``..."""
    if hasattr(node, "id"):  # an HDF5 (v7.3) group or dataset
        return h5_kind(node)
    kind = root.kinds.get(name)
    if kind is not None:
        return kind
    return "struct" if isinstance(node, Mapping) else "double"


def _refuse(kind: str, name: str, quantity: str, path: Path) -> DataError:
    """The error for a variable of a class that is not numbers, saying what to store."""
    for start, advice in _ADVICE:
        if kind.startswith(start):
            return DataError(
                f"variable '{name}' ({quantity}) {advice.format(q=quantity)}",
                file=path,
                column=name,
            )
    return DataError(
        f"variable '{name}' ({quantity}) is a MATLAB {kind}, not a numeric array; store the "
        f"{quantity} values as double",
        file=path,
        column=name,
    )


def _variable(root: _Root, name: str, path: Path, joint: str | None, quantity: str) -> np.ndarray:
    """One variable (``a.b`` for a struct field) as a float vector, the joint's column."""
    node = root.node
    seen = ""
    for part in name.strip().split("."):
        if part not in _names(node):
            where = f"struct '{seen}'" if seen else "the file"
            raise DataError(
                f"no variable '{name}': {where} has "
                + (", ".join(repr(n) for n in _names(node)) or "no variables"),
                file=path,
                column=name,
            )
        seen = f"{seen}.{part}" if seen else part
        node = _child(node, part, seen, path)
    kind = _kind_of(node, name.strip(), root)
    if kind == "struct" and _names(node):
        raise DataError(
            f"'{name}' is a struct (fields {', '.join(_names(node))}), not an array",
            file=path,
            column=name,
        )
    if kind not in NUMERIC_CLASSES:
        raise _refuse(kind, name, quantity, path)
    if hasattr(node, "id"):  # an HDF5 (v7.3) dataset
        arr = h5_values(node, name, path, MAX_BYTES)
    else:
        arr = np.asarray(node) if not isinstance(node, list) else np.asarray(node, dtype=object)
        if arr.dtype.kind not in "iuf":
            raise _refuse(
                "struct" if arr.dtype.kind == "O" else f"{arr.dtype}", name, quantity, path
            )
        arr = arr.astype(float)
    if arr.ndim == 2 and 1 in arr.shape:
        arr = arr.reshape(-1)
    if arr.ndim == 2:
        n_joints = arr.shape[1]
        if joint is None:
            raise ConfigError(
                f"{path}: '{name}' has {n_joints} columns (one per joint); choose one with "
                f"--joint 1..{n_joints}"
            )
        try:
            j = int(joint)
        except ValueError:
            raise ConfigError(
                f"--joint must be a column number 1..{n_joints}, got '{joint}'"
            ) from None
        if not 1 <= j <= n_joints:
            raise ConfigError(f"{path}: '{name}' has {n_joints} columns; --joint {j} is not one")
        arr = arr[:, j - 1]
    if arr.ndim != 1:
        raise DataError(f"'{name}' has shape {arr.shape}, not a vector", file=path, column=name)
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise DataError(
            f"non-finite value {arr[bad[0]]!r}", file=path, row=int(bad[0]), column=name
        )
    return arr


def _unit(quantity: str, units: Mapping[str, str]) -> str:
    kind = _QUANTITY.get(quantity, quantity)
    unit = units.get(quantity)
    if unit is None:
        raise ConfigError(
            f"no unit for {quantity}: a MATLAB variable carries none; write --var "
            f"{quantity}=NAME:UNIT with one of: {', '.join(UNITS[kind])}"
        )
    if unit not in UNITS[kind]:
        raise ConfigError(f"unknown {quantity} unit '{unit}'; allowed: {', '.join(UNITS[kind])}")
    return unit


def read_mat(
    path: str | os.PathLike[str],
    variables: Mapping[str, str] | None = None,
    units: Mapping[str, str] | None = None,
    *,
    joint: str | None = None,
    temperature: float | None = None,
    torque_constant: float | None = None,
) -> RawLog | FrictionSamples:
    """Read a joint's log, or a table of friction means, from a MATLAB file.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.mat`` file, version 5 or 7.3 (never modified).
    variables : mapping of str to str
        Quantity -> variable (``a.b`` for a struct field; ``x,y`` for variables joined end
        to end). With ``friction``: a table of means, quantities among
        :data:`SAMPLE_VARIABLES`; else a log, quantities among :data:`LOG_VARIABLES`.
    units : mapping of str to str
        Quantity -> unit, for every quantity in ``variables``.
    joint : str, optional
        The 1-based column to read from variables with one column per joint.
    temperature : float, optional
        A log: constant temperature [degC] without a temperature variable (without either,
        the log records none: :data:`fricid.samples.NO_TEMPERATURE_SOURCE`). A table: the
        temperature of every row; without it and without a variable, temperature is not
        measured.
    torque_constant : float, optional
        K [N m/A] for a current variable (tau = K I, eq. 13 of the BAS-RBFNN paper).

    Returns
    -------
    RawLog or FrictionSamples
        A log in SI (position integrated from velocity if absent), or samples with direction
        the sign of each velocity, load (and temperature) not measured unless given.

    Raises
    ------
    ConfigError
        An unknown quantity or unit, a missing unit, a required quantity missing, a variable
        with several joint columns and no ``joint``.
    DataError
        Not a MATLAB file (or not a regular file), a damaged one, one that declares more
        than :data:`MAX_BYTES` (an array, or its data once inflated), a link to another file;
        a variable missing (listing what is there), not numbers (logical, complex, sparse,
        text, a cell or struct array, an object: saying what to store instead), of the
        wrong shape, of another length than the others, with a non-finite value or (a table)
        a zero velocity; file, row and variable named.
    """
    path = Path(path)
    if not variables:
        raise ConfigError(
            "reading a MATLAB file needs its variables by name (--var QUANTITY=NAME:UNIT, "
            "variables= in Python); the file has: " + ", ".join(mat_variables(path))
        )
    variables = dict(variables)
    units = dict(units or {})
    as_samples = "friction" in variables
    allowed = SAMPLE_VARIABLES if as_samples else LOG_VARIABLES
    unknown = [q for q in variables if q not in allowed]
    if unknown:
        kind = "a table of means (friction given)" if as_samples else "a log"
        raise ConfigError(
            f"--var {unknown[0]} does not apply to {kind}; map any of: {', '.join(allowed)}"
        )
    extra = [q for q in units if q not in variables]
    if extra:
        raise ConfigError(f"a unit given for {extra[0]!r}, which no --var maps")
    needed = ("velocity",) if as_samples else ("time", "velocity")
    for q in needed:
        if q not in variables:
            raise ConfigError(f"--format mat needs --var {q}=NAME:UNIT")
    if not as_samples and "torque" not in variables and "current" not in variables:
        raise ConfigError(
            "--format mat needs --var torque=NAME:UNIT or current=NAME:UNIT for a log, or "
            "friction=NAME:UNIT for a table of means"
        )
    unit_of = {q: _unit(q, units) for q in variables}
    wanted = {name.strip().split(".")[0] for spec in variables.values() for name in spec.split(",")}
    root = _load(path, wanted)
    try:
        si = {}
        for q, spec in variables.items():
            parts = [_variable(root, name, path, joint, q) for name in spec.split(",")]
            si[q] = np.asarray(
                to_si(np.concatenate(parts), unit_of[q], _QUANTITY.get(q, q)), dtype=float
            )
    finally:
        root.close()
    first = next(iter(variables))
    for q, values in si.items():
        if len(values) != len(si[first]):
            raise DataError(
                f"'{variables[q]}' ({q}) has {len(values)} values, '{variables[first]}' "
                f"({first}) {len(si[first])}",
                file=path,
                column=variables[q],
            )
    meta = {"format": "mat", "variables": variables, "units": unit_of}
    if as_samples:
        velocity = si["velocity"]
        zero = np.flatnonzero(velocity == 0)
        if zero.size:
            raise DataError(
                "zero velocity: a mean of friction needs a direction of motion",
                file=path,
                row=int(zero[0]),
                column=variables["velocity"],
            )
        means = FrictionSamples(
            velocity=velocity,
            load=si.get("load"),
            temperature=si.get("temperature", temperature),
            friction=si["friction"],
            direction=np.sign(velocity),
            source=str(path),
            meta={**meta, "method": "means as published (one row per velocity and direction)"},
        )
        return drop_standstill(means, stacklevel=3)
    time, velocity = si["time"], si["velocity"]
    constant, source = constant_temperature(temperature)
    if "temperature" not in si:
        meta["temperature_source"] = source
    position = si.get("position")
    meta = {**meta, "position_source": "integrated velocity" if position is None else "channel"}
    if position is None:
        position = integrate_velocity(time, velocity)
    return RawLog(
        time=time,
        position=position,
        velocity=velocity,
        temperature=si.get("temperature", constant),
        torque=si.get("torque"),
        current=si.get("current"),
        torque_constant=torque_constant,
        joint="joint" if joint is None else f"joint {joint}",
        source=str(path),
        meta=meta,
    )
