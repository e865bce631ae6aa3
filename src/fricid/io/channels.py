"""One file per channel: headerless ``time value`` files, one set per run, read by patterns.

Many labs write each channel of a run to its own two-column text file and put the run's
identity in the file name::

    run_pos1_40.t   run_vel1_40.t   run_tau1_40.t     (joint 1 at set-point 40)
    run_pos1_80.t   run_vel1_80.t   run_tau1_80.t

One pattern per quantity names the files; ``{field}`` matches a part of the name (any
characters but ``/``, as few as the rest of the pattern allows), ``*`` and ``?`` are globs,
anything else is literal; put a literal between a field and a ``*`` (``{speed}_*.t``, not
``{speed}*.t``, which cannot tell where the field ends)::

    torque={name}_tau{joint}_{speed}.t     velocity={name}_vel{joint}_{speed}.t

A run is one value of the fields (here ``name``, ``joint`` and ``speed``): its channels are
joined on time and it becomes one :class:`~fricid.samples.RawLog`, kept apart from the other
runs (its time starts again, which ends a run in :func:`fricid.extract.extract`). With a
``{joint}`` field and several joints in the folder, ``joint=`` chooses one.

Joining on time (``join=``), onto the time stamps of the velocity file (else the position's):

* ``"exact"``: every channel has the same time stamps, else an error naming file and row;
* ``"nearest"`` (default): each time stamp takes the other channel's nearest sample within
  ``tolerance`` (default half the median sample period); rows with none are dropped (with a
  :class:`~fricid.errors.DataQualityWarning` counting them);
* ``"linear"``: the other channels are linearly interpolated at the time stamps; rows outside
  a channel's time span are dropped.

What was done is stated in each log's ``meta["join"]``.
"""

from __future__ import annotations

import os
import re
import warnings
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import ConfigError, DataError, DataQualityWarning, user_stacklevel
from ..samples import RawLog, constant_temperature
from ..units import UNITS, to_si
from ._files import check_input, read_capped
from .generic import integrate_velocity

__all__ = ["CHANNEL_QUANTITIES", "JOINS", "compile_pattern", "read_channels"]

#: Quantities a channel file can hold.
CHANNEL_QUANTITIES: tuple[str, ...] = ("position", "velocity", "torque", "current", "temperature")

#: Ways of joining channels on time.
JOINS: tuple[str, ...] = ("exact", "nearest", "linear")

_FIELD = re.compile(r"\{([A-Za-z_]\w*)\}")


def compile_pattern(pattern: str) -> tuple[re.Pattern[str], tuple[str, ...]]:
    """A file-name pattern as a regular expression and its field names.

    Parameters
    ----------
    pattern : str
        ``{field}`` matches one or more characters other than ``/``; ``*`` any characters
        other than ``/``, ``?`` one; the rest is literal.

    Returns
    -------
    regex : re.Pattern
        Matching a whole path relative to the folder (``/``-separated).
    fields : tuple of str
        The field names, in order.

    Raises
    ------
    ConfigError
        A field named twice, or an empty pattern.

    Examples
    --------
    >>> rx, fields = compile_pattern("{name}_tau{joint}_{speed}.t")
    >>> fields, rx.fullmatch("run_tau1_40.t").groupdict()
    (('name', 'joint', 'speed'), {'name': 'run', 'joint': '1', 'speed': '40'})
    """
    if not pattern.strip():
        raise ConfigError("a channel pattern is empty")
    parts: list[str] = []
    fields: list[str] = []
    pos = 0
    for m in _FIELD.finditer(pattern):
        parts.append(_glob(pattern[pos : m.start()]))
        name = m.group(1)
        if name in fields:
            raise ConfigError(f"pattern '{pattern}' names field '{name}' twice")
        fields.append(name)
        parts.append(f"(?P<{name}>[^/]+?)")
        pos = m.end()
    parts.append(_glob(pattern[pos:]))
    return re.compile("".join(parts)), tuple(fields)


def _glob(text: str) -> str:
    return "".join("[^/]*?" if c == "*" else "[^/]" if c == "?" else re.escape(c) for c in text)


def _sort_key(value: str) -> tuple[int, float, str]:
    try:
        return (0, float(value), value)
    except ValueError:
        return (1, 0.0, value)


