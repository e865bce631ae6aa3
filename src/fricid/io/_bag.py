"""Bag machinery of the ROS reader: opening a bag, streaming its messages, temperature topics.

Read with `rosbags <https://gitlab.com/ternaris/rosbags>`_ (pure Python). Every failure of the
bag itself (unreadable, truncated, corrupt, a topic missing or of another type) is a
:class:`~fricid.errors.DataError` naming the file.
"""

from __future__ import annotations

import os
import struct
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import DataError
from ._files import check_input
from ._mcap import check_mcap

__all__ = [
    "JOINT_STATE",
    "TEMPERATURE",
    "bag_errors",
    "interp_temperature",
    "messages",
    "open_bag",
    "stamp_ns",
    "temperature_series",
    "topic_connections",
]

#: The message types read.
JOINT_STATE = "sensor_msgs/msg/JointState"
TEMPERATURE = "sensor_msgs/msg/Temperature"


def bag_errors() -> tuple[type[BaseException], ...]:
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
def open_bag(path: Path) -> Iterator[Any]:
    """An open ``AnyReader``; an unreadable bag is a :class:`DataError` naming it."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    if not os.path.lexists(path):
        raise DataError("no such bag (a rosbag2 directory, .mcap, .db3 or .bag file)", file=path)
    check_input(path, folder=None, what="bag (a rosbag2 folder, .mcap, .db3 or .bag file)")
    if path.is_dir():
        for part in sorted(path.iterdir()):
            if part.suffix in (".mcap", ".db3", ".yaml"):
                check_input(part, what="file of the bag")
    if path.is_dir() and not (path / "metadata.yaml").is_file():
        raise DataError(
            "a folder without metadata.yaml is not a rosbag2 bag (give the bag's folder, or its "
            ".mcap or .db3 file)",
            file=path,
        )
    for mcap in [path] if path.is_file() else sorted(path.glob("*.mcap")):
        check_mcap(mcap)
    errors = bag_errors()
    try:
        reader = AnyReader([path], default_typestore=get_typestore(Stores.LATEST))
        reader.open()
    except errors as exc:
        raise DataError(unreadable(exc), file=path) from None
    try:
        yield reader
    finally:
        reader.close()


def unreadable(exc: BaseException) -> str:
    """The message for a bag that cannot be read, with the repair hint."""
    detail = " ".join(str(exc).split()) or type(exc).__name__
    return (
        f"unreadable or truncated bag ({detail}); a recording that was cut off can often be "
        "repaired with `ros2 bag reindex`"
    )


#: The fields read from each message type (a bag's own definition may lack one).
_FIELDS = {
    JOINT_STATE: (
        "header.stamp.sec",
        "header.stamp.nanosec",
        "name",
        "position",
        "velocity",
        "effort",
    ),
    TEMPERATURE: ("header.stamp.sec", "header.stamp.nanosec", "temperature"),
}


def _check_fields(msg: Any, msgtype: str, index: int, path: Path) -> None:
    """Refuse a message without a field fricid reads (a damaged or foreign definition)."""
    for dotted in _FIELDS.get(msgtype, ()):
        node = msg
        for part in dotted.split("."):
            if not hasattr(node, part):
                raise DataError(
                    f"message {index} ({msgtype}) has no field '{dotted}': the bag's definition "
                    "of the message type is not the standard one (a damaged bag?)",
                    file=path,
                    row=index,
                )
            node = getattr(node, part)


def messages(reader: Any, connections: list[Any], path: Path) -> Iterator[tuple[int, Any]]:
    """``(receive time [ns], message)`` of ``connections``, corrupt data as DataError (a
    message without a field fricid reads included)."""
    errors = bag_errors()
    stream = reader.messages(connections=connections)
    index = -1
    while True:
        try:
            item = next(stream, None)
            if item is None:
                return
            connection, stamp, raw = item
            msg = reader.deserialize(raw, connection.msgtype)
        except errors as exc:
            raise DataError(unreadable(exc), file=path) from None
        index += 1
        _check_fields(msg, connection.msgtype, index, path)
        yield stamp, msg


def topic_connections(reader: Any, topic: str, msgtype: str, path: Path, what: str) -> list:
    """The connections of ``topic``; a DataError listing the topics if it is absent, or
    naming the type if it carries another message type."""
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


def stamp_ns(msg: Any) -> int:
    """A message's header stamp [ns since the epoch]."""
    return int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)


def temperature_series(reader: Any, topic: str, path: Path) -> dict[str, np.ndarray]:
    """Readings of a temperature topic: header stamps and receive times [ns], values [degC]."""
    conns = topic_connections(reader, topic, TEMPERATURE, path, "temperature")
    header, receive, values = [], [], []
    for stamp, msg in messages(reader, conns, path):
        header.append(stamp_ns(msg))
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


def interp_temperature(
    series: dict[str, np.ndarray], key: str, t_ns: np.ndarray, origin: int
) -> np.ndarray:
    """Temperature [degC] at times ``t_ns`` [ns], linear between readings (``key``: which
    of their times, ``"header"`` or ``"receive"``), held constant outside them."""
    order = np.argsort(series[key], kind="stable")
    t = (series[key][order] - origin) * 1e-9
    return np.interp((t_ns - origin) * 1e-9, t, series["value"][order])
