"""The two data types that travel through fricid: :class:`RawLog` and :class:`FrictionSamples`.

Both hold SI units only (DESIGN.md, "Units") and validate themselves on construction, so a
value of either type is always safe to use. Reading and writing them is :mod:`fricid.io`'s job.

The module is longer than 500 lines because it holds both types with their validation (shapes,
finite values, the physically possible ranges of :data:`LIMITS`, each error naming its row and
column): the checks are the types' contract and belong beside them.
"""

from __future__ import annotations

import copy
import hashlib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .errors import ConfigError, DataError

__all__ = [
    "LIMITS",
    "OPTIONAL_INPUTS",
    "RAWLOG_COLUMNS",
    "SAMPLE_COLUMNS",
    "FrictionSamples",
    "RawLog",
]

#: Model inputs a :class:`FrictionSamples` may lack (not measured: all NaN).
OPTIONAL_INPUTS: tuple[str, ...] = ("load", "temperature")

#: Columns of a :class:`FrictionSamples` table and their units.
SAMPLE_COLUMNS: dict[str, str] = {
    "velocity": "rad/s",
    "load": "N m",
    "temperature": "degC",
    "friction": "N m",
    "direction": "1",
    "count": "1",
    "std": "N m",
}

#: Columns of a :class:`RawLog` and their units (``torque`` or ``current``, or both, present).
RAWLOG_COLUMNS: dict[str, str] = {
    "time": "s",
    "position": "rad",
    "velocity": "rad/s",
    "torque": "N m",
    "current": "A",
    "temperature": "degC",
}


#: Physically possible range of each column, ``(low, high, unit)`` in SI. Values outside it
#: are not measurements (a unit mistake, a corrupt file, an overflow): absolute zero below,
#: and above, bounds no joint reaches (1e6 rad/s is about 10 million rpm) that still leave
#: products such as friction x velocity far from floating-point overflow.
LIMITS: dict[str, tuple[float, float, str]] = {
    "time": (-1e10, 1e10, "s"),
    "position": (-1e12, 1e12, "rad"),
    "velocity": (-1e6, 1e6, "rad/s"),
    "torque": (-1e9, 1e9, "N m"),
    "current": (-1e6, 1e6, "A"),
    "temperature": (-273.15, 1e4, "degC"),
    "load": (-1e9, 1e9, "N m"),
    "friction": (-1e9, 1e9, "N m"),
    "count": (1.0, 2.0**53, "1"),
    "std": (0.0, 1e9, "N m"),
    "torque_constant": (0.0, 1e6, "N m/A"),
}


def _check_range(name: str, arr: np.ndarray, source: str | None) -> None:
    """Raise :class:`DataError` for the first value of column ``name`` outside :data:`LIMITS`."""
    low, high, unit = LIMITS[name]
    u = "" if unit == "1" else f" {unit}"
    bad = (arr < low) | (arr > high)
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        what = "below absolute zero" if name == "temperature" and arr[row] < low else "impossible"
        raise DataError(
            f"{what} value {float(arr[row])!r}{u}; {name} must lie in [{low:g}, {high:g}]{u} "
            "(a unit mistake or a corrupt file?)",
            file=source,
            row=row,
            column=name,
        )


def _as_column(name: str, values: Any, n: int | None, source: str | None) -> np.ndarray:
    """``values`` as a finite float column of ``n`` rows (a scalar is broadcast).

    Raises
    ------
    DataError
        Not one-dimensional, the wrong length, or a non-finite value (its row named).
    """
    arr = np.asarray(values, dtype=float)
    if arr.ndim == 0:
        arr = np.full(n if n is not None else 1, float(arr))
    if arr.ndim != 1:
        raise DataError(f"must be one-dimensional, got shape {arr.shape}", file=source, column=name)
    if n is not None and arr.shape[0] != n:
        raise DataError(f"has {arr.shape[0]} values, expected {n}", file=source, column=name)
    bad = ~np.isfinite(arr)
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise DataError(f"non-finite value {arr[row]!r}", file=source, row=row, column=name)
    if name in LIMITS and name not in ("count", "std"):  # checked after their own rules
        _check_range(name, arr, source)
    return arr


