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
import struct
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ..samples import RawLog
from ..units import SI_UNITS, UNITS, to_si
from ._mcap import check_mcap

__all__ = [
    "JOINT_STATE",
    "TEMPERATURE",
    "iter_rosbag",
    "read_rosbag",
    "rosbag_joints",
    "rosbag_topics",
]

#: The message types read.
JOINT_STATE = "sensor_msgs/msg/JointState"
TEMPERATURE = "sensor_msgs/msg/Temperature"

_TIME_SOURCES = ("auto", "header", "receive")
_EFFORTS = {"torque": "torque", "current": "current"}


def _bag_errors() -> tuple[type[BaseException], ...]:
    """Exceptions that mean the bag itself is unreadable, truncated or corrupt."""
    from rosbags.highlevel import AnyReaderError
    from rosbags.rosbag1 import ReaderError as ReaderError1
    from rosbags.rosbag2 import ReaderError as ReaderError2
    from rosbags.serde import SerdeError

    errors: list[type[BaseException]] = [
        AnyReaderError,
        ReaderError1,
        ReaderError2,
        SerdeError,
        struct.error,
        EOFError,
        OverflowError,
        UnicodeError,
        # what rosbags raises on some corrupt records (a QoS profile that is not a mapping,
        # a missing key): caught only around its calls, as a corrupt bag
        KeyError,
        IndexError,
        TypeError,
        ValueError,
    ]
    try:
        import apsw  # the SQLite driver of rosbags (.db3 storage)

        errors.append(apsw.Error)
    except ImportError:  # pragma: no cover - a rosbags without SQLite support
        pass
    return tuple(errors)