def _read_two_columns(path: Path, quantity: str) -> tuple[np.ndarray, np.ndarray]:
    """``time value`` rows (blank, comma or semicolon separated; ``#`` lines skipped)."""
    text = read_capped(path, what=f"{quantity} file").decode("utf-8", errors="replace")
    lines = text.splitlines()
    body = pd.Series(lines, index=np.arange(1, len(lines) + 1), dtype=object).str.strip()
    body = body[(body != "") & ~body.str.startswith("#")]
    if body.empty:
        raise DataError("no data rows", file=path)
    text = body.str.split(r"[\s,;]+", regex=True, expand=True)
    if text.shape[1] != 2 or text[1].isna().any():
        widths = body.str.split(r"[\s,;]+", regex=True).str.len().to_numpy()
        i = int(np.flatnonzero(widths != 2)[0])
        raise DataError(
            f"row has {widths[i]} fields, expected 2 (time {quantity})",
            file=path,
            row=int(body.index[i]),
        )
    data = np.column_stack(
        [pd.to_numeric(text[j], errors="coerce").to_numpy(float) for j in (0, 1)]
    )
    bad = ~np.isfinite(data)
    if bad.any():
        i = int(np.flatnonzero(bad.any(axis=1))[0])
        j = int(np.flatnonzero(bad[i])[0])
        raise DataError(
            f"not a finite number: {text.iat[i, j]!r}",
            file=path,
            row=int(body.index[i]),
            column=("time", quantity)[j],
        )
    t = data[:, 0]
    dt = np.diff(t)
    if (dt <= 0).any():
        i = int(np.flatnonzero(dt <= 0)[0]) + 1
        raise DataError(
            f"time is not strictly increasing ({float(t[i - 1])!r} then {float(t[i])!r})",
            file=path,
            row=int(body.index[i]),
            column="time",
        )
    return t, data[:, 1]


def _align(
    t_ref: np.ndarray, t: np.ndarray, v: np.ndarray, join: str, tol: float, path: Path
) -> tuple[np.ndarray, np.ndarray]:
    """Values of one channel at the reference times, and which reference rows have one."""
    if join == "exact":
        if t.shape != t_ref.shape or not np.array_equal(t, t_ref):
            n = min(len(t), len(t_ref))
            diff = np.flatnonzero(t[:n] != t_ref[:n])
            row = int(diff[0]) + 1 if diff.size else n + 1
            raise DataError(
                f"time stamps differ from the reference channel's (join='exact'); use "
                f"join='nearest' or 'linear' ({len(t)} rows against {len(t_ref)})",
                file=path,
                row=row,
                column="time",
            )
        return v, np.ones(len(t_ref), dtype=bool)
    if join == "linear":
        ok = (t_ref >= t[0]) & (t_ref <= t[-1])
        return np.interp(t_ref, t, v), ok
    right = (
        np.clip(np.searchsorted(t, t_ref), 1, len(t) - 1)
        if len(t) > 1
        else np.zeros(len(t_ref), dtype=int)
    )
    left = np.maximum(right - 1, 0)
    pick = np.where(np.abs(t[left] - t_ref) <= np.abs(t[right] - t_ref), left, right)
    return v[pick], np.abs(t[pick] - t_ref) <= tol


def _runs(
    folder: Path, patterns: Mapping[str, str]
) -> tuple[dict[tuple[str, ...], dict[str, Path]], tuple[str, ...]]:
    """Run key (field values) -> quantity -> file, and the field names."""
    files = sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file())
    compiled = {q: compile_pattern(p) for q, p in patterns.items()}
    names = {q: set(f) for q, (_, f) in compiled.items()}
    fields = next(iter(compiled.values()))[1]
    for q, f in names.items():
        if f != set(fields):
            raise ConfigError(
                f"every channel pattern must name the same fields; {q}='{patterns[q]}' has "
                f"{{{', '.join(sorted(f))}}}, not {{{', '.join(fields)}}}"
            )
    runs: dict[tuple[str, ...], dict[str, Path]] = {}
    owner: dict[str, str] = {}  # file -> the quantity whose pattern matched it
    for q, (rx, _) in compiled.items():
        found: dict[tuple[str, ...], list[str]] = {}
        for rel in files:
            m = rx.fullmatch(rel)
            if m is None:
                continue
            if rel in owner:
                raise ConfigError(
                    f"{folder}: file '{rel}' matches both the {owner[rel]} pattern "
                    f"'{patterns[owner[rel]]}' and the {q} pattern '{patterns[q]}'; each "
                    "channel needs its own files"
                )
            owner[rel] = q
            found.setdefault(tuple(m.group(f) for f in fields), []).append(rel)
        if not found:
            raise DataError(f"no file matches {q} pattern '{patterns[q]}'", file=folder)
        for key, rels in found.items():
            if len(rels) > 1:
                raise ConfigError(_ambiguous(folder, q, patterns[q], fields, key, rels))
            runs.setdefault(key, {})[q] = folder / rels[0]
    return runs, fields