def _optional_column(name: str, values: Any, n: int, source: str | None) -> np.ndarray:
    """An optional input of :class:`FrictionSamples`: None or all NaN -> all NaN (not
    measured), else a finite column (:func:`_as_column`)."""
    if values is None:
        return np.full(n, np.nan)
    arr = np.asarray(values, dtype=float)
    if arr.size and np.isnan(arr).all():
        shape_checked = _as_column(name, np.zeros_like(arr), n, source)
        return np.full_like(shape_checked, np.nan)
    return _as_column(name, values, n, source)


#: The array columns of a :class:`RawLog`.
_COLUMNS = ("time", "position", "velocity", "temperature", "torque", "current")


@dataclass(frozen=True, eq=False)
class RawLog:
    """A joint's raw log: one row per sample, SI units.

    The columns are converted to float arrays and checked on construction; the object is
    frozen, so a ``RawLog`` is always valid.

    Parameters
    ----------
    time : array_like, shape (n,)
        Time [s], strictly increasing.
    position : array_like, shape (n,)
        Joint position [rad].
    velocity : array_like, shape (n,)
        Joint velocity [rad/s].
    temperature : array_like, shape (n,) or scalar
        Temperature [degC]; a scalar is broadcast to every row.
    torque : array_like, shape (n,), optional
        Motor torque [N m]; None when only the current was logged.
    current : array_like, shape (n,), optional
        Motor current [A]; None when the torque was logged.
    torque_constant : float, optional
        K [N m/A] of eq. 13 (BAS-RBFNN paper), tau = K I. Needed when only the current was
        logged.
    joint : str, default "joint"
        The joint's name, for messages and provenance.
    source : str, optional
        Where the log came from (a file name), for messages and provenance.
    meta : mapping, optional
        Anything else worth keeping (free-form).

    Raises
    ------
    DataError
        A column of the wrong shape or length, a non-finite value, time not strictly
        increasing (the row named), neither torque nor current, or current without a positive
        torque constant.

    See Also
    --------
    fricid.io.read_rawlog, fricid.io.write_rawlog : the log as a CSV or Parquet table.

    Examples
    --------
    >>> log = RawLog(time=[0.0, 0.1], position=[0.0, 0.01], velocity=0.1, temperature=25.0,
    ...              torque=[0.2, 0.21])
    >>> len(log), float(log.motor_torque[1])
    (2, 0.21)
    """

    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    temperature: np.ndarray
    torque: np.ndarray | None = None
    current: np.ndarray | None = None
    torque_constant: float | None = None
    joint: str = "joint"
    source: str | None = None
    meta: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        src = self.source
        time = _as_column("time", self.time, None, src)
        n = time.shape[0]
        set_ = object.__setattr__
        set_(self, "time", time)
        # velocity before position: readers may integrate position from it
        for name in ("velocity", "position", "temperature"):
            set_(self, name, _as_column(name, getattr(self, name), n, src))
        if self.torque is None and self.current is None:
            raise DataError("the log has neither a torque nor a current column", file=src)
        for name in ("torque", "current"):
            if getattr(self, name) is not None:
                set_(self, name, _as_column(name, getattr(self, name), n, src))
        k = self.torque_constant
        if self.torque is None and k is None:
            raise DataError(
                "only current was logged, so a positive torque constant K [N m/A] is "
                f"needed (tau = K I, eq. 13); got {k!r}",
                file=src,
            )
        if k is not None:
            try:
                k = float(k)
            except (TypeError, ValueError):
                raise DataError(
                    f"the torque constant K must be a number [N m/A], got {k!r}", file=src
                ) from None
            high = LIMITS["torque_constant"][1]
            if not (np.isfinite(k) and 0 < k <= high):
                raise DataError(
                    f"the torque constant K (tau = K I, eq. 13) must lie in (0, {high:g}] "
                    f"N m/A; got {k!r}",
                    file=src,
                )
            set_(self, "torque_constant", k)
        if n > 1:
            dt = np.diff(time)
            bad = np.flatnonzero(dt <= 0)
            if bad.size:
                row = int(bad[0]) + 1
                raise DataError(
                    f"time is not strictly increasing ({time[row - 1]!r} then {time[row]!r})",
                    file=src,
                    row=row,
                    column="time",
                )

    def __len__(self) -> int:
        return int(self.time.shape[0])

    @property
    def motor_torque(self) -> np.ndarray:
        """ndarray, shape (n,): motor torque [N m], the logged torque, else K times the
        current (eq. 13 of the BAS-RBFNN paper)."""
        if self.torque is not None:
            return self.torque
        return self.current * float(self.torque_constant)

    def slice(self, start: int, stop: int) -> RawLog:
        """Rows ``start:stop`` as a new log.

        Parameters
        ----------
        start, stop : int
            The rows, as in ``array[start:stop]``.

        Returns
        -------
        RawLog
            The rows, as views of this log's columns (no copy; not checked again: the rows
            of a valid log are a valid log).
        """
        s = np.s_[start:stop]
        out = copy.copy(self)
        for name in _COLUMNS:
            column = getattr(self, name)
            object.__setattr__(out, name, None if column is None else column[s])
        return out

    @staticmethod
    def concatenate(logs: list[RawLog]) -> RawLog:
        """Join logs end to end.

        Parameters
        ----------
        logs : list of RawLog
            Logs of the same joint in time order; a torque (or current) column is kept only
            if every log has one.

        Returns
        -------
        RawLog
            The rows of all logs; names, torque constant and ``meta`` from the first.

        Raises
        ------
        DataError
            No logs, or time that does not increase across a junction.
        """
        if not logs:
            raise DataError("no logs to concatenate")
        first = logs[0]

        def cat(name: str):
            parts = [getattr(g, name) for g in logs]
            if any(p is None for p in parts):
                return None
            return np.concatenate(parts)

        columns = {name: cat(name) for name in _COLUMNS}
        if columns["torque"] is None and (
            columns["current"] is None or first.torque_constant is None
        ):
            return replace(first, **columns)  # no usable effort: the full check says why
        # each log is valid, so only the junctions need checking
        row = 0
        last = None
        for log in logs:
            if len(log) and last is not None and not log.time[0] > last:
                raise DataError(
                    f"time is not strictly increasing ({last!r} then {log.time[0]!r})",
                    file=first.source,
                    row=row,
                    column="time",
                )
            if len(log):
                last = log.time[-1]
            row += len(log)
        out = copy.copy(first)
        for name, column in columns.items():
            object.__setattr__(out, name, column)
        return out


