"""Opening input files: regular files (or folders) only, whole-file reads with a byte cap.

A path given as input may name something that is not a file at all: ``/dev/zero`` (its size
reads 0, so a check of the size alone lets it through, and a read never ends), a FIFO (opening
it blocks until a writer comes), a socket, a terminal. Every reader checks its input with
:func:`check_input` before opening it, and a reader that takes a whole file into memory does
so with :func:`read_capped`, which reads at most the cap plus one byte whatever the size the
file system reports.
"""

from __future__ import annotations

import os
import stat

from ..errors import DataError

__all__ = ["MAX_TEXT_BYTES", "check_input", "read_capped", "size_text"]

#: Largest text file read whole into memory [bytes] (an EPOS export, a per-channel file): the
#: parsers need several times its size.
MAX_TEXT_BYTES = 256 * 2**20

_KINDS = (
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISSOCK, "a socket"),
)


def _kind(mode: int) -> str:
    for test, name in _KINDS:
        if test(mode):
            return name
    return "not a regular file"


def check_input(
    path: str | os.PathLike[str], *, folder: bool | None = False, what: str = "file"
) -> os.stat_result:
    """Refuse an input that is missing, or neither a regular file nor (where allowed) a folder.

    Parameters
    ----------
    path : str or os.PathLike
        The input (symbolic links are followed).
    folder : bool or None, default False
        False: a regular file is needed; True: a folder; None: either.
    what : str, default "file"
        What the input is, for messages (``"MATLAB file"``).

    Returns
    -------
    os.stat_result
        The input's status.

    Raises
    ------
    DataError
        One line naming the path: no such file, cannot be read, a folder where a file is
        needed (or the reverse), a device, FIFO or socket.
    """
    try:
        st = os.stat(path)
    except OSError as exc:
        raise DataError(f"cannot read the {what}: {exc.strerror or exc}", file=path) from None
    if stat.S_ISREG(st.st_mode):
        if folder is True:
            raise DataError(f"cannot read the {what}: a file, not a folder", file=path)
    elif stat.S_ISDIR(st.st_mode):
        if folder is False:
            raise DataError(f"cannot read the {what}: a folder, not a file", file=path)
    else:
        need = {False: "a regular file", True: "a folder", None: "a regular file or a folder"}
        raise DataError(
            f"cannot read the {what}: {_kind(st.st_mode)}, not {need[folder]}", file=path
        )
    return st


def read_capped(
    path: str | os.PathLike[str], cap: int | None = None, *, what: str = "file"
) -> bytes:
    """The bytes of a regular file, refused beyond ``cap`` without reading further.

    The file is opened without blocking (a FIFO swapped in after a check does not hang the
    reader) and checked again once open, then read to its end or to ``cap + 1`` bytes,
    whichever comes first: the size the file system reports is not trusted.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    cap : int, optional
        The largest size accepted [bytes]; default :data:`MAX_TEXT_BYTES`.
    what : str, default "file"
        What the file is, for messages.

    Returns
    -------
    bytes
        The whole file.

    Raises
    ------
    DataError
        As :func:`check_input`, or the file is larger than ``cap``.
    """
    cap = MAX_TEXT_BYTES if cap is None else int(cap)
    check_input(path, what=what)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        raise DataError(f"cannot read the {what}: {exc.strerror or exc}", file=path) from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise DataError(f"cannot read the {what}: {_kind(mode)}, not a regular file", file=path)
        parts: list[bytes] = []
        held = 0
        while held <= cap:
            part = os.read(fd, min(cap + 1 - held, 1 << 24))
            if not part:
                break
            parts.append(part)
            held += len(part)
    except OSError as exc:
        raise DataError(f"cannot read the {what}: {exc.strerror or exc}", file=path) from None
    finally:
        os.close(fd)
    if held > cap:
        raise DataError(f"the {what} is larger than {size_text(cap)}", file=path)
    return b"".join(parts)


def size_text(n: int) -> str:
    """A byte count for messages: ``256 MiB``, ``74.5 GiB``, ``1000 bytes``."""
    for unit, scale in (("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= scale:
            return f"{n // scale} {unit}" if n % scale == 0 else f"{n / scale:.3g} {unit}"
    return f"{n} bytes"
