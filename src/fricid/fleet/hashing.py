"""Content hashes of a joint's input and settings, and a cheap stat signature of the input.

A re-run skips a joint whose input content and settings are unchanged. The content hash is
computed by the worker that reads the log (so a plant's terabytes are not hashed twice, nor
by the driver alone); the driver first compares the stat signature (sizes and modification
times, as make and git do) and sends the previous content hash along, so a worker that finds
the content unchanged returns at once.
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import stat
from pathlib import Path
from typing import Any

from .. import __version__
from ._fs import kind_of

__all__ = ["RECORD_FORMAT", "input_files", "input_hash", "input_stat", "settings_hash"]

#: Format of a joint's record (part of the settings hash: a new format re-runs every joint).
RECORD_FORMAT = "fricid-fleet-record/1"

_BLOCK = 1 << 20


#: Readers that take a folder as a joint's log (an EPOS folder of recordings, a ROS 2 bag,
#: a folder of per-channel files; a whole robot's log: a bag or a folder of channels too); the
#: others read one file.
FOLDER_READERS = ("epos", "rosbag", "channels", "robot")


def _regular(path: Path) -> None:
    """Refuse (``OSError``) a log file that is not a regular file: a FIFO would block the
    worker that opens it, a device (``/dev/zero``) would be read without end."""
    mode = os.stat(path).st_mode
    if not stat.S_ISREG(mode):
        raise OSError(errno.EINVAL, f"{kind_of(mode)}, not a regular file", str(path))


def input_files(path: Path, reader: str, reader_options: dict[str, Any]) -> list[Path]:
    """The files a joint's log consists of: the file, an EPOS folder's recordings, or every
    file of another folder (a ROS 2 bag: its metadata and storage files).

    Raises :class:`OSError` when the log is missing, when it is a folder for a reader that
    reads one file, or when it (or a file in its folder) is not a regular file: a FIFO, a
    device or a socket, checked with ``os.stat`` before anything opens it.
    """
    mode = os.stat(path).st_mode  # FileNotFoundError when missing
    if stat.S_ISDIR(mode):
        if reader not in FOLDER_READERS:
            raise OSError(errno.EISDIR, f"a folder; reader '{reader}' reads a file", str(path))
        if reader == "epos":
            pattern = str(reader_options.get("pattern", "*.csv"))
            found = [p for p in path.glob(pattern) if not p.is_dir()]
        else:
            found = [p for p in path.rglob("*") if not p.is_dir()]
        for p in found:
            _regular(p)
        return sorted(found)
    _regular(path)
    return [path]


def input_hash(path: Path, reader: str, reader_options: dict[str, Any]) -> str:
    """SHA-256 of the log's bytes (for a folder: of each file's name and bytes, in order)."""
    h = hashlib.sha256()
    files = input_files(path, reader, reader_options)
    for f in files:
        if len(files) > 1 or f != path:
            name = f.relative_to(path).as_posix() if f != path and path.is_dir() else f.name
            h.update(name.encode("utf-8") + b"\0")
        with open(f, "rb") as fh:
            while block := fh.read(_BLOCK):
                h.update(block)
    return h.hexdigest()


def input_stat(path: Path, reader: str, reader_options: dict[str, Any]) -> str | None:
    """Paths, sizes and modification times of the log's files, hashed; None if unreadable."""
    try:
        files = input_files(path, reader, reader_options)
        parts = [(str(f), f.stat().st_size, f.stat().st_mtime_ns) for f in files]
    except OSError:
        return None
    return hashlib.sha256(json.dumps(parts).encode("utf-8")).hexdigest()[:32]


def settings_hash(settings: dict[str, Any]) -> str:
    """SHA-256 of a joint's settings, the record format and fricid's version."""
    doc = {"settings": settings, "format": RECORD_FORMAT, "fricid": __version__}
    text = json.dumps(doc, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:32]