def _ambiguous(
    folder: Path,
    quantity: str,
    pattern: str,
    fields: tuple[str, ...],
    key: tuple[str, ...],
    rels: list[str],
) -> str:
    """The message for a pattern that matches several files of one run."""
    shown = ", ".join(repr(r) for r in rels[:4]) + (
        f" and {len(rels) - 4} more" if len(rels) > 4 else ""
    )
    run = (
        "{" + ", ".join(f"{f}={v!r}" for f, v in zip(fields, key, strict=True)) + "}"
        if fields
        else "(the patterns have no {field})"
    )
    return (
        f"{folder}: the {quantity} pattern '{pattern}' matches {len(rels)} files of one run "
        f"{run}: {shown}; put a {{field}} where their names differ (e.g. {{run}} or "
        "{speed}) so that each run is one set of files"
    )


def read_channels(
    folder: str | os.PathLike[str],
    channels: Mapping[str, str] | None = None,
    units: Mapping[str, str] | None = None,
    *,
    joint: str | None = None,
    join: str = "nearest",
    tolerance: float | None = None,
    time_unit: str = "s",
    temperature: float | None = None,
    torque_constant: float | None = None,
) -> list[RawLog]:
    """Read a folder of per-channel ``time value`` files as one raw log per run.

    Parameters
    ----------
    folder : str or os.PathLike
        The folder (searched recursively; files never modified).
    channels : mapping of str to str
        Quantity -> file-name pattern (see the module docstring). Quantities: velocity or
        position (one required; velocity is then central differences of position), torque or
        current (one required), temperature (optional).
    units : mapping of str to str
        Quantity -> unit of its value column, for every quantity in ``channels``.
    joint : str, optional
        The value of a ``{joint}`` field to read, when the folder holds several joints.
    join : {"exact", "nearest", "linear"}
        How channels are joined on time (module docstring).
    tolerance : float, optional
        ``join="nearest"``: the largest time difference [s] accepted; default half the median
        sample period of the reference channel.
    time_unit : str
        Unit of every file's time column (default s).
    temperature : float, optional
        Constant temperature [degC] without a temperature channel; without either, the log
        records none (:data:`fricid.samples.NO_TEMPERATURE_SOURCE`).
    torque_constant : float, optional
        K [N m/A] of tau = K I (eq. 13 of the BAS-RBFNN paper) for a current channel.

    Returns
    -------
    list of RawLog
        One per run, sorted by the fields' values (numerically where they are numbers); a
        log's ``meta`` holds its ``run`` (field -> value), ``files``, ``join`` (what was done)
        and ``rows_dropped`` (reference rows without a partner).

    Raises
    ------
    ConfigError
        An unknown quantity, join or unit, a missing unit, patterns naming different fields,
        no velocity/position or torque/current channel, several joints without ``joint=``; a
        pattern that matches several files of one run (no field tells them apart: the
        pattern and a few files named), a file that matches the patterns of two channels.
    DataError
        No file for a pattern, a run missing a channel (naming the run), a bad cell (file,
        row, column), time not increasing, time stamps that differ with ``join="exact"``.
    """
    folder = Path(folder)
    check_input(folder, folder=True, what="folder of per-channel files (--format channels)")
    if not channels:
        raise ConfigError(
            "reading per-channel files needs a pattern per quantity (--channels "
            "QUANTITY=PATTERN:UNIT, channels= in Python)"
        )
    patterns = dict(channels)
    units = dict(units or {})
    unknown = [q for q in patterns if q not in CHANNEL_QUANTITIES]
    if unknown:
        raise ConfigError(
            f"unknown channel quantity '{unknown[0]}'; choose among {', '.join(CHANNEL_QUANTITIES)}"
        )
    if "velocity" not in patterns and "position" not in patterns:
        raise ConfigError("channels need a velocity or a position pattern")
    if "torque" not in patterns and "current" not in patterns:
        raise ConfigError("channels need a torque or a current pattern")
    if join not in JOINS:
        raise ConfigError(f"join must be one of {', '.join(JOINS)}; got '{join}'")
    if tolerance is not None and not (np.isfinite(tolerance) and tolerance > 0):
        raise ConfigError(f"tolerance must be a positive number of seconds, got {tolerance!r}")
    for q in patterns:
        unit = units.get(q)
        if unit is None:
            raise ConfigError(
                f"no unit for the {q} channel; write it as {q}=PATTERN:UNIT with one of: "
                + ", ".join(UNITS[q])
            )
        if unit not in UNITS[q]:
            raise ConfigError(f"unknown {q} unit '{unit}'; allowed: {', '.join(UNITS[q])}")
    if time_unit not in UNITS["time"]:
        raise ConfigError(f"unknown time unit '{time_unit}'; allowed: {', '.join(UNITS['time'])}")
    if "temperature" in patterns and temperature is not None:
        raise ConfigError(
            "give the temperature either as a channel or as a constant [degC], not both"
        )
    runs, fields = _runs(folder, patterns)
    if "joint" in fields:
        joints = sorted({key[fields.index("joint")] for key in runs}, key=_sort_key)
        if joint is not None:
            if joint not in joints:
                raise ConfigError(
                    f"no joint '{joint}' in {folder}; its joints: {', '.join(joints)}"
                )
            runs = {k: v for k, v in runs.items() if k[fields.index("joint")] == joint}
        elif len(joints) > 1:
            raise ConfigError(f"{folder} holds joints {', '.join(joints)}; choose one with --joint")
    elif joint is not None:
        raise ConfigError("joint= selects a {joint} field, which the channel patterns lack")
    logs = []
    for key in sorted(runs, key=lambda k: tuple(_sort_key(v) for v in k)):
        logs.append(
            _read_run(
                dict(zip(fields, key, strict=True)),
                runs[key],
                patterns,
                units,
                join,
                tolerance,
                time_unit,
                temperature,
                torque_constant,
            )
        )
    return logs