@dataclass(frozen=True, eq=False)
class FrictionSamples:
    """Friction at operating points: one row per (velocity, load, temperature, direction).

    The model input matrix is :attr:`X`, columns (velocity, load, temperature); the target is
    :attr:`friction`. The columns are checked on construction and the object is frozen.

    Parameters
    ----------
    velocity : array_like, shape (n,)
        Joint velocity [rad/s], n >= 1.
    load : array_like, shape (n,) or scalar, or None
        Load torque [N m] (eq. 7 of the BAS-RBFNN paper: the gravity torque of the link).
        None (or all NaN) when not measured: the column is then all NaN, :attr:`measured`
        leaves it out, and a model that needs it is refused (:meth:`require`).
    temperature : array_like, shape (n,) or scalar, or None
        Temperature [degC]; None (or all NaN) when not measured, as for ``load``.
    friction : array_like, shape (n,)
        Friction torque [N m].
    direction : array_like of {-1, 0, 1}, shape (n,), optional
        +1 or -1 for a sample measured in one direction of motion (velocity and friction
        then carry that sign), 0 when both directions were combined by eq. 11 of the
        BAS-RBFNN paper (velocity and friction are then the positive-direction values).
        Default: the sign of ``velocity``.
    count : array_like of int, shape (n,), optional
        The number of raw samples averaged into each row, >= 1 (default 1).
    std : array_like, shape (n,), optional
        Their standard deviation [N m], >= 0 (default 0).
    source : str, optional
        Where the samples came from (a file name), for messages and provenance.
    meta : mapping, optional
        Anything else worth keeping (copied).

    Raises
    ------
    DataError
        No rows, a column of the wrong shape or length, a non-finite value (in load or
        temperature: some but not all), a direction other than -1, 0, +1, a count below 1
        or a negative std (the row and column named).

    See Also
    --------
    fricid.io.read_samples, fricid.io.write_samples : samples as a CSV or Parquet table.

    Examples
    --------
    >>> s = FrictionSamples(velocity=[-0.1, 0.1], load=0.0, temperature=25.0,
    ...                     friction=[-0.3, 0.3])
    >>> s.directions(), s.X.shape
    ((-1, 1), (2, 3))
    """

    velocity: np.ndarray
    load: np.ndarray | None
    temperature: np.ndarray | None
    friction: np.ndarray
    direction: np.ndarray | None = None
    count: np.ndarray | None = None
    std: np.ndarray | None = None
    source: str | None = None
    meta: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        src = self.source
        set_ = object.__setattr__
        velocity = _as_column("velocity", self.velocity, None, src)
        n = velocity.shape[0]
        if n == 0:
            raise DataError("no friction samples", file=src)
        set_(self, "velocity", velocity)
        for name in ("load", "temperature"):  # optional: None or all NaN is not measured
            set_(self, name, _optional_column(name, getattr(self, name), n, src))
        set_(self, "friction", _as_column("friction", self.friction, n, src))
        direction = (
            np.sign(velocity)
            if self.direction is None
            else _as_column("direction", self.direction, n, src)
        )
        bad = np.flatnonzero(~np.isin(direction, (-1.0, 0.0, 1.0)))
        if bad.size:
            row = int(bad[0])
            raise DataError(
                f"direction must be -1, 0 or +1, got {direction[row]!r}",
                file=src,
                row=row,
                column="direction",
            )
        set_(self, "direction", direction.astype(np.int8))
        count = np.ones(n) if self.count is None else _as_column("count", self.count, n, src)
        if (count < 1).any():
            row = int(np.flatnonzero(count < 1)[0])
            raise DataError(
                f"count must be >= 1, got {count[row]!r}", file=src, row=row, column="count"
            )
        _check_range("count", count, src)
        if (count != np.round(count)).any():
            row = int(np.flatnonzero(count != np.round(count))[0])
            raise DataError(
                f"count must be a whole number, got {count[row]!r}",
                file=src,
                row=row,
                column="count",
            )
        set_(self, "count", count.astype(np.int64))
        std = np.zeros(n) if self.std is None else _as_column("std", self.std, n, src)
        if (std < 0).any():
            row = int(np.flatnonzero(std < 0)[0])
            raise DataError(f"std must be >= 0, got {std[row]!r}", file=src, row=row, column="std")
        _check_range("std", std, src)
        set_(self, "std", std)
        set_(self, "meta", dict(self.meta))

    def __len__(self) -> int:
        return int(self.velocity.shape[0])

    @property
    def measured(self) -> tuple[str, ...]:
        """tuple of str: the model inputs measured, among velocity, load and temperature (an
        input given as None, or all NaN, was not measured)."""
        found = [name for name in OPTIONAL_INPUTS if np.isfinite(getattr(self, name)).all()]
        return ("velocity", *found)

    def require(self, inputs: tuple[str, ...] | list[str], user: str) -> None:
        """Refuse samples that lack an input ``user`` needs.

        Parameters
        ----------
        inputs : sequence of str
            The inputs needed, among velocity, load and temperature.
        user : str
            Who needs them, for the message (e.g. ``"model 'vlt'"``).

        Raises
        ------
        ConfigError
            Naming the first input that was not measured.
        """
        missing = [name for name in inputs if name not in self.measured]
        if missing:
            raise ConfigError(
                f"{user} needs {', '.join(inputs)}, but the samples"
                + (f" ({self.source})" if self.source else "")
                + f" have no {missing[0]} (not measured); choose a model of velocity only "
                "or give samples with that column"
            )

    @property
    def X(self) -> np.ndarray:
        """ndarray, shape (n, 3): the model inputs, columns velocity [rad/s], load [N m],
        temperature [degC]; an input not measured is a column of NaN."""
        return np.column_stack([self.velocity, self.load, self.temperature])

    @property
    def y(self) -> np.ndarray:
        """ndarray, shape (n,): the model target, friction [N m]."""
        return self.friction

    def subset(self, mask: Any) -> FrictionSamples:
        """The rows selected by a boolean mask or an index array.

        Parameters
        ----------
        mask : array_like of bool or int
            A boolean mask of length n, or row indices.

        Returns
        -------
        FrictionSamples
            The selected rows; ``source`` and ``meta`` kept (the per-row standard errors
            ``meta["sem"]`` selected with the rows).

        Raises
        ------
        DataError
            The selection is empty.
        """
        idx = np.asarray(mask)
        meta = self.meta
        sem = meta.get("sem")
        if isinstance(sem, list | tuple) and len(sem) == len(self):
            meta = {**meta, "sem": [sem[i] for i in np.arange(len(self))[idx]]}
        return replace(
            self,
            meta=meta,
            velocity=self.velocity[idx],
            load=self.load[idx],
            temperature=self.temperature[idx],
            friction=self.friction[idx],
            direction=self.direction[idx],
            count=self.count[idx],
            std=self.std[idx],
        )

    def directions(self) -> tuple[int, ...]:
        """The distinct directions present.

        Returns
        -------
        tuple of int
            Sorted, a subset of ``(-1, 0, 1)``.
        """
        return tuple(int(d) for d in np.unique(self.direction))

    def to_frame(self) -> Any:
        """The samples as a table.

        Returns
        -------
        pandas.DataFrame
            One column per key of :data:`SAMPLE_COLUMNS`, SI units.
        """
        import pandas as pd

        return pd.DataFrame({name: getattr(self, name) for name in SAMPLE_COLUMNS})

    @classmethod
    def concatenate(cls, parts: list[FrictionSamples]) -> FrictionSamples:
        """Stack sample tables.

        Parameters
        ----------
        parts : list of FrictionSamples
            The tables, stacked in order.

        Returns
        -------
        FrictionSamples
            All rows; ``source`` and ``meta`` from the first table.

        Raises
        ------
        DataError
            No tables.
        """
        if not parts:
            raise DataError("no samples to concatenate")
        cols = {name: np.concatenate([getattr(p, name) for p in parts]) for name in SAMPLE_COLUMNS}
        return cls(**cols, source=parts[0].source, meta=parts[0].meta)


def samples_hash(samples: FrictionSamples) -> str:
    """A short content hash of the samples, for provenance and caching.

    Parameters
    ----------
    samples : FrictionSamples
        The samples.

    Returns
    -------
    str
        16 hexadecimal digits of the SHA-256 of velocity, load, temperature, friction and
        direction (not count, std, source or meta).
    """
    h = hashlib.sha256()
    for a in (
        samples.velocity,
        samples.load,
        samples.temperature,
        samples.friction,
        samples.direction.astype(float),
    ):
        h.update(np.ascontiguousarray(a, dtype=float).tobytes())
    return h.hexdigest()[:16]
