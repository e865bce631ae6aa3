"""All joints of a ROS 2 bag's (or MCAP file's) ``sensor_msgs/msg/JointState`` topic.

Messages are grouped by the set of joints they name (several publishers may share the topic,
e.g. an arm's driver and a gripper's); one group becomes the robot log: the one whose joints
map to ``joints=`` (:func:`fricid.io._robot_map.match_joints`), or without ``joints=`` the
group naming the most joints. A message may list the group's joints in any order. Time, the
effort's meaning and units, and temperature topics are as for one joint
(:func:`fricid.io.iter_rosbag`); a topic without velocities (empty ``velocity`` arrays) gets
them as the central difference of the positions (``meta["velocity_from"]``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ..samples import RobotLog
from ..samples.robot_log import joint_column
from ..units import SI_UNITS, UNITS, to_si
from ._bag import (
    JOINT_STATE,
    interp_temperature,
    messages,
    open_bag,
    stamp_ns,
    temperature_series,
    topic_connections,
)
from ._robot_map import constants_for, match_joints, velocity_from_position

__all__ = ["BagOptions", "read_robot_bag"]


@dataclass(frozen=True)
class BagOptions:
    """How to read a bag (see :func:`fricid.io.read_robot_log`)."""

    topic: str = "/joint_states"
    effort: str = "torque"
    effort_unit: str | None = None
    position_unit: str = "rad"
    velocity_unit: str = "rad/s"
    time_source: str = "auto"
    temperature_topic: str | None = None

    def check(self) -> str:
        """The effort's unit, the options checked (a ConfigError naming the bad one)."""
        if self.effort not in ("torque", "current"):
            raise ConfigError(f"effort must be 'torque' or 'current', got {self.effort!r}")
        if self.time_source not in ("auto", "header", "receive"):
            raise ConfigError(
                f"time_source must be 'auto', 'header' or 'receive', got {self.time_source!r}"
            )
        unit = (self.effort_unit or SI_UNITS[self.effort]).strip()
        for quantity, u in (
            (self.effort, unit),
            ("position", self.position_unit),
            ("velocity", self.velocity_unit),
        ):
            if u.strip() not in UNITS[quantity]:
                raise ConfigError(
                    f"'{u}' is not a {quantity} unit; use one of: {', '.join(UNITS[quantity])}"
                )
        return unit


@dataclass
class _Group:
    """The messages naming one set of joints: their rows, in message order."""

    names: tuple[str, ...]
    index: list[int] = field(default_factory=list)  # message index on the topic
    header: list[int] = field(default_factory=list)  # stamps [ns]
    receive: list[int] = field(default_factory=list)
    position: list[np.ndarray] = field(default_factory=list)
    velocity: list[np.ndarray | None] = field(default_factory=list)
    effort: list[np.ndarray] = field(default_factory=list)


def _values(msg: Any, name: str, order: list[int], index: int, path: Path) -> np.ndarray | None:
    """One array of a message in the group's joint order; None when it is empty."""
    values = np.asarray(getattr(msg, name), dtype=float)
    if values.size == 0:
        return None
    if values.shape != (len(msg.name),):
        raise DataError(
            f"JointState message {index} has {len(msg.name)} names but {values.size} "
            f"'{name}' values",
            file=path,
            row=index,
            column=name,
        )
    return values[order]


def _groups(reader: Any, conns: list[Any], path: Path) -> list[_Group]:
    """The topic's messages grouped by the set of joints they name."""
    groups: dict[frozenset[str], _Group] = {}
    orders: dict[tuple[str, ...], list[int]] = {}
    for index, (stamp, msg) in enumerate(messages(reader, conns, path)):
        names = tuple(msg.name)
        if not names:
            continue
        group = groups.setdefault(frozenset(names), _Group(names))
        if names not in orders:
            orders[names] = [names.index(n) for n in group.names]
        order = orders[names]
        position = _values(msg, "position", order, index, path)
        effort = _values(msg, "effort", order, index, path)
        for what, values in (("position", position), ("effort", effort)):
            if values is None:
                raise DataError(
                    f"JointState message {index} has no {what} for joint '{group.names[0]}' "
                    f"(nor for {', '.join(group.names[1:]) or 'any other'}): its '{what}' "
                    "array is empty; fricid needs every joint's position and effort",
                    file=path,
                    row=index,
                    column=joint_column(group.names[0], "torque" if what == "effort" else what),
                )
        group.index.append(index)
        group.header.append(stamp_ns(msg))
        group.receive.append(int(stamp))
        group.position.append(position)
        group.velocity.append(_values(msg, "velocity", order, index, path))
        group.effort.append(effort)
    return list(groups.values())


