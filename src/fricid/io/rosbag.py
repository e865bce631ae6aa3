"""ROS 2 bags and MCAP files: one joint of ``sensor_msgs/msg/JointState`` to a raw log.

Read with `rosbags <https://gitlab.com/ternaris/rosbags>`_ (pure Python): a rosbag2 directory
(``metadata.yaml`` plus ``.db3`` or ``.mcap`` storage), a bare ``.mcap`` or ``.db3`` file, or
a ROS 1 ``.bag`` file.

Each ``JointState`` message that names the joint gives one row: time, position, velocity and
effort at the joint's index in ``name``. Messages on the topic that do not name the joint
are skipped (several publishers may share ``/joint_states``). Effort is the motor torque
[N m] or, with ``effort="current"``, the motor current [A] with a torque constant K
(tau = K I, eq. 13 of the BAS-RBFNN paper). Temperature comes from an optional
``sensor_msgs/msg/Temperature`` topic, interpolated linearly to the joint's sample times
(held constant before its first and after its last reading), or is a given constant.

Time is the message header stamp (``time_source="header"``), the time the recorder received
the message (``"receive"``), or, by default (``"auto"``), the stamp unless the first message
has none (a zero stamp), then the receive time. It is stored in seconds from the first sample
(the absolute start is ``meta["time_origin_ns"]``, nanoseconds since the epoch), so no
precision is lost to large epoch values.

Large bags are read in chunks with :func:`iter_rosbag` (memory bounded by ``chunk_rows``);
:func:`read_rosbag` returns the whole log.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ..samples import RawLog, constant_temperature
from ..units import SI_UNITS, UNITS, to_si
from ._bag import (
    JOINT_STATE,
    TEMPERATURE,
    interp_temperature,
    messages,
    open_bag,
    stamp_ns,
    temperature_series,
    topic_connections,
)

__all__ = [
    "JOINT_STATE",
    "TEMPERATURE",
    "iter_rosbag",
    "read_rosbag",
    "rosbag_joints",
    "rosbag_topics",
]


_TIME_SOURCES = ("auto", "header", "receive")
_EFFORTS = {"torque": "torque", "current": "current"}


def rosbag_topics(path: str | os.PathLike[str]) -> dict[str, str]:
    """List the topics of a bag.

    Parameters
    ----------
    path : str or os.PathLike
        A rosbag2 directory, an ``.mcap`` or ``.db3`` file, or a ROS 1 ``.bag``.

    Returns
    -------
    dict of str to str
        Topic -> message type, e.g. ``{"/joint_states": "sensor_msgs/msg/JointState"}``.

    Raises
    ------
    DataError
        A missing, unreadable or truncated bag.
    """
    path = Path(path)
    with open_bag(path) as reader:
        return {c.topic: c.msgtype for c in reader.connections}


def rosbag_joints(path: str | os.PathLike[str], topic: str = "/joint_states") -> list[str]:
    """List the joints named on a ``JointState`` topic.

    Parameters
    ----------
    path : str or os.PathLike
        A rosbag2 directory, an ``.mcap`` or ``.db3`` file, or a ROS 1 ``.bag``.
    topic : str, default "/joint_states"
        A ``sensor_msgs/msg/JointState`` topic.

    Returns
    -------
    list of str
        The joint names, in order of first appearance.

    Raises
    ------
    DataError
        A missing, unreadable or corrupt bag; no such topic, or one of another type.
    """
    path = Path(path)
    seen: dict[str, None] = {}
    with open_bag(path) as reader:
        conns = topic_connections(reader, topic, JOINT_STATE, path, "joint-state")
        for _stamp, msg in messages(reader, conns, path):
            seen.update(dict.fromkeys(msg.name))
    return list(seen)


@dataclass(frozen=True)
class _Options:
    """The reading options of :func:`iter_rosbag`, checked (``unit``: the effort's unit)."""

    joint: str
    topic: str
    temperature_topic: str | None
    temperature: float | None
    effort: str
    unit: str
    torque_constant: float | None
    position_unit: str
    velocity_unit: str
    time_source: str
    chunk_rows: int


def _check_options(
    effort: str,
    effort_unit: str | None,
    torque_constant: float | None,
    time_source: str,
    temperature_topic: str | None,
    temperature: float | None,
    chunk_rows: int,
) -> str:
    """Check the options (a :class:`ConfigError` naming the bad one); return the effort unit."""
    if effort not in _EFFORTS:
        raise ConfigError(f"effort must be one of: {', '.join(_EFFORTS)}; got '{effort}'")
    quantity = _EFFORTS[effort]
    unit = (effort_unit or SI_UNITS[quantity]).strip()
    if unit not in UNITS[quantity]:
        other = "current" if quantity == "torque" else "torque"
        hint = f" (it is a {other} unit: pass effort='{other}')" if unit in UNITS[other] else ""
        raise ConfigError(
            f"effort unit '{unit}' is not a {quantity} unit{hint}; use one of: "
            f"{', '.join(UNITS[quantity])}"
        )
    if effort == "current" and not (
        torque_constant is not None and np.isfinite(torque_constant) and torque_constant > 0
    ):
        raise ConfigError(
            "effort='current' needs a positive torque constant K [N m/A] (tau = K I, eq. 13); "
            f"got {torque_constant!r}"
        )
    if time_source not in _TIME_SOURCES:
        raise ConfigError(
            f"time_source must be one of: {', '.join(_TIME_SOURCES)}; got '{time_source}'"
        )
    if temperature_topic is not None and temperature is not None:
        raise ConfigError(
            "give the temperature either as a topic (temperature_topic=..., "
            "sensor_msgs/msg/Temperature) or as a constant (temperature=... degC), not both"
        )
    if not isinstance(chunk_rows, int | np.integer) or chunk_rows < 1:
        raise ConfigError(f"chunk_rows must be a positive integer, got {chunk_rows!r}")
    return unit


class _Chunk:
    """Preallocated columns of one chunk of rows."""

    def __init__(self, size: int) -> None:
        self.time_ns = np.empty(size, dtype=np.int64)
        self.values = np.empty((3, size))  # position, velocity, effort
        self.index = np.empty(size, dtype=np.int64)  # message index, for messages
        self.n = 0

    def add(self, t: int, position: float, velocity: float, effort: float, index: int) -> None:
        """Append one row: time [ns], position, velocity, effort, message index."""
        k = self.n
        self.time_ns[k] = t
        self.values[0, k] = position
        self.values[1, k] = velocity
        self.values[2, k] = effort
        self.index[k] = index
        self.n = k + 1


def _component(msg: Any, field: str, idx: int, joint: str, index: int, path: Path) -> float:
    """The joint's value in one array of a ``JointState`` message (a DataError naming the
    message if the array is empty or does not match ``name``)."""
    values = getattr(msg, field)
    if len(values) == 0:
        what = "effort (torque or current)" if field == "effort" else field
        raise DataError(
            f"JointState message {index} has no {what} for joint '{joint}' (the '{field}' "
            "array is empty); fricid needs position, velocity and effort",
            file=path,
            row=index,
            column=field,
        )
    if len(values) != len(msg.name):
        raise DataError(
            f"JointState message {index} has {len(msg.name)} names but {len(values)} "
            f"'{field}' values",
            file=path,
            row=index,
            column=field,
        )
    return float(values[idx])


def iter_rosbag(
    path: str | os.PathLike[str],
    joint: str,
    *,
    topic: str = "/joint_states",
    temperature_topic: str | None = None,
    temperature: float | None = None,
    effort: str = "torque",
    effort_unit: str | None = None,
    torque_constant: float | None = None,
    position_unit: str = "rad",
    velocity_unit: str = "rad/s",
    time_source: str = "auto",
    chunk_rows: int = 1_000_000,
) -> Iterator[RawLog]:
    """Read one joint of a bag as consecutive :class:`RawLog` chunks of ``chunk_rows`` rows.

    Parameters
    ----------
    path : str or os.PathLike
        A rosbag2 directory, an ``.mcap`` or ``.db3`` file, or a ROS 1 ``.bag``.
    joint : str
        The joint's name in ``JointState.name``.
    topic : str, default "/joint_states"
        The ``sensor_msgs/msg/JointState`` topic.
    temperature_topic : str, optional
        A ``sensor_msgs/msg/Temperature`` topic [degC], interpolated to the joint's sample
        times. Give it or ``temperature``, not both.
    temperature : float, optional
        Constant temperature [degC] when there is no temperature topic; without either, the
        log records none (:data:`fricid.samples.NO_TEMPERATURE_SOURCE`).
    effort : {"torque", "current"}, default "torque"
        What ``JointState.effort`` holds: the motor torque, or the motor current (which
        needs ``torque_constant``).
    effort_unit : str, optional
        Unit of the effort values (default N m for torque, A for current).
    torque_constant : float, optional
        K [N m/A] for ``effort="current"`` (tau = K I, eq. 13 of the BAS-RBFNN paper).
    position_unit, velocity_unit : str, default "rad", "rad/s"
        Units of position and velocity (ROS uses rad and rad/s, REP 103; a driver that
        publishes degrees needs ``"deg"`` and ``"deg/s"``).
    time_source : {"auto", "header", "receive"}, default "auto"
        Which time to use (module docstring).
    chunk_rows : int, default 1000000
        Rows per chunk; memory is bounded by it whatever the bag's size.

    Yields
    ------
    RawLog
        SI units; ``meta`` records the topic, time source and origin, effort kind and unit,
        and the temperature source. The chunks concatenate to :func:`read_rosbag`'s log.

    Raises
    ------
    DataError
        A missing, unreadable, truncated or corrupt bag; a missing topic or one of another
        type (the topics present are listed); a joint that no message names (the names
        present are listed); a message without position, velocity or effort for the joint;
        time not strictly increasing; non-finite values.
    ConfigError
        Inconsistent options: an effort unit of the wrong kind (mixed units), current
        without a torque constant, temperature both or neither as topic and constant.
    """
    path = Path(path)
    unit = _check_options(
        effort,
        effort_unit,
        torque_constant,
        time_source,
        temperature_topic,
        temperature,
        chunk_rows,
    )
    for quantity, u in (("position", position_unit), ("velocity", velocity_unit)):
        if u.strip() not in UNITS[quantity]:
            raise ConfigError(
                f"unknown {quantity} unit '{u}'; use one of: {', '.join(UNITS[quantity])}"
            )
    options = _Options(
        joint=joint,
        topic=topic,
        temperature_topic=temperature_topic,
        temperature=temperature,
        effort=effort,
        unit=unit,
        torque_constant=torque_constant,
        position_unit=position_unit,
        velocity_unit=velocity_unit,
        time_source=time_source,
        chunk_rows=int(chunk_rows),
    )
    with open_bag(path) as reader:
        conns = topic_connections(reader, topic, JOINT_STATE, path, "joint-state")
        yield from _read_chunks(reader, conns, path, options)


def _read_chunks(reader: Any, conns: list[Any], path: Path, opt: _Options) -> Iterator[RawLog]:
    """The chunks of one joint's rows (see :func:`iter_rosbag`)."""
    joint, topic, effort, unit = opt.joint, opt.topic, opt.effort, opt.unit
    temperature_topic, temperature = opt.temperature_topic, opt.temperature
    time_source, chunk_rows = opt.time_source, opt.chunk_rows
    names_seen: dict[str, None] = {}
    last_names: tuple[str, ...] | None = None
    idx: int | None = None
    use_header: bool | None = None if time_source == "auto" else time_source == "header"
    temps = (
        None if temperature_topic is None else temperature_series(reader, temperature_topic, path)
    )
    origin: int | None = None
    last_time: int | None = None
    chunk = _Chunk(chunk_rows)
    meta_base: dict[str, Any] = {
        "format": "rosbag",
        "topic": topic,
        "effort": effort,
        "effort_unit": unit,
        "temperature_source": temperature_topic or constant_temperature(temperature)[1],
    }

    def emit() -> RawLog:
        t_ns = chunk.time_ns[: chunk.n]
        rows = chunk.index[: chunk.n]
        k = None  # first row whose time does not increase, across chunk boundaries too
        if last_time is not None and t_ns[0] <= last_time:
            k, before = 0, last_time
        else:
            bad = np.flatnonzero(np.diff(t_ns) <= 0)
            if bad.size:
                k = int(bad[0]) + 1
                before = int(t_ns[k - 1])
        if k is not None:
            raise DataError(
                f"time is not strictly increasing at JointState message {int(rows[k])} "
                f"({(before - origin) * 1e-9!r} s then {(int(t_ns[k]) - origin) * 1e-9!r} s, "
                f"{'header stamps' if use_header else 'receive times'}); try another "
                "time_source ('header' or 'receive')",
                file=path,
                row=int(rows[k]),
                column="time",
            )
        time = (t_ns - origin) * 1e-9
        if temps is None:
            temp = np.full(chunk.n, constant_temperature(temperature)[0])
        else:
            temp = interp_temperature(temps, "header" if use_header else "receive", t_ns, origin)
        values = chunk.values[:, : chunk.n].copy()  # the buffer is reused for the next chunk
        eff = np.asarray(to_si(values[2], unit, _EFFORTS[effort]), dtype=float)
        try:
            log = RawLog(
                time=time,
                position=np.asarray(to_si(values[0], opt.position_unit, "position"), dtype=float),
                velocity=np.asarray(to_si(values[1], opt.velocity_unit, "velocity"), dtype=float),
                temperature=temp,
                torque=eff if effort == "torque" else None,
                current=eff if effort == "current" else None,
                torque_constant=opt.torque_constant,
                joint=joint,
                source=str(path),
                meta={
                    **meta_base,
                    "time_source": "header" if use_header else "receive",
                    "time_origin_ns": int(origin),
                },
            )
        except DataError as err:
            row = None if err.row is None else int(rows[err.row])
            raise DataError(err.message, file=path, row=row, column=err.column) from None
        return log

    index = -1
    for stamp, msg in messages(reader, conns, path):
        index += 1
        names = tuple(msg.name)
        if names != last_names:
            last_names = names
            names_seen.update(dict.fromkeys(names))
            idx = names.index(joint) if joint in names else None
        if idx is None:
            continue
        if use_header is None:
            use_header = stamp_ns(msg) != 0
        t = stamp_ns(msg) if use_header else int(stamp)
        if origin is None:
            origin = t
        chunk.add(
            t,
            _component(msg, "position", idx, joint, index, path),
            _component(msg, "velocity", idx, joint, index, path),
            _component(msg, "effort", idx, joint, index, path),
            index,
        )
        if chunk.n == chunk_rows:
            log = emit()
            last_time = int(chunk.time_ns[chunk.n - 1])
            chunk.n = 0
            yield log
    if origin is None:
        present = ", ".join(repr(n) for n in names_seen) or "none (no messages)"
        raise DataError(
            f"no joint '{joint}' on topic '{topic}'; the joints there are: {present}",
            file=path,
        )
    if chunk.n:
        yield emit()


def read_rosbag(path: str | os.PathLike[str], joint: str, **options: Any) -> RawLog:
    """Read one joint of a bag as a whole :class:`RawLog`.

    Parameters
    ----------
    path : str or os.PathLike
        A rosbag2 directory, an ``.mcap`` or ``.db3`` file, or a ROS 1 ``.bag``.
    joint : str
        The joint's name in ``JointState.name``.
    **options
        The keyword options of :func:`iter_rosbag`.

    Returns
    -------
    RawLog
        The whole log, SI units.

    Raises
    ------
    DataError, ConfigError
        As :func:`iter_rosbag`.

    See Also
    --------
    iter_rosbag : the same log in chunks, for bags larger than memory.

    Examples
    --------
    >>> log = read_rosbag("run1/", "elbow", temperature=25.0)  # doctest: +SKIP
    """
    chunks = list(iter_rosbag(path, joint, **options))
    return chunks[0] if len(chunks) == 1 else RawLog.concatenate(chunks)
