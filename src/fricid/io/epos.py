"""Maxon EPOS Studio data-recorder CSV export.

The format, as EPOS Studio 3.x writes it (``;``-separated, CRLF line ends)::

    Date:;2020-07-08 21:28:28
    Firmware Version:;0x0120;0x6150;0x0000;0x0000
    ...
    Sampling period:;128.000                 (ms)
    Scale:;0;True;2.000;6.000;-14.000;2.000   (optional, repeated)
    ;Velocity actual value averaged;Torque actual value averaged
    ms;rpm;%
    0.000;-1;-32.8
    128.000;-7;-22.8

:func:`read_epos` turns one file into a :class:`~fricid.samples.RawLog` in SI units;
:func:`read_epos_dir` reads a folder of them; :func:`epos_steady_samples` turns a folder of
steady-state recordings (one constant velocity per file), or one such recording, into friction
samples, dropping outlier rows and warning about them (the robust statistics are in
:mod:`._steady`); :func:`steady_recording` says whether a recording is one steady point.

The file's text (its header, data rows and a spreadsheet's re-save with ``skip_bad_rows``) is
parsed by :mod:`._epos_text`; this module gives the parsed channels their units and meaning.
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError, FricidError
from ..metrics import sem_autocorrelated
from ..samples import FrictionSamples, RawLog, constant_temperature
from ..units import UNITS, to_si
from ._epos_text import (
    _COUNT_UNITS,
    _NOT_ACTUAL,
    _QUANTITIES,
    _TIME_ALIASES,
    _TORQUE_FRACTION,
    FORMAT,
    _parse,
    _Recording,
    _warn_bad_rows,
)
from ._files import check_input
from ._steady import (
    OUTLIER_SIGMAS,
    SCATTER_RATIO,
    high_scatter,
    one_operating_point,
    outliers,
    quality_rows,
    warn_steady,
)
from .generic import integrate_velocity

__all__ = [
    "DEFAULT_NOMINAL_TORQUE",
    "OUTLIER_SIGMAS",
    "SCATTER_RATIO",
    "SEM_CAVEAT",
    "SEM_METHOD",
    "epos_steady_samples",
    "read_epos",
    "read_epos_dir",
    "steady_recording",
]

logger = logging.getLogger(__name__)

#: Nominal torque [N m] of the Maxon motor in the lead-screw recordings of
#: Mablekos-Alexiou et al. (IEEE T-RO 2021), 9.84 mNm: the reference of their ``%`` torque.
DEFAULT_NOMINAL_TORQUE = 9.84e-3


def _pick_channels(channels: list[str]) -> dict[str, int]:
    """Which column holds each quantity: names containing 'velocity', 'torque', ...

    When several match, an 'actual' value beats anything else and an 'averaged' one beats a
    plain one; demand, target and command values are never taken for measurements.
    """
    picked: dict[str, int] = {}
    for quantity in _QUANTITIES:
        best, best_score = None, -1
        for j, name in enumerate(channels[1:], start=1):
            low = name.lower()
            if quantity not in low or any(word in low for word in _NOT_ACTUAL):
                continue
            score = 2 * ("actual" in low) + ("averaged" in low)
            if score > best_score:
                best, best_score = j, score
        if best is not None:
            picked[quantity] = best
    return picked


def _unknown_unit(rec: _Recording, j: int, known: Iterable[str], path: Path) -> DataError:
    return DataError(
        f"unknown unit '{rec.units[j]}' for channel '{rec.channels[j]}'; known: {', '.join(known)}",
        file=path,
        row=rec.units_line,
        column=rec.channels[j],
    )


def _convert(
    rec: _Recording,
    j: int,
    quantity: str,
    path: Path,
    nominal_torque: float,
    counts_per_turn: float | None,
) -> np.ndarray:
    """Column ``j`` of the recording in SI, by its unit in the units line."""
    unit, values = rec.units[j], rec.data[:, j]
    if quantity == "time":
        unit = _TIME_ALIASES.get(unit, unit)
    if quantity == "torque" and unit in _TORQUE_FRACTION:
        return values * (_TORQUE_FRACTION[unit] * nominal_torque)
    if quantity == "position" and unit in _COUNT_UNITS:
        if counts_per_turn is None:
            raise ConfigError(
                f"{path}: the position channel is in encoder counts ('{unit}'); pass "
                "counts_per_turn (e.g. 4 x encoder lines for quadrature counts)"
            )
        return values * (2.0 * math.pi / counts_per_turn)
    if unit not in UNITS[quantity]:
        known = list(UNITS[quantity])
        if quantity == "torque":
            known = [*_TORQUE_FRACTION, *known]
        elif quantity == "position":
            known = [*_COUNT_UNITS, *known]
        raise _unknown_unit(rec, j, known, path)
    return np.asarray(to_si(values, unit, quantity), dtype=float)


def _positive(name: str, value: float | None) -> None:
    if value is not None and not (np.isfinite(value) and value > 0):
        raise ConfigError(f"{name} must be a positive number, got {value!r}")


def read_epos(
    path: str | os.PathLike[str],
    *,
    nominal_torque: float = DEFAULT_NOMINAL_TORQUE,
    flip_sign: bool = False,
    temperature: float | None = None,
    torque_constant: float | None = None,
    counts_per_turn: float | None = None,
    joint: str = "joint",
    skip_bad_rows: bool = False,
) -> RawLog:
    """Read one EPOS Studio data-recorder CSV export as a raw log in SI units.

    Parameters
    ----------
    path : the exported file (never modified).
    nominal_torque : the motor's nominal torque [N m], the reference of a torque channel in
        ``%`` (or per mille). Default 9.84 mNm, the motor of the lead-screw recordings.
    flip_sign : negate every motion and effort channel. The lead-screw recordings need it to
        match their file names (``N.csv`` is +N rpm): their authors' converter flips both
        velocity and torque (motor convention).
    temperature : [degC], constant; the recorder has no temperature channel. Without one the
        log's temperature column is a placeholder (:data:`fricid.samples.NO_TEMPERATURE`),
        ``meta["temperature_source"]`` says it is none, and the samples extracted from the log
        record no temperature rather than a made-up one.
    torque_constant : K [N m/A], needed when only a current channel was recorded.
    counts_per_turn : encoder counts per revolution, needed for a position channel in counts.
    joint : name for the log.
    skip_bad_rows : drop a data row with a malformed cell or the wrong number of fields
        (``--skip-bad-rows``) instead of refusing the file; the rows dropped are counted and
        listed in a :class:`~fricid.errors.DataQualityWarning` and in ``meta["skipped_rows"]``.

    Returns
    -------
    RawLog
        Channels are found by name (velocity, torque or current, position). Without a
        position channel, position is the trapezoidal integral of velocity, starting at 0.
        ``meta`` holds the header (``Key:`` -> value text; repeated keys, such as ``Scale``,
        -> list), the channel names and units used, and the conversion options.

    Raises
    ------
    DataError
        Naming file, line and column: no channel or units line, an unknown unit of a used
        channel, a number-like but malformed value, a short row, time not increasing.
        A text line in or after the data block (a typed comment) is skipped with a warning.
        A spreadsheet's re-save (trailing empty fields ``-1200,,`` on every line, or ``,``
        as the separator) is read as the original.
    """
    return _read(
        path,
        nominal_torque=nominal_torque,
        flip_sign=flip_sign,
        temperature=temperature,
        torque_constant=torque_constant,
        counts_per_turn=counts_per_turn,
        joint=joint,
        skip_bad_rows=skip_bad_rows,
    )[0]


def _read(
    path: str | os.PathLike[str],
    *,
    nominal_torque: float = DEFAULT_NOMINAL_TORQUE,
    flip_sign: bool = False,
    temperature: float | None = None,
    torque_constant: float | None = None,
    counts_per_turn: float | None = None,
    joint: str = "joint",
    skip_bad_rows: bool = False,
) -> tuple[RawLog, np.ndarray]:
    """:func:`read_epos`, also returning the 1-based line number of each data row."""
    path = Path(path)
    _positive("nominal_torque", nominal_torque)
    _positive("counts_per_turn", counts_per_turn)
    rec = _parse(path, skip_bad_rows)
    _warn_bad_rows(path, rec.skipped)
    picked = _pick_channels(rec.channels)
    if "velocity" not in picked:
        raise DataError(f"no velocity channel among {rec.channels[1:]}", file=path)
    if "torque" not in picked and "current" not in picked:
        raise DataError(f"no torque or current channel among {rec.channels[1:]}", file=path)

    def si(quantity: str, j: int) -> np.ndarray:
        return _convert(rec, j, quantity, path, nominal_torque, counts_per_turn)

    time = si("time", 0)
    dt = np.diff(time)
    if (dt <= 0).any():
        i = int(np.flatnonzero(dt <= 0)[0]) + 1
        raise DataError(
            "time is not strictly increasing "
            f"({float(rec.data[i - 1, 0])!r} then {float(rec.data[i, 0])!r})",
            file=path,
            row=int(rec.lines[i]),
            column="time",
        )
    sign = -1.0 if flip_sign else 1.0
    values = {q: sign * si(q, j) for q, j in picked.items()}
    position = values.get("position")
    meta = {
        "format": FORMAT,
        "header": rec.header,
        "channels": {q: rec.channels[j] for q, j in picked.items()},
        "units": {q: rec.units[j] for q, j in picked.items()},
        "flip_sign": bool(flip_sign),
        "nominal_torque [N m]": float(nominal_torque),
        "position_source": "channel" if position is not None else "integrated velocity",
        "temperature_source": constant_temperature(temperature)[1],
        "skipped_rows": rec.skipped,
    }
    log = RawLog(
        time=time,
        position=integrate_velocity(time, values["velocity"]) if position is None else position,
        velocity=values["velocity"],
        temperature=constant_temperature(temperature)[0],
        torque=values.get("torque"),
        current=values.get("current"),
        torque_constant=torque_constant,
        joint=joint,
        source=str(path),
        meta=meta,
    )
    return log, rec.lines


def _files(folder: str | os.PathLike[str], pattern: str) -> list[Path]:
    folder = Path(folder)
    if folder.is_file():  # one recording
        check_input(folder, what="EPOS recording")
        return [folder]
    check_input(folder, folder=True, what="folder of EPOS recordings")
    files = sorted(p for p in folder.glob(pattern) if p.is_file())
    if not files:
        raise DataError(f"no files matching '{pattern}'", file=folder)
    return files


def steady_recording(path: str | os.PathLike[str]) -> bool:
    """Whether the EPOS recording at ``path`` holds one steady operating point (its velocity
    at rest or moving one way in every row, at one level: :func:`._steady.one_operating_point`),
    as each file of a folder of steady-state recordings is taken to be; then its samples are
    :func:`epos_steady_samples` of it, the same as its folder gives for it. False for a folder
    and for a file that cannot be read as a recording (reading it says why)."""
    path = Path(path)
    if not path.is_file():
        return False
    try:
        rec = _parse(path, skip_bad_rows=True, quiet=True)
        j = _pick_channels(rec.channels).get("velocity")
        if j is None:
            return False
        velocity = _convert(rec, j, "velocity", path, DEFAULT_NOMINAL_TORQUE, None)
    except (FricidError, OSError):
        return False
    return one_operating_point(velocity)


def read_epos_dir(
    folder: str | os.PathLike[str], *, pattern: str = "*.csv", **options: Any
) -> list[RawLog]:
    """Read every EPOS export in ``folder`` (one :func:`read_epos` per file).

    The logs are sorted by set-point, taken as each file's mean velocity (signed, after
    ``flip_sign``); file names are not interpreted. ``options`` go to :func:`read_epos`.
    """
    return [log for log, _ in _read_dir(folder, pattern, **options)]


#: How ``epos_steady_samples`` estimates each file's standard error (``meta["sem_method"]``).
SEM_METHOD = "within-run, autocorrelation-corrected"

#: What that estimate leaves out (``meta["sem_caveat"]``).
SEM_CAVEAT = "one run per set-point: offsets between runs are not in it"


def _read_dir(folder, pattern: str, **options: Any) -> list[tuple[RawLog, np.ndarray]]:
    """(log, data line numbers) of every file, sorted by mean velocity."""
    read = [_read(path, **options) for path in _files(folder, pattern)]
    return sorted(read, key=lambda item: float(np.mean(item[0].velocity)))


def epos_steady_samples(
    folder: str | os.PathLike[str],
    *,
    pattern: str = "*.csv",
    nominal_torque: float = DEFAULT_NOMINAL_TORQUE,
    flip_sign: bool = False,
    temperature: float | None = None,
    load: float = 0.0,
    torque_constant: float | None = None,
    counts_per_turn: float | None = None,
    outlier_sigmas: float | None = OUTLIER_SIGMAS,
    skip_bad_rows: bool = False,
) -> FrictionSamples:
    """Friction samples from a folder of steady-state EPOS recordings, one point per file
    (or from one such recording, :func:`steady_recording`).

    Each file is taken as one constant-velocity operating point already in steady state
    (as in the lead-screw recordings): friction is the mean motor torque over the file's rows
    that are not outliers (in torque or in velocity), velocity the mean velocity over the same
    rows, direction the sign of
    the mean velocity, count the rows averaged and std their torque's sample standard
    deviation. Load and temperature are the given constants (the recorder logs neither); with
    no temperature given the samples have none (not measured, ``meta["temperature_source"]``
    says so), rather than a made-up one printed as data downstream.

    Parameters
    ----------
    folder : str or os.PathLike
        The folder of recordings, or one recording (never modified).
    pattern : str
        Glob of the files to read in a folder.
    nominal_torque, flip_sign, temperature, torque_constant, counts_per_turn
        As for :func:`read_epos`.
    load : float
        N m, the load recorded with every sample.
    outlier_sigmas : float or None
        Rows whose torque, or velocity, is further than this many robust standard deviations
        (1.4826 MAD) from the file's median are dropped (default :data:`OUTLIER_SIGMAS`, 8);
        None keeps every row.
    skip_bad_rows : bool
        As for :func:`read_epos`; ``meta["skipped_rows"]`` lists the rows dropped, per file.

    Returns
    -------
    FrictionSamples
        ``meta["quality"]`` holds one row per file (the columns of
        :data:`fricid.extract.QUALITY_COLUMNS`: rows kept, outliers dropped, scatter, and
        whether the scatter is far above the neighbours'); ``meta["outlier_lines"]`` the
        1-based line numbers of the dropped rows, per file (``meta["velocity_outlier_lines"]``
        those dropped for their velocity); ``meta["sem"]`` each file's
        standard error of the mean torque [N m] (:func:`fricid.metrics.sem_autocorrelated` of
        its kept rows, in time order; None for fewer than 4 rows), with ``meta["sem_method"]``
        and ``meta["sem_caveat"]`` saying how it was estimated
        (:func:`fricid.identify.validate.measurement_scatter` prefers it).

    Raises
    ------
    DataError
        For a file whose mean velocity is zero (no direction of motion).

    Warns
    -----
    DataQualityWarning
        Naming the file, the set-point and the lines, when rows were dropped as outliers or a
        file's scatter is more than :data:`SCATTER_RATIO` times its neighbours'.

    Notes
    -----
    The lead-screw folder (32 files, 16 per direction) gives, as recorded
    (``flip_sign=False``, the drive's sign convention): +3.56 mNm at +2.14 rpm (``n2.csv``)
    and -2.77 mNm at -2.07 rpm (``2.csv``). With ``flip_sign=True`` (the authors' convention,
    ``N.csv`` is +N rpm) the same two points read +2.77 mNm at +2.07 rpm and -3.56 mNm at
    -2.14 rpm: which direction has the larger friction depends on the sign convention chosen.
    No row of it is an outlier.
    """
    if outlier_sigmas is not None and not (np.isfinite(outlier_sigmas) and outlier_sigmas > 0):
        raise ConfigError(
            f"outlier_sigmas must be a positive number or None, got {outlier_sigmas!r}"
        )
    read = _read_dir(
        folder,
        pattern,
        nominal_torque=nominal_torque,
        flip_sign=flip_sign,
        temperature=temperature,
        torque_constant=torque_constant,
        counts_per_turn=counts_per_turn,
        skip_bad_rows=skip_bad_rows,
    )
    out = [outliers(log.motor_torque, log.velocity, outlier_sigmas) for log, _ in read]
    keep = [~(t | v) for t, v in out]
    velocity = np.array([np.mean(log.velocity[k]) for (log, _), k in zip(read, keep, strict=True)])
    order = np.argsort(velocity, kind="stable")  # by the velocity without its glitches
    read, out, keep = ([x[i] for i in order] for x in (read, out, keep))
    logs, velocity = [log for log, _ in read], velocity[order]
    zero = np.flatnonzero(velocity == 0)
    if zero.size:
        raise DataError(
            "mean velocity is zero: not a constant-velocity recording", file=logs[zero[0]].source
        )
    torque = [log.motor_torque[k] for log, k in zip(logs, keep, strict=True)]
    std = np.array([np.std(t, ddof=1) if len(t) > 1 else 0.0 for t in torque])
    flagged = high_scatter(velocity, std, SCATTER_RATIO)
    names = [Path(log.source).name for log in logs]
    dropped_lines, torque_lines, velocity_lines = (
        {
            name: [int(x) for x in lines[rows]]
            for name, (_, lines), rows in zip(names, read, masks, strict=True)
            if rows.any()
        }
        for masks in ([~k for k in keep], [t for t, _ in out], [v for _, v in out])
    )
    quality = quality_rows(names, velocity, keep, std, flagged, temperature)
    warn_steady(str(folder), quality, torque_lines, velocity_lines)
    sem = [sem_autocorrelated(t) for t in torque]
    return FrictionSamples(
        velocity=velocity,
        load=load,
        temperature=temperature,
        friction=np.array([np.mean(t) for t in torque]),
        direction=np.sign(velocity),
        count=np.array([len(t) for t in torque]),
        std=std,
        source=str(folder),
        meta={
            "format": FORMAT,
            "method": "steady state: per-file mean torque and velocity, outlier rows dropped",
            "files": names,
            "flip_sign": bool(flip_sign),
            "nominal_torque [N m]": float(nominal_torque),
            "temperature_source": constant_temperature(temperature)[1],
            "outlier_sigmas": outlier_sigmas,
            "outlier_lines": dropped_lines,
            "velocity_outlier_lines": velocity_lines,
            "skipped_rows": {
                name: log.meta["skipped_rows"]
                for name, log in zip(names, logs, strict=True)
                if log.meta["skipped_rows"]
            },
            "quality": quality,
            "sem": [float(x) if np.isfinite(x) else None for x in sem],
            "sem_method": SEM_METHOD,
            "sem_caveat": SEM_CAVEAT,
        },
    )
