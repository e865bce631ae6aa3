"""The two data types that travel through fricid: :class:`RawLog` and :class:`FrictionSamples`.

Both hold SI units only (DESIGN.md, "Units") and validate themselves on construction, so a
value of either type is always safe to use. Reading and writing them is :mod:`fricid.io`'s job.

:class:`RawLog` is in :mod:`.rawlog` (all joints of a robot, :class:`RobotLog`, in
:mod:`.robot_log`; several recordings of one robot joined into one by :mod:`.robot_join`),
the columns, units, ranges and column checks both types share in :mod:`._columns`, the
checks a trajectory log passes before identification in :mod:`._trajectory_log`, whether a
log's velocity is its position's derivative in :mod:`._agreement`.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ._agreement import coarse_velocity, velocity_mismatch, windowed_velocity, wrapped_rows
from ._columns import (
    DIRECTION_TOLERANCE,
    LIMITS,
    OPTIONAL_INPUTS,
    RAWLOG_COLUMNS,
    SAMPLE_COLUMNS,
    _as_column,
    _check_range,
    _optional_column,
)
from ._encoder_steps import encoder_quantum, position_unit_problem
from ._standstill import drop_standstill, standstill_rows
from ._trajectory_log import check_trajectory_log
from .rawlog import NO_TEMPERATURE, NO_TEMPERATURE_SOURCE, RawLog, constant_temperature
from .robot_join import join_robot_logs
from .robot_log import ROBOT_COLUMNS, RobotLog

__all__ = [
    "DIRECTION_TOLERANCE",
    "LIMITS",
    "NO_TEMPERATURE",
    "NO_TEMPERATURE_SOURCE",
    "OPTIONAL_INPUTS",
    "RAWLOG_COLUMNS",
    "ROBOT_COLUMNS",
    "ROW_META",
    "SAMPLE_COLUMNS",
    "FrictionSamples",
    "RawLog",
    "RobotLog",
    "check_trajectory_log",
    "coarse_velocity",
    "constant_temperature",
    "drop_standstill",
    "encoder_quantum",
    "join_robot_logs",
    "position_unit_problem",
    "row_digests",
    "samples_hash",
    "standstill_rows",
    "velocity_mismatch",
    "windowed_velocity",
    "wrapped_rows",
]


#: ``meta`` entries with one value per row, selected with the rows by
#: :meth:`FrictionSamples.subset`: ``sem`` (each row's standard error) and ``setpoint`` (a
#: label per row; rows sharing one are repeated runs of one operating point, e.g. one file,
#: run or segment each at one commanded speed).
ROW_META = ("sem", "setpoint")


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
        then carry that sign; a velocity of the other sign is refused), 0 when both
        directions were combined by eq. 11 of the BAS-RBFNN paper (velocity and friction are
        then the positive-direction values).
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
        temperature: some but not all), a direction other than -1, 0, +1 or one that
        contradicts its row's velocity (+1 with a velocity below -:data:`DIRECTION_TOLERANCE`,
        or the reverse), a count below 1
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
                f"direction must be -1, 0 or +1, got {float(direction[row])!r}",
                file=src,
                row=row,
                column="direction",
            )
        against = np.flatnonzero(direction * velocity < -DIRECTION_TOLERANCE)
        if against.size:
            row = int(against[0])
            raise DataError(
                f"direction {int(direction[row]):+d} contradicts the velocity "
                f"{float(velocity[row])!r} rad/s of the same row ({against.size} such rows): "
                "a row measured in one direction has a velocity of that sign",
                file=src,
                row=row,
                column="direction",
            )
        set_(self, "direction", direction.astype(np.int8))
        count = np.ones(n) if self.count is None else _as_column("count", self.count, n, src)
        if (count < 1).any():
            row = int(np.flatnonzero(count < 1)[0])
            raise DataError(
                f"count must be >= 1, got {float(count[row])!r}", file=src, row=row, column="count"
            )
        _check_range("count", count, src)
        if (count != np.round(count)).any():
            row = int(np.flatnonzero(count != np.round(count))[0])
            raise DataError(
                f"count must be a whole number, got {float(count[row])!r}",
                file=src,
                row=row,
                column="count",
            )
        set_(self, "count", count.astype(np.int64))
        std = np.zeros(n) if self.std is None else _as_column("std", self.std, n, src)
        if (std < 0).any():
            row = int(np.flatnonzero(std < 0)[0])
            raise DataError(
                f"std must be >= 0, got {float(std[row])!r}", file=src, row=row, column="std"
            )
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
            The selected rows; ``source`` and ``meta`` kept (the per-row entries of
            :data:`ROW_META` selected with the rows).

        Raises
        ------
        DataError
            The selection is empty.
        """
        idx = np.asarray(mask)
        meta = dict(self.meta)
        rows = np.arange(len(self))[idx]
        for key in ROW_META:
            per_row = meta.get(key)
            if isinstance(per_row, list | tuple) and len(per_row) == len(self):
                meta[key] = [per_row[i] for i in rows]
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


def _hashed_columns(samples: FrictionSamples) -> list[np.ndarray]:
    """The columns the content hashes read: velocity, load, temperature, friction, direction
    (float)."""
    cols = (samples.velocity, samples.load, samples.temperature, samples.friction)
    return [np.asarray(a, dtype=float) for a in (*cols, samples.direction.astype(float))]


def row_digests(samples: FrictionSamples) -> np.ndarray:
    """One short content hash per row (12 hexadecimal digits of the SHA-256 of its velocity,
    load, temperature, friction and direction): which rows two sets share, whatever their
    order (:func:`samples_hash` is of the whole set, in order)."""
    rows = np.ascontiguousarray(np.column_stack(_hashed_columns(samples)))
    return np.array([hashlib.sha256(r.tobytes()).hexdigest()[:12] for r in rows], dtype=object)


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
    for a in _hashed_columns(samples):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:16]
