"""Checks of the paths a command was given, before it reads or writes anything.

Every command calls :func:`check_paths` once, first thing, with its input and output paths,
so that a missing input, a folder where a file is meant (or the reverse), an input that is
neither a regular file nor a folder (a device, a FIFO) and an output that
cannot be written are one line on stderr and exit status 2 (DESIGN.md, "Errors"), never a
traceback, a usage screen or a partial output (a second output refused after the first was
written). The commands leave ``exists=`` and ``dir_okay=`` out of their ``typer`` arguments:
the library's own check prints a three-line usage screen instead.
"""

from __future__ import annotations

import os
from collections.abc import Collection, Mapping
from pathlib import Path

from ..errors import ConfigError, DataError
from ..io._files import check_input

__all__ = ["check_paths", "read_samples_file"]

Paths = Mapping[str, Path | None]


def _input(name: str, path: Path, folders: bool) -> None:
    if not path.exists():
        what = "file or folder" if folders else "file"
        raise ConfigError(f"{name}: no such {what} '{path}'")
    if path.is_dir() and not folders:
        raise ConfigError(f"{name}: '{path}' is a folder; give a file")
    try:  # a device (/dev/zero), a FIFO or a socket would never end or block the read
        check_input(path, folder=None, what="input")
    except DataError as exc:
        raise ConfigError(f"{name}: {exc}") from None


def _out_file(name: str, path: Path) -> None:
    if getattr(path, "folder_meant", False):  # ``--out d/``: ``_options.OutPath``
        raise ConfigError(
            f"{name}: '{path}{os.sep}' names a folder (it ends with '{os.sep}'); give the name "
            f"of a file to write in it (e.g. '{path / 'model'}' with the format's extension: "
            ".json, .csv, .xml, .urdf, .yaml)"
        )
    if path.is_dir():
        raise ConfigError(
            f"{name}: '{path}' is an existing folder; give the name of a file to write"
        )
    parent = path.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent  # writers create missing folders
    if not parent.is_dir():
        raise ConfigError(f"{name}: cannot write '{path}': '{parent}' is a file, not a folder")


def _out_dir(name: str, path: Path) -> None:
    if path.exists() and not path.is_dir():
        raise ConfigError(f"{name}: '{path}' is an existing file; give a folder to write into")


def check_paths(
    *,
    inputs: Paths | None = None,
    folders: bool | Collection[str] = False,
    out_files: Paths | None = None,
    out_dirs: Paths | None = None,
) -> None:
    """Raise :class:`~fricid.errors.ConfigError` (one line) for the first unusable path.

    Parameters
    ----------
    inputs : Mapping[str, Path or None]
        Paths to read, keyed by the argument or option name shown in the message
        (``{"SAMPLES": samples}``); each must exist. None values are skipped.
    folders : bool or Collection[str]
        Whether the inputs may be folders (a folder of EPOS recordings, a rosbag2 folder),
        or the names of those that may; by default each must be a file.
    out_files : Mapping[str, Path or None]
        Files to write: each must not be an existing folder, nor lie below a file.
    out_dirs : Mapping[str, Path or None]
        Folders to write into: each must not be an existing file.

    Examples
    --------
    >>> check_paths(inputs={"SAMPLES": Path("s.csv")}, out_files={"--out": None})  # doctest: +SKIP
    """
    for name, path in (inputs or {}).items():
        if path is not None:
            ok = folders if isinstance(folders, bool) else name in folders
            _input(name, Path(path), ok)
    for name, path in (out_files or {}).items():
        if path is not None:
            _out_file(name, path if isinstance(path, Path) else Path(path))  # keeps an OutPath
    for name, path in (out_dirs or {}).items():
        if path is not None:
            _out_dir(name, Path(path))


def read_samples_file(path: Path):
    """:func:`fricid.io.read_samples` of ``path``; a raw log (time, position, torque) given
    where samples go is told the commands that take it."""
    from ..io import read_samples

    try:
        return read_samples(path)
    except DataError as exc:
        raw = exc.column == "friction" and "'time" in exc.message and "found" in exc.message
        if not raw:
            raise
        raise DataError(
            f"{exc.message}; a log of time, position and torque is a raw log: identify from "
            "it with fricid fit LOG --trajectory, or extract samples from its constant-velocity "
            "runs with fricid extract LOG",
            file=exc.file,
            column=exc.column,
        ) from None
