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
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ..samples import FrictionSamples, RawLog
from ..units import UNITS, to_si
from .generic import integrate_velocity

__all__ = ["LOG_VARIABLES", "SAMPLE_VARIABLES", "mat_variables", "read_mat"]

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


def _load(path: Path) -> Any:
    """The file's variables: a dict (v5) or an open ``h5py.File`` (v7.3)."""
    import h5py
    import scipy.io

    if not path.is_file():
        raise DataError("no such file", file=path)
    if h5py.is_hdf5(path):
        return h5py.File(path, "r")
    try:
        return scipy.io.loadmat(path, simplify_cells=True)
    except (ValueError, TypeError, OSError, NotImplementedError) as exc:
        raise DataError(f"not a readable MATLAB file: {exc}", file=path) from None


def _names(node: Any) -> list[str]:
    if isinstance(node, Mapping) or hasattr(node, "keys"):
        return sorted(k for k in node if not str(k).startswith("__") and k != "#refs#")
    return []


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
    """
    root = _load(Path(path))
    try:
        out: list[str] = []

        def walk(node: Any, prefix: str) -> None:
            for name in _names(node):
                child = node[name]
                if _names(child):
                    walk(child, f"{prefix}{name}.")
                else:
                    out.append(prefix + name)

        walk(root, "")
        return out
    finally:
        if hasattr(root, "close"):
            root.close()


def _variable(root: Any, name: str, path: Path, joint: str | None) -> np.ndarray:
    """One variable (``a.b`` for a struct field) as a float vector, the joint's column."""
    node = root
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
        node = node[part]
        seen = f"{seen}.{part}" if seen else part
    if _names(node):
        raise DataError(
            f"'{name}' is a struct (fields {', '.join(_names(node))}), not an array",
            file=path,
            column=name,
        )
    try:
        if hasattr(node, "id"):  # an HDF5 (v7.3) dataset, stored transposed (column-major)
            arr = np.asarray(node[()], dtype=float).T
        else:
            arr = np.asarray(node, dtype=float)
    except (TypeError, ValueError):
        raise DataError(f"'{name}' is not numeric", file=path, column=name) from None
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
        A log: constant temperature [degC] without a temperature variable (one of the two is
        needed). A table: the temperature of every row; without it and without a variable,
        temperature is not measured.
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
        Not a MATLAB file, a variable missing (listing what is there), not numeric, of the
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
    root = _load(path)
    try:
        si = {}
        for q, spec in variables.items():
            parts = [_variable(root, name, path, joint) for name in spec.split(",")]
            si[q] = np.asarray(
                to_si(np.concatenate(parts), unit_of[q], _QUANTITY.get(q, q)), dtype=float
            )
    finally:
        if hasattr(root, "close"):
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
        return FrictionSamples(
            velocity=velocity,
            load=si.get("load"),
            temperature=si.get("temperature", temperature),
            friction=si["friction"],
            direction=np.sign(velocity),
            source=str(path),
            meta={**meta, "method": "means as published (one row per velocity and direction)"},
        )
    time, velocity = si["time"], si["velocity"]
    if "temperature" not in si and temperature is None:
        raise ConfigError("give the temperature as --var temperature=NAME:UNIT or --temperature")
    position = si.get("position")
    if position is None:
        position = integrate_velocity(time, velocity)
    return RawLog(
        time=time,
        position=position,
        velocity=velocity,
        temperature=si.get("temperature", temperature),
        torque=si.get("torque"),
        current=si.get("current"),
        torque_constant=torque_constant,
        joint="joint" if joint is None else f"joint {joint}",
        source=str(path),
        meta=meta,
    )
