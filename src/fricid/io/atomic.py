"""Atomic file output: write to a temporary file beside the target, then rename.

A reader never sees a half-written file, and a writer that fails leaves the target as it was:
absent if it did not exist, untouched if it did (DESIGN.md, "Files").

fricid's temporary files and folders carry fricid's mark in their names,
``.<target name>.fricid-<host>-<pid>-<random>.tmp``: the writer's host (a short hash of its
name) and process id. They are removed on every exit path of the writer (an exception,
``KeyboardInterrupt``, ``SystemExit``; the CLI turns SIGTERM into an exception; an
interpreter exit through :mod:`atexit`). A writer killed outright (SIGKILL, power loss)
leaves its temporary file; the next write of the same target removes it, as
:func:`remove_stale` does for a whole folder, once its writer's process is gone. Files
without fricid's mark are never touched, whatever their names.
"""

from __future__ import annotations

import atexit
import contextlib
import datetime as _dt
import hashlib
import logging
import os
import re
import shutil
import socket
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

__all__ = [
    "atomic_dir",
    "atomic_path",
    "atomic_write",
    "created_timestamp",
    "is_stale_temp",
    "pid_alive",
    "remove_stale",
    "temp_prefix",
]

logger = logging.getLogger(__name__)

#: A short hash of this host's name: a pid is only meaningful on the host that wrote it.
HOST_TAG = hashlib.sha256(socket.gethostname().encode("utf-8", "replace")).hexdigest()[:8]

#: The mark of fricid's temporary files and folders (see the module docstring).
_MARK = re.compile(r"\.fricid-(?P<host>[0-9a-f]{8})-(?P<pid>[0-9]+)-[A-Za-z0-9_]+\.tmp\Z")

#: The longest part of a target's name kept in its temporary file's name (names are <= 255).
_NAME_KEEP = 180

#: Temporary files and folders of this process still in use (absolute; removed at exit).
_live: set[str] = set()


def temp_prefix(name: str) -> str:
    """The prefix of a temporary file or folder for the target named ``name``.

    ``tempfile.mkstemp(prefix=temp_prefix(name), suffix=".tmp")`` gives a name that
    :func:`is_stale_temp` recognises as fricid's.
    """
    return f".{name[:_NAME_KEEP]}.fricid-{HOST_TAG}-{os.getpid()}-"


def pid_alive(pid: int) -> bool:
    """Whether a process ``pid`` exists on this host (when in doubt: True)."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True  # exists, owned by someone else (or cannot tell: keep the file)
    return True


def is_stale_temp(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is a temporary file or folder of fricid whose writer is gone.

    True only for a name with fricid's mark, written on this host by a process that no
    longer exists (or by this process, which no longer uses it). A name without the mark,
    or from another host, is never stale: it may be a user's file or a live writer's.
    """
    path = Path(path)
    match = _MARK.search(path.name)
    if match is None or not path.name.startswith(".") or match.group("host") != HOST_TAG:
        return False
    pid = int(match.group("pid"))
    if pid == os.getpid():
        return os.path.abspath(path) not in _live
    return not pid_alive(pid)


def _remove(path: Path) -> bool:
    try:
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        else:
            path.unlink()
    except FileNotFoundError:
        return False
    except OSError as exc:
        logger.warning("could not remove the stale temporary %s: %s", path, exc)
        return False
    return True


def remove_stale(
    folder: str | os.PathLike[str], *, recursive: bool = False, name: str | None = None
) -> list[Path]:
    """Remove the temporary files and folders that killed fricid writers left in ``folder``.

    Parameters
    ----------
    folder : str or path-like
        Where to look (a missing folder has nothing to remove).
    recursive : bool
        Also look in every sub-folder.
    name : str, optional
        Only temporaries of the target with this file name.

    Returns
    -------
    list of Path
        What was removed. Only names with fricid's mark whose writing process is gone
        (:func:`is_stale_temp`) are removed; every other file stays, whatever its name.
    """
    folder = Path(folder)
    pattern = f".{name[:_NAME_KEEP]}.fricid-*.tmp" if name is not None else ".*.fricid-*.tmp"
    try:
        found = list(folder.rglob(pattern) if recursive else folder.glob(pattern))
    except OSError:
        return []
    removed = [p for p in sorted(found) if is_stale_temp(p) and _remove(p)]
    if removed:
        logger.info("removed %d stale temporary file(s) under %s", len(removed), folder)
    return removed


def created_timestamp() -> str:
    """The creation time stamped into a file: now (UTC), or ``SOURCE_DATE_EPOCH``.

    Returns
    -------
    str
        ISO 8601 with seconds and the UTC offset, e.g. ``2026-03-01T12:00:00+00:00``.

    Notes
    -----
    ``SOURCE_DATE_EPOCH`` (seconds since 1970-01-01 UTC, the reproducible-builds convention,
    https://reproducible-builds.org/specs/source-date-epoch/) replaces the clock, so identical
    inputs give byte-identical files. A value that is not a non-negative integer is ignored
    with a warning in the log.
    """
    text = os.environ.get("SOURCE_DATE_EPOCH", "").strip()
    when = _dt.datetime.now(_dt.UTC)
    if text:
        try:
            seconds = int(text)
            if seconds < 0:
                raise ValueError(text)
            when = _dt.datetime.fromtimestamp(seconds, _dt.UTC)
        except (ValueError, OverflowError, OSError):
            logger.warning("ignoring SOURCE_DATE_EPOCH=%r: not a non-negative integer", text)
    return when.isoformat(timespec="seconds")


