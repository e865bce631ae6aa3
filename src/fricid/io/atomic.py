"""Atomic file output: write to a temporary file beside the target, then rename.

A reader never sees a half-written file, and a writer that fails leaves the target as it was:
absent if it did not exist, untouched if it did (DESIGN.md, "Files").
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

__all__ = ["atomic_path", "atomic_write"]


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
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
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
    if os.name == "posix":  # make the rename itself durable
        with contextlib.suppress(OSError):
            dfd = os.open(path.parent, os.O_RDONLY)
            try:
                os.fsync(dfd)
            finally:
                os.close(dfd)


def _discard(tmp: Path) -> None:
    with contextlib.suppress(FileNotFoundError):
        tmp.unlink()


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
