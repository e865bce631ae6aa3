"""The file system under a fleet: what the fleet writes, its limits, and safe reading.

Records are data, never instructions: the fleet writes and deletes only the files of its
own layout (:mod:`fricid.fleet.store`) under its output folder, never through a symbolic
link and never outside the folder. Names from a manifest are checked against the file
system's limits (``NAME_MAX`` bytes per name, ``PATH_MAX`` bytes per path) before any work,
counting every name the fleet derives from them (suffixes, the temporary names of
:mod:`fricid.io.atomic`, the results table's partition folders). Files the fleet reads
(the manifest, the records, the joints' logs) must be regular files (or folders where a
folder is expected): a FIFO, a device or a socket is refused before a byte is read, so
nothing blocks on it or reads it without end.
"""

from __future__ import annotations

import errno
import os
import stat
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import quote

from ..errors import ConfigError
from ..io.atomic import temp_prefix

__all__ = [
    "NAME_MAX",
    "PATH_MAX",
    "Derived",
    "fs_limits",
    "joint_names",
    "kind_of",
    "model_parts",
    "partition_dir",
    "read_regular",
    "record_parts",
    "require_real",
    "temp_name_bytes",
]

#: Bytes in one file name, and in a whole path (with its terminating NUL), where the file
#: system does not say (Linux's ext4, XFS, Btrfs and tmpfs).
NAME_MAX = 255
PATH_MAX = 4096

#: Random characters ``tempfile`` puts in a temporary name, and the suffix fricid gives it.
_TEMP_RANDOM = 8
_TEMP_SUFFIX = ".tmp"
#: Digits of the widest process id (Linux's ``pid_max`` is at most 2**22).
_PID_DIGITS = 7
#: The results folder (swapped in through a temporary folder beside it), a partition's
#: date folder (ISO dates have a fixed length) and its file (:mod:`.table`).
_RESULTS = "results"
_DATE_PART = "date=0000-00-00"
_PART_FILE = "part-0.parquet"


def partition_dir(value: object) -> str:
    """A hive partition folder's value, encoded as pyarrow's reader decodes it."""
    return "__HIVE_DEFAULT_PARTITION__" if value is None else quote(str(value), safe="")


def record_parts(robot: str, joint: str) -> tuple[str, str, str]:
    """The path of a joint's record under the output folder, as parts."""
    return ("records", robot, f"{joint}.json")


def model_parts(robot: str, joint: str, model: str) -> tuple[str, str, str]:
    """The path of a joint's model file under the output folder, as parts."""
    return ("models", robot, f"{joint}.{model}.json")


def temp_name_bytes(name: str) -> int:
    """Bytes in the name of the temporary file or folder fricid writes before ``name``
    (:mod:`fricid.io.atomic`), the writer's process id counted at its widest."""
    prefix = len(os.fsencode(temp_prefix(name))) - len(str(os.getpid())) + _PID_DIGITS
    return prefix + _TEMP_RANDOM + len(_TEMP_SUFFIX)


@dataclass(frozen=True)
class Derived:
    """A file or folder name the fleet derives from a joint's manifest names.

    Attributes
    ----------
    column : the manifest column whose value makes it long (``robot`` or ``joint``; a model
        file's name is the joint's with the model's, and model names are short).
    name : the name as written.
    name_bytes : bytes of its longest form on disk (it, or a file's temporary name).
    path_bytes : bytes of its longest path under the output folder, separators included.
    temporary : whether that longest form is the temporary name.
    """

    column: str
    name: str
    name_bytes: int
    path_bytes: int
    temporary: bool = False


def _derived(column: str, parents: tuple[str, ...], name: str, file: bool) -> Derived:
    own = len(os.fsencode(name))
    temp = temp_name_bytes(name) if file else 0
    longest = max(own, temp)
    path = sum(len(os.fsencode(p)) + 1 for p in parents) + longest
    return Derived(column, name, longest, path, temp > own)


def joint_names(robot: str, joint: str, models: Iterable[str]) -> list[Derived]:
    """Every file and folder name the fleet derives from a joint's names (:class:`Derived`):
    the robot's folders (records, models, the results table's partition), the record and
    each model file, each file with the temporary name it is first written under."""
    results = "X" * temp_name_bytes(_RESULTS)  # the results folder being swapped in
    part = f"robot={partition_dir(robot)}"
    out = [
        _derived("robot", ("records",), robot, False),
        _derived("robot", ("models",), robot, False),
        _derived("robot", (results,), part, False),
        _derived("robot", (results, part, _DATE_PART), _PART_FILE, True),
        _derived("joint", ("records", robot), record_parts(robot, joint)[-1], True),
    ]
    out += [
        _derived("joint", ("models", robot), model_parts(robot, joint, m)[-1], True) for m in models
    ]
    return out