def _read_run(
    run: dict[str, str],
    files: dict[str, Path],
    patterns: Mapping[str, str],
    units: Mapping[str, str],
    join: str,
    tolerance: float | None,
    time_unit: str,
    temperature: float | None,
    torque_constant: float | None,
) -> RawLog:
    missing = [q for q in patterns if q not in files]
    if missing:
        have = ", ".join(str(p) for p in files.values())
        raise DataError(
            f"run {run} has no {missing[0]} file (pattern '{patterns[missing[0]]}'); "
            f"it has: {have}",
            file=next(iter(files.values())).parent,
        )
    raw = {}
    for q, path in files.items():
        t, v = _read_two_columns(path, q)
        raw[q] = (
            np.asarray(to_si(t, time_unit, "time"), dtype=float),
            np.asarray(to_si(v, units[q], q), dtype=float),
        )
    ref = "velocity" if "velocity" in raw else "position"
    t_ref = raw[ref][0]
    if len(t_ref) < 2:
        raise DataError("a run needs at least two rows", file=files[ref])
    tol = 0.5 * float(np.median(np.diff(t_ref))) if tolerance is None else float(tolerance)
    keep = np.ones(len(t_ref), dtype=bool)
    values = {ref: raw[ref][1]}
    for q, (t, v) in raw.items():
        if q != ref:
            values[q], ok = _align(t_ref, t, v, join, tol, files[q])
            keep &= ok
    if keep.sum() < 2:
        raise DataError(
            f"the channels of run {run} share fewer than two time stamps (join='{join}', "
            f"tolerance {tol:g} s)",
            file=files[ref],
        )
    if not keep.all():
        warnings.warn(
            f"{files[ref].parent}: run {run}: {int((~keep).sum())} of {len(keep)} {ref} time "
            f"stamps have no sample of every channel (join='{join}', tolerance {tol:g} s); "
            "those rows are dropped",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )
    t_ref = t_ref[keep]
    values = {q: v[keep] for q, v in values.items()}
    stated = {
        "exact": "exact time stamps",
        "nearest": f"nearest sample within {tol:g} s of the {ref} time stamps",
        "linear": f"linear interpolation at the {ref} time stamps",
    }[join]
    velocity = values.get("velocity")
    if velocity is None:
        velocity = np.gradient(values["position"], t_ref)
    position = values.get("position")
    if position is None:
        position = integrate_velocity(t_ref, velocity)
    constant, source = constant_temperature(temperature)
    return RawLog(
        time=t_ref,
        position=position,
        velocity=velocity,
        temperature=values.get("temperature", constant),
        torque=values.get("torque"),
        current=values.get("current"),
        torque_constant=torque_constant,
        joint=run.get("joint", "joint"),
        source=str(files[ref]),
        meta={
            "format": "channels",
            "run": run,
            "files": {q: str(p) for q, p in files.items()},
            "units": {**dict(units), "time": time_unit},
            "join": stated,
            "rows_dropped": int((~keep).sum()),
            "velocity_source": "channel" if "velocity" in values else "central differences",
            "position_source": "channel" if "position" in values else "integrated velocity",
            **({} if "temperature" in values else {"temperature_source": source}),
        },
    )
