"""Readers and writers: fricid's CSV and Parquet tables, Maxon EPOS recorder CSV, ROS 2 bags
and MCAP, generic column-mapped logs; the registry of readers and their options
(:mod:`.registry`: :data:`READERS`, :data:`READER_OPTIONS`, :func:`open_log`).

Every reader converts to SI once, at the edge, and names the file, row and column of bad
input (:class:`~fricid.errors.DataError`); every writer is atomic (DESIGN.md, "Files").
"""

from .atomic import atomic_path, atomic_write
from .epos import DEFAULT_NOMINAL_TORQUE, epos_steady_samples, read_epos, read_epos_dir
from .generic import read_table_log
from .registry import EPOS_FOLDER_ONLY, READER_OPTIONS, READERS, check_reader, open_log
from .rosbag import iter_rosbag, read_rosbag, rosbag_joints, rosbag_topics
from .tables import iter_rawlog, read_rawlog, read_samples, write_rawlog, write_samples

__all__ = [
    "DEFAULT_NOMINAL_TORQUE",
    "EPOS_FOLDER_ONLY",
    "READERS",
    "READER_OPTIONS",
    "atomic_path",
    "atomic_write",
    "check_reader",
    "epos_steady_samples",
    "iter_rawlog",
    "iter_rosbag",
    "open_log",
    "read_epos",
    "read_epos_dir",
    "read_rawlog",
    "read_rosbag",
    "read_samples",
    "read_table_log",
    "rosbag_joints",
    "rosbag_topics",
    "write_rawlog",
    "write_samples",
]
