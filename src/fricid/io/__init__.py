"""Readers and writers: fricid's CSV and Parquet tables, Maxon EPOS recorder CSV, ROS 2 bags
and MCAP, generic column-mapped logs, per-channel ``time value`` files, MATLAB files; robot
logs of all joints at once (:mod:`.robot_logs`); the registry of readers and their options
(:mod:`.registry`: :data:`READERS`, :data:`READER_OPTIONS`, :func:`open_log`); the parsers of
option values written as text (:mod:`.options`); atomic writes (:mod:`.atomic`).

Every reader converts to SI once, at the edge, and names the file, row and column of bad
input (:class:`~fricid.errors.DataError`); every writer is atomic (DESIGN.md, "Files"). An
input that is not a regular file (a device such as ``/dev/zero``, a FIFO, a socket), or not a
folder where one is expected, is refused before it is opened, and a file read whole is read
with a byte cap (:mod:`._files`). What a file declares (array sizes, compressed sizes) is
checked against a cap before anything is allocated; Parquet and MCAP checksums are verified.

The readers and writers are imported on first use, so a module that needs only the registry,
the option parsers or the atomic writer (the fleet manifest, a fleet worker) does not import
pandas, pyarrow or rosbags.
"""

from __future__ import annotations

import importlib
from typing import Any

from ._dialect import csv_dialect as csv_dialect
from .atomic import atomic_path as atomic_path
from .atomic import atomic_write as atomic_write
from .registry import EPOS_FOLDER_ONLY as EPOS_FOLDER_ONLY
from .registry import READER_EXAMPLES as READER_EXAMPLES
from .registry import READER_OPTIONS as READER_OPTIONS
from .registry import READERS as READERS
from .registry import check_reader as check_reader
from .registry import open_log as open_log

#: Public name -> the module defining it (imported on first use).
_WHERE = {
    "DEFAULT_NOMINAL_TORQUE": "epos",
    "epos_steady_samples": "epos",
    "read_epos": "epos",
    "read_epos_dir": "epos",
    "read_table_log": "generic",
    "read_channels": "channels",
    "read_mat": "matlab",
    "mat_variables": "matlab",
    "iter_rosbag": "rosbag",
    "read_rosbag": "rosbag",
    "rosbag_joints": "rosbag",
    "rosbag_topics": "rosbag",
    "read_robot_log": "robot_logs",
    "write_robot_log": "robot_logs",
    "iter_rawlog": "tables",
    "read_rawlog": "tables",
    "read_samples": "tables",
    "write_rawlog": "tables",
    "write_samples": "tables",
}

__all__ = sorted(
    [
        *_WHERE,
        "EPOS_FOLDER_ONLY",
        "READERS",
        "READER_EXAMPLES",
        "READER_OPTIONS",
        "atomic_path",
        "atomic_write",
        "check_reader",
        "csv_dialect",
        "open_log",
    ]
)


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_WHERE})
