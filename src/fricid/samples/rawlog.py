""":class:`RawLog`: one joint's time series as a reader gives it, SI units, validated."""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import DataError
from ._columns import LIMITS, _as_column

__all__ = ["NO_TEMPERATURE", "NO_TEMPERATURE_SOURCE", "RawLog", "constant_temperature"]

#: The array columns of a :class:`RawLog`.
_COLUMNS = ("time", "position", "velocity", "temperature", "torque", "current")

#: ``meta["temperature_source"]`` of a log whose recorder logs no temperature and that was
#: given none: its temperature column is a placeholder (a log needs one), not a measurement,
#: and the samples extracted from it record no temperature (:attr:`RawLog.temperature_measured`).
NO_TEMPERATURE_SOURCE = (
    "none: the recorder logs no temperature (give the joint's with --temperature)"
)

#: The placeholder temperature column [degC] of such a log (never recorded as a measurement).
NO_TEMPERATURE = 25.0


def constant_temperature(temperature: float | None) -> tuple[float, str]:
    """The temperature column of a log without a temperature channel and its
    ``meta["temperature_source"]``: the constant given, or :data:`NO_TEMPERATURE` with
    :data:`NO_TEMPERATURE_SOURCE` (the samples extracted from it then record none, rather
    than a made-up 25 degC)."""
    if temperature is None:
        return NO_TEMPERATURE, NO_TEMPERATURE_SOURCE
    return float(temperature), f"constant {float(temperature):g} degC, given (none logged)"


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
                    "time is not strictly increasing "
                    f"({float(time[row - 1])!r} then {float(time[row])!r})",
                    file=src,
                    row=row,
                    column="time",
                )

    def __len__(self) -> int:
        return int(self.time.shape[0])

    @property
    def temperature_measured(self) -> bool:
        """bool: whether the temperature column is the joint's (logged or given), not the
        placeholder of a log without one (``meta["temperature_source"]`` is
        :data:`NO_TEMPERATURE_SOURCE`)."""
        return self.meta.get("temperature_source") != NO_TEMPERATURE_SOURCE

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
                    "time is not strictly increasing "
                    f"({float(last)!r} then {float(log.time[0])!r})",
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
