"""Robot logs: all joints of a robot from one file or folder, a
:class:`~fricid.samples.RobotLog`.

Three layouts are read, each converted to SI once, here:

* a ROS 2 bag or MCAP file: every joint of a ``sensor_msgs/msg/JointState`` topic
  (:mod:`._robot_bag`);
* a wide CSV or Parquet table: a time column and per-joint columns named ``q1 [rad]``,
  ``dq1 [rad/s]``, ``tau1 [N m]``, ``q_1``, ``position_<joint>``, ``<joint>_position``,
  ``<joint>.position`` (quantities ``pos``, ``vel``, ``acc``, ``eff``/``effort``/``torque``,
  ``current``, ``temp``, ``load`` and their long names), units in the headers as fricid's
  other tables (``[deg]``, ``[deg/s]``, ``[mN m]``...) (:mod:`._robot_table`);
* a folder of per-channel ``time value`` files, one set per joint, named by patterns with a
  ``{joint}`` field (:func:`fricid.io.read_channels`), e.g. ``torque=tau_{joint}.txt``.

``joints=`` names the joints to map to (a URDF's moving joints, in order): each joint of the
file maps to its exact name, else the name equal ignoring case, else, for a numbered joint
(``q1``), the name at that 1-based index; a joint of the file left over or a name asked for
that is missing is one :class:`~fricid.errors.DataError` listing both sides (a file with more
joints than asked for is read when it names every joint asked for). Without ``joints=`` the
file's own names are kept (``"1"``, ``"2"`` for numbered columns).

A file without velocities gets them as the central difference of the positions
(:func:`numpy.gradient`: second order inside, one-sided at the ends), recorded in
``meta["velocity_from"]``. :func:`write_robot_log` writes a table that reads back to the
same log.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError
from ..samples import RobotLog
from ._files import check_input
from ._robot_bag import BagOptions, read_robot_bag
from ._robot_map import check_names, constants_for, match_joints
from ._robot_table import ROBOTLOG_FORMAT, read_robot_table, write_robot_table

__all__ = ["ROBOTLOG_FORMAT", "ROBOT_READERS", "read_robot_log", "write_robot_log"]

#: The layouts :func:`read_robot_log` reads (``reader=``).
ROBOT_READERS: tuple[str, ...] = ("auto", "table", "rosbag", "channels")

PathLike = str | os.PathLike[str]


def _reader_of(path: Path) -> str:
    """The layout of ``path`` for ``reader="auto"``."""
    if path.is_dir():
        return "rosbag" if (path / "metadata.yaml").is_file() else "channels"
    suffix = path.suffix.lower()
    if suffix in (".mcap", ".db3", ".bag"):
        return "rosbag"
    if suffix in (".csv", ".parquet", ".pq"):
        return "table"
    raise ConfigError(
        f"cannot tell the layout of '{path}': give a .csv, .parquet or .pq table, a bag (a "
        "rosbag2 folder, .mcap, .db3, .bag) or a folder of per-channel files, or reader="
    )


def read_robot_log(
    paths: PathLike | Sequence[PathLike],
    *,
    joints: Sequence[str] | None = None,
    reader: str = "auto",
    topic: str = "/joint_states",
    torque_constants: Sequence[float] | Mapping[str, float] | None = None,
    temperature: float | None = None,
    temperature_topic: str | None = None,
    effort: str = "torque",
    effort_unit: str | None = None,
    position_unit: str = "rad",
    velocity_unit: str = "rad/s",
    time_source: str = "auto",
    channels: Mapping[str, str] | str | None = None,
    units: Mapping[str, str] | None = None,
    join: str = "nearest",
    tolerance: float | None = None,
    time_unit: str = "s",
) -> RobotLog:
    """Read all joints of a robot from a bag, a wide table or a folder of channel files.

    Parameters
    ----------
    paths : str or os.PathLike, or a sequence of them
        The file or folder; several are read alike and joined end to end (time must go on
        increasing from one to the next; bags are placed by their absolute time).
    joints : sequence of str, optional
        The names to map the file's joints to, in the order wanted (module docstring).
    reader : {"auto", "table", "rosbag", "channels"}, default "auto"
        The layout; ``"auto"`` goes by the suffix (a folder is a bag if it holds
        ``metadata.yaml``, else per-channel files).
    topic : str, default "/joint_states"
        Bags: the ``sensor_msgs/msg/JointState`` topic.
    torque_constants : sequence of float or mapping of str to float, optional
        K [N m/A] per joint, tau = K I (eq. 13 of the BAS-RBFNN paper), in the order of the
        log's joints or by joint name; needed when only currents were logged (a table written
        by :func:`write_robot_log` carries its own).
    temperature : float, optional
        A constant temperature [degC] for every joint when the file has none.
    temperature_topic : str, optional
        Bags: a ``sensor_msgs/msg/Temperature`` topic [degC], interpolated to the joint
        states' times, for every joint.
    effort, effort_unit, position_unit, velocity_unit, time_source
        Bags: what ``JointState.effort`` holds (``"torque"`` or ``"current"``) and the units,
        as for :func:`fricid.io.iter_rosbag`.
    channels, units, join, tolerance, time_unit
        Per-channel folders: quantity -> file-name pattern with a ``{joint}`` field, quantity
        -> unit, and the joining on time, as for :func:`fricid.io.read_channels`; or one
        pattern with a ``{quantity}`` field too (``"{quantity}_{joint}.txt"``: files
        ``position_1.txt``, ``torque_1.txt``...), written out for each quantity of ``units``.
        A position pattern is needed; the joints' files must share their time stamps.

    Returns
    -------
    RobotLog
        SI units; ``meta`` records what the reader did (``velocity_from``, ``joint_map``
        from the file's names to the names asked for, ``joints_left_out``).

    Raises
    ------
    ConfigError
        An unknown reader, an option of another reader, inconsistent options.
    DataError
        Bad data, named by file, row and column (``<joint>.<quantity>`` or the file's own
        column label): a missing, repeated or non-finite column, a joint without torque,
        joints that do not map (module docstring), time not increasing.

    See Also
    --------
    write_robot_log : the inverse, for tables.
    fricid.samples.RobotLog.joint : one joint of the log for single-joint extraction.

    Examples
    --------
    >>> log = read_robot_log("arm.csv", joints=["shoulder", "elbow"])  # doctest: +SKIP
    >>> log.joint("elbow", temperature=25.0)  # a RawLog  # doctest: +SKIP
    """
    if reader not in ROBOT_READERS:
        raise ConfigError(f"reader must be one of: {', '.join(ROBOT_READERS)}; got {reader!r}")
    names = None if joints is None else check_names(joints)
    many = not isinstance(paths, str | os.PathLike)
    files = [Path(p) for p in (paths if many else [paths])]  # type: ignore[union-attr]
    if not files:
        raise ConfigError("read_robot_log got no paths")
    bag = BagOptions(
        topic, effort, effort_unit, position_unit, velocity_unit, time_source, temperature_topic
    )
    folder = {"channels": channels, "units": units, "join": join}
    folder |= {"tolerance": tolerance, "time_unit": time_unit}
    logs = []
    for path in files:
        kind = _reader_of(path) if reader == "auto" else reader
        _check_options(kind, bag, folder)
        if kind == "rosbag":
            log = read_robot_bag(path, names, bag, torque_constants, temperature)
        elif kind == "channels":
            log = _read_channel_folder(path, names, folder, torque_constants, temperature)
        else:
            log = read_robot_table(path, names, torque_constants, temperature)
        logs.append(log)
    return logs[0] if len(logs) == 1 else _concatenate(logs)


def _check_options(kind: str, bag: BagOptions, folder: dict[str, Any]) -> None:
    """A ConfigError for an option of another reader than ``kind``."""
    default_folder = {"channels": None, "units": None, "join": "nearest"}
    default_folder |= {"tolerance": None, "time_unit": "s"}
    wrong = []
    if kind != "rosbag":
        wrong += [k for k, v in vars(bag).items() if v != getattr(BagOptions, k)]
    if kind != "channels":
        wrong += [k for k, v in folder.items() if v != default_folder[k]]
    if wrong:
        raise ConfigError(f"{', '.join(wrong)} is not an option of the {kind} reader")


def _read_channel_folder(
    folder: Path,
    joints: list[str] | None,
    options: dict[str, Any],
    torque_constants: Any,
    temperature: float | None,
) -> RobotLog:
    """Several joints of a folder of per-channel files (:func:`read_robot_log`)."""
    from .channels import _runs, _sort_key, read_channels

    check_input(folder, folder=True, what="folder of per-channel files")
    patterns = _patterns(options["channels"], options["units"])
    if "position" not in patterns:
        raise ConfigError(
            "a robot's channel files need a position pattern (channels={'position': ...}), "
            "and a {joint} field in every pattern"
        )
    runs, fields = _runs(folder, patterns)
    if "joint" not in fields:
        raise ConfigError("the channel patterns need a {joint} field to tell the joints apart")
    at = fields.index("joint")
    ids = sorted({key[at] for key in runs}, key=_sort_key)
    for j in ids:
        keys = [key for key in runs if key[at] == j]
        if len(keys) > 1:
            raise DataError(
                f"joint '{j}' has {len(keys)} runs (fields {fields}: {keys[:3]}); read one run "
                "per folder",
                file=folder,
            )
    order, names = match_joints(ids, joints, file=folder)
    ks = constants_for(names, torque_constants)
    if ks is not None and len(np.atleast_1d(ks)) != len(names):
        raise ConfigError(f"torque_constants= must give {len(names)} values, got {ks!r}")
    # read_channels wants a temperature; without one, a placeholder that is not kept
    placeholder = temperature is None and "temperature" not in patterns
    logs = [
        read_channels(
            folder,
            patterns,
            options["units"],
            joint=j,
            join=options["join"],
            tolerance=options["tolerance"],
            time_unit=options["time_unit"],
            temperature=25.0 if placeholder else temperature,
            torque_constant=None if ks is None else float(np.atleast_1d(ks)[i]),
        )[0]
        for i, j in enumerate(order)
    ]
    time = logs[0].time
    for name, log in zip(names, logs, strict=True):
        if len(log) != len(time) or not np.array_equal(log.time, time):
            row = int(np.argmax(log.time[: len(time)] != time[: len(log)]))
            raise DataError(
                f"joint '{name}' has {len(log)} rows and joint '{names[0]}' {len(time)}, their "
                f"time stamps differ from row {row}; the joints' channel files must share "
                "their time stamps",
                file=log.source,
                row=row,
                column="time",
            )
    effort = "torque" if all(g.torque is not None for g in logs) else "current"
    stack = {
        q: np.column_stack([getattr(g, q) for g in logs])
        for q in ("position", "velocity", effort, *(() if placeholder else ("temperature",)))
    }
    meta: dict[str, Any] = {
        "format": "channels",
        "files": {n: g.meta["files"] for n, g in zip(names, logs, strict=True)},
        "join": logs[0].meta["join"],
    }
    if "velocity" not in patterns:
        meta["velocity_from"] = "position (central difference)"
    if order != names:
        meta["joint_map"] = dict(zip(order, names, strict=True))
    return RobotLog(
        time=time, joints=names, torque_constants=ks, source=str(folder), meta=meta, **stack
    )


def _patterns(channels: Mapping[str, str] | str | None, units: Any) -> dict[str, str]:
    """Quantity -> file-name pattern: ``channels`` itself, or one pattern with a
    ``{quantity}`` field written out for each quantity that ``units`` gives a unit."""
    if not isinstance(channels, str):
        return dict(channels or {})
    if "{quantity}" not in channels:
        raise ConfigError(
            f"channels= as one pattern needs a {{quantity}} field, got {channels!r} (or give "
            "a mapping quantity -> pattern)"
        )
    return {q: channels.replace("{quantity}", q) for q in (units or {})}


def _concatenate(logs: list[RobotLog]) -> RobotLog:
    """Logs of the same joints end to end (bags placed by their absolute start)."""
    first = logs[0]
    origins = [g.meta.get("time_origin_ns") for g in logs]
    shift = [0.0] * len(logs)
    if all(isinstance(o, int) for o in origins):
        shift = [(o - origins[0]) * 1e-9 for o in origins]  # type: ignore[operator]
    present = ["torque", "current", "acceleration", "temperature", "load"]
    for i, log in enumerate(logs[1:], 1):
        kept = [q for q in present if getattr(log, q) is not None]
        first_kept = [q for q in present if getattr(first, q) is not None]
        if log.joints != first.joints or kept != first_kept:
            raise DataError(
                f"this file's joints or columns ({', '.join(log.joints)}; {', '.join(kept)}) are "
                f"not those of the first file, {first.source}",
                file=log.source,
            )
        if not log.time[0] + shift[i] > logs[i - 1].time[-1] + shift[i - 1]:
            raise DataError(
                f"time does not go on increasing from {logs[i - 1].source} into this file; "
                "read the files separately",
                file=log.source,
                row=0,
                column="time",
            )
    cols = {
        q: np.concatenate([getattr(g, q) for g in logs])
        for q in ("position", "velocity", *present)
        if getattr(first, q) is not None
    }
    time = np.concatenate([g.time + s for g, s in zip(logs, shift, strict=True)])
    meta = {**first.meta, "files": [g.source for g in logs]}
    return RobotLog(
        time=time,
        joints=first.joints,
        torque_constants=first.torque_constants,
        source=first.source,
        meta=meta,
        **cols,
    )


def write_robot_log(log: RobotLog, path: PathLike) -> Path:
    """Write a robot log as a CSV or Parquet table, atomically.

    Parameters
    ----------
    log : RobotLog
        The log; its joint names must be writable in a header (no ``,;"[]#``, tabs,
        newlines or blanks around them).
    path : str or os.PathLike
        The file; ``.csv`` or ``.parquet`` / ``.pq`` chooses the format.

    Returns
    -------
    pathlib.Path
        The path written: ``time [s]`` and ``<joint>.<quantity> [unit]`` columns in SI, the
        source, torque constants and ``meta`` in the comment lines (CSV) or the schema
        metadata (Parquet). :func:`read_robot_log` reads it back to the same log.

    Raises
    ------
    ConfigError
        Not a RobotLog, an unknown suffix, an unwritable joint name, ``meta`` that is not
        JSON-serialisable.
    """
    return write_robot_table(log, path)