def _choose(groups: list[_Group], joints: list[str] | None, path: Path, topic: str) -> tuple:
    """The group of the robot log, its joints in output order and their names."""
    if not groups:
        raise DataError(f"no JointState message naming a joint on topic '{topic}'", file=path)
    ranked = sorted(groups, key=lambda g: -len(g.names))  # stable: first seen among equals
    if joints is None:
        return ranked[0], list(ranked[0].names), list(ranked[0].names)
    errors = []
    for group in ranked:
        try:
            order, names = match_joints(group.names, joints, file=path)
        except DataError as err:
            errors.append(err)
            continue
        return group, order, names
    if len(groups) == 1:
        raise errors[0]
    sets = "; ".join("[" + ", ".join(g.names) + "]" for g in groups)
    raise DataError(
        f"no publisher on topic '{topic}' names the joints asked for "
        f"({', '.join(joints)}); its messages name: {sets}",
        file=path,
    )


def read_robot_bag(
    path: Path,
    joints: list[str] | None,
    options: BagOptions,
    torque_constants: Any,
    temperature: float | None,
) -> RobotLog:
    """Read a bag's joint states as a robot log (the module docstring)."""
    unit = options.check()
    if options.temperature_topic is not None and temperature is not None:
        raise ConfigError("give temperature_topic= or temperature=, not both")
    with open_bag(path) as reader:
        conns = topic_connections(reader, options.topic, JOINT_STATE, path, "joint-state")
        groups = _groups(reader, conns, path)
        temps = (
            None
            if options.temperature_topic is None
            else temperature_series(reader, options.temperature_topic, path)
        )
    group, order, names = _choose(groups, joints, path, options.topic)
    cols = [group.names.index(j) for j in order]
    use_header = options.time_source == "header" or (
        options.time_source == "auto" and group.header[0] != 0
    )
    t_ns = np.asarray(group.header if use_header else group.receive, dtype=np.int64)
    origin = int(t_ns[0])
    time = (t_ns - origin) * 1e-9
    position = np.asarray(
        to_si(np.stack(group.position)[:, cols], options.position_unit, "position"), dtype=float
    )
    meta: dict[str, Any] = {
        "format": "rosbag",
        "topic": options.topic,
        "effort": options.effort,
        "effort_unit": unit,
        "time_source": "header" if use_header else "receive",
        "time_origin_ns": origin,
    }
    velocity = _velocity(group, cols, options.velocity_unit, path)
    if velocity is None:
        velocity = velocity_from_position(position, time, path)
        meta["velocity_from"] = "position (central difference)"
    effort = np.asarray(to_si(np.stack(group.effort)[:, cols], unit, options.effort), dtype=float)
    if temps is not None:
        key = "header" if use_header else "receive"
        temp: Any = np.repeat(interp_temperature(temps, key, t_ns, origin)[:, None], len(cols), 1)
        meta["temperature_source"] = options.temperature_topic
    else:
        temp = temperature
    left_out = [n for n in group.names if n not in order]
    if left_out:
        meta["joints_left_out"] = left_out
    if order != names:
        meta["joint_map"] = dict(zip(order, names, strict=True))
    rows = np.asarray(group.index)
    try:
        return RobotLog(
            time=time,
            joints=names,
            position=position,
            velocity=velocity,
            torque=effort if options.effort == "torque" else None,
            current=effort if options.effort == "current" else None,
            torque_constants=constants_for(names, torque_constants),
            temperature=temp,
            source=str(path),
            meta=meta,
        )
    except DataError as err:
        row = None if err.row is None else int(rows[err.row])
        raise DataError(err.message, file=path, row=row, column=err.column) from None


def _velocity(group: _Group, cols: list[int], unit: str, path: Path) -> np.ndarray | None:
    """The logged velocities in SI; None if no message has any; a DataError naming the first
    message without them when only some have."""
    missing = [i for i, v in enumerate(group.velocity) if v is None]
    if len(missing) == len(group.velocity):
        return None
    if missing:
        index = group.index[missing[0]]
        raise DataError(
            f"JointState message {index} has no velocities, while other messages have them",
            file=path,
            row=index,
            column="velocity",
        )
    return np.asarray(to_si(np.stack(group.velocity)[:, cols], unit, "velocity"), dtype=float)
