""":class:`RobotLog`: all joints of a robot logged together, one row per sample, SI units.

Whole-robot identification needs every joint at the same instants (the gravity and inertia
of one joint depend on the whole configuration), so the joints share one time column and
each quantity is a matrix with one column per joint. :meth:`RobotLog.joint` gives one joint
as a :class:`~fricid.samples.RawLog`, so everything that works on one joint (extraction,
fitting) works on each joint of a robot log.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import DataError
from ._columns import LIMITS, _as_column
from .rawlog import RawLog

__all__ = ["ROBOT_COLUMNS", "RobotLog", "joint_column"]

#: The per-joint columns of a :class:`RobotLog` and their SI units (position and velocity
#: are in m and m/s for a prismatic joint, torque in N).
ROBOT_COLUMNS: dict[str, str] = {
    "position": "rad",
    "velocity": "rad/s",
    "acceleration": "rad/s^2",
    "torque": "N m",
    "current": "A",
    "temperature": "degC",
    "load": "N m",
}

#: The per-joint columns that may be absent (None).
_OPTIONAL = ("acceleration", "torque", "current", "temperature", "load")


def joint_column(joint: str, quantity: str) -> str:
    """The name of one joint's column in messages, ``"<joint>.<quantity>"``.

    Parameters
    ----------
    joint : str
        The joint's name.
    quantity : str
        A key of :data:`ROBOT_COLUMNS`.

    Returns
    -------
    str
        E.g. ``"elbow.torque"``.
    """
    return f"{joint}.{quantity}"


def _check_joints(joints: Any, source: str | None) -> tuple[str, ...]:
    """The joint names as a tuple of unique, non-empty strings."""
    if isinstance(joints, str) or not isinstance(joints, Iterable):
        raise DataError(
            f"joints must be a sequence of joint names, got {joints!r}",
            file=source,
            column="joints",
        )
    names = tuple(joints)
    if not names:
        raise DataError("a robot log needs at least one joint", file=source, column="joints")
    for name in names:
        if not isinstance(name, str) or not name.strip():
            raise DataError(
                f"a joint name must be a non-empty string, got {name!r}",
                file=source,
                column="joints",
            )
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise DataError(
                f"joint '{name}' is named twice in {list(names)}", file=source, column=name
            )
        seen.add(name)
    return names


def _as_matrix(
    quantity: str, values: Any, n: int, joints: tuple[str, ...], source: str | None
) -> np.ndarray:
    """``values`` as a finite ``(n, k)`` float matrix (a 1-D column accepted for one joint, a
    scalar temperature broadcast); each error names the row and ``<joint>.<quantity>``."""
    k = len(joints)
    arr = np.asarray(values, dtype=float)
    if arr.ndim == 0 and quantity == "temperature":
        arr = np.full((n, k), float(arr))
    if arr.ndim == 1 and k == 1:
        arr = arr[:, None]
    if arr.shape != (n, k):
        raise DataError(
            f"{quantity} has shape {arr.shape}, expected ({n}, {k}): one row per time stamp "
            f"and one column per joint ({', '.join(joints)})",
            file=source,
            column=quantity,
        )
    limit = "torque" if quantity == "load" else quantity
    for j, joint in enumerate(joints):
        try:
            _as_column(limit, arr[:, j], n, source)
        except DataError as err:
            raise DataError(
                err.message, file=source, row=err.row, column=joint_column(joint, quantity)
            ) from None
    return arr


def _check_constants(values: Any, joints: tuple[str, ...], source: str | None) -> np.ndarray:
    """The torque constants as ``(k,)`` values in (0, limit] N m/A."""
    arr = np.asarray(values, dtype=float)
    if arr.ndim == 0 and len(joints) == 1:
        arr = arr[None]
    if arr.shape != (len(joints),):
        raise DataError(
            f"torque_constants has shape {arr.shape}, expected ({len(joints)},): one K [N m/A] "
            "per joint",
            file=source,
            column="torque_constants",
        )
    high = LIMITS["torque_constant"][1]
    for joint, k in zip(joints, arr, strict=True):
        if not (np.isfinite(k) and 0 < k <= high):
            raise DataError(
                f"the torque constant K (tau = K I, eq. 13) must lie in (0, {high:g}] N m/A; "
                f"got {float(k)!r}",
                file=source,
                column=joint_column(joint, "torque_constant"),
            )
    return arr


@dataclass(frozen=True, eq=False)
class RobotLog:
    """All joints of a robot: one row per sample, one column per joint, SI units.

    The columns are converted to float arrays and checked on construction; the object is
    frozen, so a ``RobotLog`` is always valid.

    Parameters
    ----------
    time : array_like, shape (n,)
        Time [s], strictly increasing.
    joints : sequence of str
        The joints' names, unique and non-empty, in column order.
    position : array_like, shape (n, k)
        Joint positions [rad, or m for a prismatic joint].
    velocity : array_like, shape (n, k)
        Joint velocities [rad/s or m/s]. A reader that finds none computes them from the
        positions and says so in ``meta["velocity_from"]``.
    torque : array_like, shape (n, k), optional
        Motor torques [N m]; None when only the currents were logged.
    current : array_like, shape (n, k), optional
        Motor currents [A]; needs ``torque_constants`` when there is no torque.
    torque_constants : array_like, shape (k,), optional
        K [N m/A] per joint, tau = K I (eq. 13 of the BAS-RBFNN paper).
    acceleration : array_like, shape (n, k), optional
        Joint accelerations [rad/s^2].
    temperature : array_like, shape (n, k) or scalar, optional
        Temperatures [degC]; a scalar is broadcast to every row and joint.
    load : array_like, shape (n, k), optional
        Load torques [N m] (eq. 7 of the BAS-RBFNN paper: the gravity torque on the joint).
    source : str, optional
        Where the log came from (a file name), for messages and provenance.
    meta : mapping, optional
        Anything else worth keeping (copied).

    Raises
    ------
    DataError
        Joint names missing, empty or repeated; a column of the wrong shape; a non-finite or
        impossible value (the row and ``<joint>.<quantity>`` named); time not strictly
        increasing; neither torque nor current; current without a positive torque constant
        per joint.

    See Also
    --------
    fricid.io.read_robot_log, fricid.io.write_robot_log : the log as a file.

    Examples
    --------
    >>> log = RobotLog(time=[0.0, 0.1], joints=("shoulder", "elbow"),
    ...                position=[[0.0, 1.0], [0.01, 1.02]], velocity=[[0.1, 0.2], [0.1, 0.2]],
    ...                torque=[[1.5, 0.3], [1.4, 0.3]], temperature=25.0)
    >>> log.n_joints, len(log), float(log.joint("elbow").torque[1])
    (2, 2, 0.3)
    """

    time: np.ndarray
    joints: tuple[str, ...]
    position: np.ndarray
    velocity: np.ndarray
    torque: np.ndarray | None = None
    current: np.ndarray | None = None
    torque_constants: np.ndarray | None = None
    acceleration: np.ndarray | None = None
    temperature: np.ndarray | None = None
    load: np.ndarray | None = None
    source: str | None = None
    meta: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        src = self.source
        set_ = object.__setattr__
        joints = _check_joints(self.joints, src)
        set_(self, "joints", joints)
        time = _as_column("time", self.time, None, src)
        n = time.shape[0]
        set_(self, "time", time)
        for name in ("position", "velocity"):
            set_(self, name, _as_matrix(name, getattr(self, name), n, joints, src))
        for name in _OPTIONAL:
            if getattr(self, name) is not None:
                set_(self, name, _as_matrix(name, getattr(self, name), n, joints, src))
        if self.torque is None and self.current is None:
            raise DataError("the log has neither torque nor current columns", file=src)
        if self.torque_constants is not None:
            set_(self, "torque_constants", _check_constants(self.torque_constants, joints, src))
        elif self.torque is None:
            raise DataError(
                "only currents were logged, so a positive torque constant K [N m/A] per joint is "
                "needed (tau = K I, eq. 13): give torque_constants",
                file=src,
                column="torque_constants",
            )
        bad = np.flatnonzero(np.diff(time) <= 0)
        if bad.size:
            row = int(bad[0]) + 1
            raise DataError(
                "time is not strictly increasing "
                f"({float(time[row - 1])!r} then {float(time[row])!r})",
                file=src,
                row=row,
                column="time",
            )
        set_(self, "meta", dict(self.meta))

    def __len__(self) -> int:
        return int(self.time.shape[0])

    @property
    def n_joints(self) -> int:
        """int: the number of joints, k."""
        return len(self.joints)

    @property
    def motor_torque(self) -> np.ndarray:
        """ndarray, shape (n, k): motor torques [N m], the logged torques, else K times the
        currents (eq. 13 of the BAS-RBFNN paper)."""
        if self.torque is not None:
            return self.torque
        return self.current * self.torque_constants

    def index(self, name: str) -> int:
        """The column of joint ``name``.

        Raises
        ------
        DataError
            No such joint (the joints listed).
        """
        try:
            return self.joints.index(name)
        except ValueError:
            raise DataError(
                f"no joint '{name}' in the log; its joints: {', '.join(self.joints)}",
                file=self.source,
            ) from None

    def joint(self, name: str, *, temperature: float | None = None) -> RawLog:
        """One joint as a :class:`~fricid.samples.RawLog`, for single-joint extraction and
        fitting.

        Parameters
        ----------
        name : str
            The joint.
        temperature : float, optional
            Constant temperature [degC] when the log has none.

        Returns
        -------
        RawLog
            The joint's time, position, velocity, temperature, torque and/or current with
            its torque constant; ``meta`` is this log's plus ``robot_joints`` (all joints)
            and ``joint_index``.

        Raises
        ------
        DataError
            No such joint, or no temperature in the log and none given.
        """
        j = self.index(name)
        if self.temperature is not None:
            temp: Any = self.temperature[:, j]
        elif temperature is not None:
            temp = temperature
        else:
            raise DataError(
                "the log has no temperature; give one [degC] (on the command line "
                f"--temperature, in Python joint('{name}', temperature=...))",
                file=self.source,
                column=joint_column(name, "temperature"),
            )
        k = None if self.torque_constants is None else float(self.torque_constants[j])
        return RawLog(
            time=self.time,
            position=self.position[:, j],
            velocity=self.velocity[:, j],
            temperature=temp,
            torque=None if self.torque is None else self.torque[:, j],
            current=None if self.current is None else self.current[:, j],
            torque_constant=k,
            joint=name,
            source=self.source,
            meta={**self.meta, "robot_joints": list(self.joints), "joint_index": j},
        )

    def select(self, names: Iterable[str]) -> RobotLog:
        """The given joints, in the given order.

        Raises
        ------
        DataError
            An unknown joint (the joints listed), or a joint named twice.
        """
        idx = [self.index(name) for name in names]
        return self._columns(idx, tuple(self.joints[i] for i in idx))

    def rename(self, mapping: Mapping[str, str]) -> RobotLog:
        """The joints renamed by ``mapping`` (old -> new); joints not in it keep their names.

        Raises
        ------
        DataError
            An old name that is not a joint of the log, or new names that are not unique.
        """
        for old in mapping:
            self.index(old)
        return replace(self, joints=tuple(mapping.get(j, j) for j in self.joints))

    def slice(self, start: int, stop: int) -> RobotLog:
        """Rows ``start:stop`` as a new log (as ``array[start:stop]``)."""
        s = np.s_[start:stop]
        rows = {
            name: getattr(self, name)[s] for name in _OPTIONAL if getattr(self, name) is not None
        }
        return replace(
            self, time=self.time[s], position=self.position[s], velocity=self.velocity[s], **rows
        )

    def _columns(self, idx: list[int], joints: tuple[str, ...]) -> RobotLog:
        cols = {
            name: getattr(self, name)[:, idx]
            for name in ("position", "velocity", *_OPTIONAL)
            if getattr(self, name) is not None
        }
        if self.torque_constants is not None:
            cols["torque_constants"] = self.torque_constants[idx]
        return replace(self, joints=joints, **cols)