if hasattr(os, "register_at_fork"):  # a forked child owns none of its parent's temporaries
    os.register_at_fork(after_in_child=_live.clear)


@atexit.register
def _discard_live() -> None:
    """At interpreter exit, remove the temporaries this process still holds."""
    for tmp in list(_live):
        _discard(Path(tmp))


def _umask() -> int:
    """The process umask, read without changing it (Linux), else the usual 0o022."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    return 0o022


def _new_temp(path: Path) -> Path:
    """A new, marked temporary file beside ``path``; stale ones of the same target go first."""
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale(path.parent, name=path.name)
    fd, tmp = tempfile.mkstemp(prefix=temp_prefix(path.name), suffix=".tmp", dir=path.parent)
    os.close(fd)
    _live.add(os.path.abspath(tmp))
    return Path(tmp)


def _commit(tmp: Path, path: Path) -> None:
    """fsync ``tmp``, give it the permissions a new file would get, and rename it to ``path``."""
    with open(tmp, "rb+") as fh:
        os.fsync(fh.fileno())
    try:
        mode = path.stat().st_mode & 0o7777
    except FileNotFoundError:
        mode = 0o666 & ~_umask()
    os.chmod(tmp, mode)
    os.replace(tmp, path)
    _live.discard(os.path.abspath(tmp))
    if os.name == "posix":  # make the rename itself durable
        with contextlib.suppress(OSError):
            dfd = os.open(path.parent, os.O_RDONLY)
            try:
                os.fsync(dfd)
            finally:
                os.close(dfd)


def _discard(tmp: Path) -> None:
    with contextlib.suppress(FileNotFoundError):
        if tmp.is_dir() and not tmp.is_symlink():
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            tmp.unlink()
    _live.discard(os.path.abspath(tmp))


@contextlib.contextmanager
def atomic_write(
    path: str | os.PathLike[str],
    mode: str = "w",
    *,
    encoding: str | None = "utf-8",
    newline: str | None = "\n",
) -> Iterator[IO[Any]]:
    """Open a temporary file for writing; on success it replaces ``path`` atomically.

    Parameters
    ----------
    path : the file to (re)write. Missing parent directories are created.
    mode : ``"w"`` (text) or ``"wb"`` (binary).
    encoding, newline : for text mode (UTF-8, ``"\\n"`` line ends by default).

    Notes
    -----
    The temporary file lives in the target's directory (so the rename is atomic) and is
    fsync'ed before the rename. If the body raises, the temporary file is removed and
    ``path`` is left as it was.

    Examples
    --------
    >>> with atomic_write(tmp / "out.txt") as fh:  # doctest: +SKIP
    ...     fh.write("hello")
    """
    if mode not in ("w", "wb"):
        raise ValueError(f"atomic_write mode must be 'w' or 'wb', got {mode!r}")
    path = Path(path)
    tmp = _new_temp(path)
    try:
        text = {} if mode == "wb" else {"encoding": encoding, "newline": newline}
        with open(tmp, mode, **text) as fh:
            yield fh
        _commit(tmp, path)
    except BaseException:
        _discard(tmp)
        raise


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """A temporary path for libraries that write by file name (pyarrow, matplotlib).

    The body writes the file at the yielded path; on success it is fsync'ed and renamed to
    ``path``. If the body raises, whatever it wrote is removed and ``path`` is left as it was.
    """
    path = Path(path)
    tmp = _new_temp(path)
    try:
        yield tmp
        _commit(tmp, path)
    except BaseException:
        _discard(tmp)
        raise


@contextlib.contextmanager
def atomic_dir(path: str | os.PathLike[str]) -> Iterator[Path]:
    """A temporary folder that replaces the folder ``path`` when the body succeeds.

    The body fills the yielded folder (marked as fricid's, beside ``path``); on success an
    existing ``path`` is renamed aside (to a marked name) and the new folder renamed in its
    place, then the old one is deleted. If the body raises, the new folder is removed and
    ``path`` is left as it was. A killed run leaves only marked folders, which
    :func:`remove_stale` removes later.

    Parameters
    ----------
    path : str or path-like
        The folder to (re)write. Missing parents are created.

    Yields
    ------
    Path
        The temporary folder to fill.

    Notes
    -----
    The two renames are not one atomic step: a process killed between them leaves no
    ``path``, and the previous folder under a marked name beside it.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale(path.parent, name=path.name)
    tmp = Path(tempfile.mkdtemp(prefix=temp_prefix(path.name), suffix=".tmp", dir=path.parent))
    _live.add(os.path.abspath(tmp))
    try:
        os.chmod(tmp, 0o777 & ~_umask())  # mkdtemp makes it 0o700
        yield tmp
    except BaseException:
        _discard(tmp)
        raise
    old = None
    try:
        if path.exists():
            old = Path(
                tempfile.mkdtemp(prefix=temp_prefix(path.name), suffix=".tmp", dir=path.parent)
            )
            _live.add(os.path.abspath(old))
            os.replace(path, old)  # (replaces the empty folder made just now)
        os.replace(tmp, path)
    except BaseException:  # put the previous folder back before anything is removed
        if old is not None and not path.exists() and any(old.iterdir()):
            os.replace(old, path)
        if old is not None:
            _discard(old)
        _discard(tmp)
        raise
    _live.discard(os.path.abspath(tmp))
    if old is not None:
        _discard(old)