def fs_limits(folder: str | os.PathLike[str]) -> tuple[int, int]:
    """``(NAME_MAX, PATH_MAX)`` of the file system that holds (or will hold) ``folder``.

    Asked of the nearest folder that exists (``os.pathconf``); :data:`NAME_MAX` and
    :data:`PATH_MAX` where the system cannot say.
    """
    here = Path(os.path.abspath(folder))
    while not here.is_dir() and here != here.parent:
        here = here.parent
    limits = []
    for key, default in (("PC_NAME_MAX", NAME_MAX), ("PC_PATH_MAX", PATH_MAX)):
        try:
            value = os.pathconf(here, key)
        except (OSError, ValueError, AttributeError):
            value = -1
        limits.append(value if value > 0 else default)
    return limits[0], limits[1]


def kind_of(mode: int) -> str:
    """What a file of ``st_mode`` is, in words."""
    kinds = (
        (stat.S_ISREG, "a file"),
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISLNK, "a symbolic link"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    )
    return next((text for test, text in kinds if test(mode)), "not a regular file")


def read_regular(path: str | os.PathLike[str], limit: int, *, follow: bool = True) -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` of them.

    The file is opened without blocking (a FIFO opens at once) and checked with ``fstat``
    before a byte is read. Anything but a regular file raises ``OSError`` (``EINVAL``, its
    kind as the message), as does a file larger than ``limit`` (``EFBIG``); with ``follow``
    false, a symbolic link too (``ELOOP``).
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    if not follow:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        if exc.errno == errno.ELOOP and not follow:
            raise OSError(errno.ELOOP, "a symbolic link", str(path)) from None
        raise
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise OSError(errno.EINVAL, kind_of(info.st_mode), str(path))
        if info.st_size > limit:
            raise OSError(errno.EFBIG, f"larger than {limit} bytes", str(path))
        chunks, left = [], limit + 1
        while left > 0:
            block = os.read(fd, min(left, 1 << 20))
            if not block:
                break
            chunks.append(block)
            left -= len(block)
    finally:
        os.close(fd)
    data = b"".join(chunks)
    if len(data) > limit:  # it grew while being read
        raise OSError(errno.EFBIG, f"larger than {limit} bytes", str(path))
    return data


def _target(link: Path) -> str:
    try:
        return os.readlink(link)
    except OSError:  # pragma: no cover - removed meanwhile
        return "?"


def _plain(part: str) -> bool:
    """Whether ``part`` is one plain name: no separator, no NUL, not ``.`` or ``..``."""
    seps = {"/", "\0", os.sep} | ({os.altsep} if os.altsep else set())
    return bool(part) and part not in (".", "..") and not any(s in part for s in seps)


def require_real(root: Path, parts: Iterable[str], *, folder: bool = False) -> Path:
    """``root`` joined with ``parts``, refused if writing there could leave ``root``.

    Each part must be one plain name (no separator, not ``.`` or ``..``); every part that
    exists must be a real folder (not a symbolic link), and the last, if it exists, a
    regular file (a real folder with ``folder``). Nothing is created.

    Raises
    ------
    ConfigError
        One line naming the path: a symbolic link, a file where a folder belongs, a folder,
        FIFO or device where a file belongs, or a part that is not a plain name.
    """
    parts = list(parts)
    for part in parts:
        if not _plain(part):
            raise ConfigError(f"{part[:80]!r} cannot name a file or folder under {root}")
    path = root
    for i, part in enumerate(parts):
        path = path / part
        try:
            info = os.lstat(path)
        except FileNotFoundError:
            return root.joinpath(*parts)
        except OSError as exc:
            raise ConfigError(f"cannot write {path}: {exc.strerror or exc}") from None
        if stat.S_ISLNK(info.st_mode):
            raise ConfigError(
                f"{path} is a symbolic link (to {_target(path)}); fricid writes under {root} "
                "only into real folders and files: remove the link or choose another "
                "output folder"
            )
        want_dir = folder or i < len(parts) - 1
        if want_dir != stat.S_ISDIR(info.st_mode) or not (want_dir or stat.S_ISREG(info.st_mode)):
            want = "a folder" if want_dir else "a file"
            raise ConfigError(f"{path} is {kind_of(info.st_mode)}, where fricid writes {want}")
    return path