@contextmanager
def _open(path: Path) -> Iterator[Any]:
    """An open ``AnyReader``; an unreadable bag is a :class:`DataError` naming it."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    if not path.exists():
        raise DataError("no such bag (a rosbag2 directory, .mcap, .db3 or .bag file)", file=path)
    if path.is_dir() and not (path / "metadata.yaml").is_file():
        raise DataError(
            "a folder without metadata.yaml is not a rosbag2 bag (give the bag's folder, or its "
            ".mcap or .db3 file)",
            file=path,
        )
    for mcap in [path] if path.is_file() else sorted(path.glob("*.mcap")):
        check_mcap(mcap)
    errors = _bag_errors()
    try:
        reader = AnyReader([path], default_typestore=get_typestore(Stores.LATEST))
        reader.open()
    except errors as exc:
        raise DataError(_unreadable(exc), file=path) from None
    try:
        yield reader
    finally:
        reader.close()


def _unreadable(exc: BaseException) -> str:
    detail = " ".join(str(exc).split()) or type(exc).__name__
    return (
        f"unreadable or truncated bag ({detail}); a recording that was cut off can often be "
        "repaired with `ros2 bag reindex`"
    )


def _messages(reader: Any, connections: list[Any], path: Path) -> Iterator[tuple[int, Any]]:
    """``(receive time [ns], message)`` of ``connections``, corrupt data as DataError."""
    errors = _bag_errors()
    stream = reader.messages(connections=connections)
    while True:
        try:
            item = next(stream, None)
            if item is None:
                return
            connection, stamp, raw = item
            msg = reader.deserialize(raw, connection.msgtype)
        except errors as exc:
            raise DataError(_unreadable(exc), file=path) from None
        yield stamp, msg


def _topic_connections(reader: Any, topic: str, msgtype: str, path: Path, what: str) -> list:
    conns = [c for c in reader.connections if c.topic == topic]
    if not conns:
        present = ", ".join(
            f"{c.topic} ({c.msgtype})" for c in sorted(reader.connections, key=lambda c: c.topic)
        )
        raise DataError(
            f"no {what} topic '{topic}' in the bag; its topics: {present or 'none'}", file=path
        )
    wrong = {c.msgtype for c in conns if c.msgtype != msgtype}
    if wrong:
        raise DataError(
            f"topic '{topic}' carries {', '.join(sorted(wrong))}, not {msgtype}", file=path
        )
    return conns


def rosbag_topics(path: str | os.PathLike[str]) -> dict[str, str]:
    """Topics of a bag and their message types."""
    path = Path(path)
    with _open(path) as reader:
        return {c.topic: c.msgtype for c in reader.connections}


def rosbag_joints(path: str | os.PathLike[str], topic: str = "/joint_states") -> list[str]:
    """The joint names found on a ``JointState`` topic, in order of first appearance."""
    path = Path(path)
    seen: dict[str, None] = {}
    with _open(path) as reader:
        conns = _topic_connections(reader, topic, JOINT_STATE, path, "joint-state")
        for _stamp, msg in _messages(reader, conns, path):
            seen.update(dict.fromkeys(msg.name))
    return list(seen)


def _stamp_ns(msg: Any) -> int:
    return int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)


def _temperature_series(reader: Any, topic: str, path: Path) -> dict[str, np.ndarray]:
    """Readings of a temperature topic: header stamps and receive times [ns], values [degC]."""
    conns = _topic_connections(reader, topic, TEMPERATURE, path, "temperature")
    header, receive, values = [], [], []
    for stamp, msg in _messages(reader, conns, path):
        header.append(_stamp_ns(msg))
        receive.append(stamp)
        values.append(float(msg.temperature))
    if not values:
        raise DataError(f"temperature topic '{topic}' has no messages", file=path)
    v = np.asarray(values, dtype=float)
    bad = np.flatnonzero(~np.isfinite(v))
    if bad.size:
        raise DataError(
            f"temperature message {int(bad[0])} on '{topic}' is not finite ({v[bad[0]]!r})",
            file=path,
            row=int(bad[0]),
            column="temperature",
        )
    return {
        "header": np.asarray(header, dtype=np.int64),
        "receive": np.asarray(receive, dtype=np.int64),
        "value": v,
    }


def _interp_temperature(
    series: dict[str, np.ndarray], key: str, t_ns: np.ndarray, origin: int
) -> np.ndarray:
    order = np.argsort(series[key], kind="stable")
    t = (series[key][order] - origin) * 1e-9
    return np.interp((t_ns - origin) * 1e-9, t, series["value"][order])


def _check_options(
    effort: str,
    effort_unit: str | None,
    torque_constant: float | None,
    time_source: str,
    temperature_topic: str | None,
    temperature: float | None,
    chunk_rows: int,
) -> str:
    """Validate the options; return the effort unit."""
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
    if (temperature_topic is None) == (temperature is None):
        raise ConfigError(
            "give the temperature either as a topic (temperature_topic=..., "
            "sensor_msgs/msg/Temperature) or as a constant (temperature=... degC), "
            "not both and not neither"
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
        k = self.n
        self.time_ns[k] = t
        self.values[0, k] = position
        self.values[1, k] = velocity
        self.values[2, k] = effort
        self.index[k] = index
        self.n = k + 1


def _component(msg: Any, field: str, idx: int, joint: str, index: int, path: Path) -> float:
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
    path : a rosbag2 directory, an ``.mcap`` or ``.db3`` file, or a ROS 1 ``.bag``.
    joint : the joint's name in ``JointState.name``.
    topic : the ``sensor_msgs/msg/JointState`` topic.
    temperature_topic : a ``sensor_msgs/msg/Temperature`` topic [degC], or None.
    temperature : constant temperature [degC] when there is no temperature topic.
    effort : ``"torque"`` (motor torque) or ``"current"`` (motor current, needs
        ``torque_constant``).
    effort_unit : unit of the effort values (default N m for torque, A for current).
    torque_constant : K [N m/A] for ``effort="current"``.
    position_unit, velocity_unit : units of position and velocity (ROS uses rad and rad/s,
        REP 103; a driver that publishes degrees needs ``"deg"`` and ``"deg/s"``).
    time_source : ``"auto"``, ``"header"`` or ``"receive"`` (module docstring).
    chunk_rows : rows per chunk; memory is bounded by it whatever the bag's size.

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
    with _open(path) as reader:
        conns = _topic_connections(reader, topic, JOINT_STATE, path, "joint-state")
        yield from _read_chunks(
            reader,
            conns,
            path,
            joint,
            topic,
            temperature_topic,
            temperature,
            effort,
            unit,
            torque_constant,
            position_unit,
            velocity_unit,
            time_source,
            int(chunk_rows),
        )


def _read_chunks(
    reader,
    conns,
    path,
    joint,
    topic,
    temperature_topic,
    temperature,
    effort,
    unit,
    torque_constant,
    position_unit,
    velocity_unit,
    time_source,
    chunk_rows,
) -> Iterator[RawLog]:
    names_seen: dict[str, None] = {}
    last_names: tuple[str, ...] | None = None
    idx: int | None = None
    use_header: bool | None = None if time_source == "auto" else time_source == "header"
    temps = (
        None if temperature_topic is None else _temperature_series(reader, temperature_topic, path)
    )
    origin: int | None = None
    last_time: int | None = None
    chunk = _Chunk(chunk_rows)
    meta_base: dict[str, Any] = {
        "format": "rosbag",
        "topic": topic,
        "effort": effort,
        "effort_unit": unit,
        "temperature_source": temperature_topic or f"constant {temperature} degC",
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
            temp = np.full(chunk.n, float(temperature))
        else:
            temp = _interp_temperature(temps, "header" if use_header else "receive", t_ns, origin)
        values = chunk.values[:, : chunk.n].copy()  # the buffer is reused for the next chunk
        eff = np.asarray(to_si(values[2], unit, _EFFORTS[effort]), dtype=float)
        try:
            log = RawLog(
                time=time,
                position=np.asarray(to_si(values[0], position_unit, "position"), dtype=float),
                velocity=np.asarray(to_si(values[1], velocity_unit, "velocity"), dtype=float),
                temperature=temp,
                torque=eff if effort == "torque" else None,
                current=eff if effort == "current" else None,
                torque_constant=torque_constant,
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
    for stamp, msg in _messages(reader, conns, path):
        index += 1
        names = tuple(msg.name)
        if names != last_names:
            last_names = names
            names_seen.update(dict.fromkeys(names))
            idx = names.index(joint) if joint in names else None
        if idx is None:
            continue
        if use_header is None:
            use_header = _stamp_ns(msg) != 0
        t = _stamp_ns(msg) if use_header else int(stamp)
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
    """Read one joint of a bag as a whole :class:`RawLog` (options as :func:`iter_rosbag`).

    Example
    -------
    >>> log = read_rosbag("run1/", "elbow", temperature=25.0)  # doctest: +SKIP
    """
    chunks = list(iter_rosbag(path, joint, **options))
    return chunks[0] if len(chunks) == 1 else RawLog.concatenate(chunks)
