"""The output folder of a fleet run: one record and one model file per joint, written atomically.

Layout::

    OUT/records/<robot>/<joint>.json           what happened to the joint (the source of truth)
    OUT/models/<robot>/<joint>.<model>.json    one FittedModel JSON per joint and model
    OUT/results/robot=<r>/date=<d>/part-0.parquet   the results table (see .table)
    OUT/results.csv

Every file is replaced atomically (temporary file, then rename), and each joint's record is
written as soon as its result arrives, so an interrupted run keeps every finished joint and
the next run resumes from there. A run holds a lock on ``OUT/.lock``: two runs cannot write
the same folder at once. Temporary files and folders a killed run left behind are removed when
the next run opens the folder, and only those: a file is removed only if its name carries
fricid's mark and its writer's process is gone (:func:`fricid.io.atomic.remove_stale`), or it
is a results folder being swapped in by a fricid process that is gone
(:func:`_is_stale_results`). A user's ``notes.tmp`` or ``.results-2025`` stays.

Records are data, never instructions. The store writes only the files of the layout above,
each only through real folders under ``OUT`` (a symbolic link on the way, a FIFO or a folder
where a file belongs is refused with one line naming it: :func:`._fs.require_real`), and it
deletes only the model files it wrote itself: a previous record's model file is removed only
if its path is the one this layout gives the joint and model, under real folders; any other
path a record names (absolute, with ``..``, through a link, of another joint) is left alone
with a warning. A record that is not a regular file, is too large, is of another joint or
holds values of the wrong kinds is ignored with a warning (the joint runs again).
"""

from __future__ import annotations

import datetime as _dt
import errno
import json
import logging
import math
import os
import re
import shutil
import stat
import warnings
from pathlib import Path
from typing import Any

from .. import __version__
from ..errors import ConfigError, DataQualityWarning, user_stacklevel
from ..io import atomic_write
from ..io.atomic import pid_alive, remove_stale
from ._fs import kind_of, model_parts, read_regular, record_parts, require_real
from .hashing import RECORD_FORMAT
from .job import JointOutcome, warning_lines
from .manifest import JointSpec
from .table import row_problem

__all__ = ["FleetStore"]

logger = logging.getLogger(__name__)

#: The folders :func:`fricid.fleet.table.write_results` swaps the results table through.
_RESULTS_SWAP = re.compile(r"\.results-(?:new-(?P<new>[0-9]+)-[0-9a-f]{8}|old-(?P<old>[0-9]+))\Z")

#: What such a folder holds: Parquet parts under robot=/date= partitions, nothing else.
_RESULTS_PART = re.compile(r"robot=[^/]*/date=[^/]*/part-[0-9]+\.parquet\Z")

#: The largest record read [bytes] (a record is a few kB; a traceback at most some more).
MAX_RECORD_BYTES = 16 * 2**20

#: A model name as the store puts it in a file name.
_MODEL = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]*\Z")

#: The keys of a record whose values are text or None.
_TEXT_KEYS = ("stage", "error", "traceback", "input_hash", "input_stat", "settings_hash", "log")


def _is_stale_results(folder: Path) -> bool:
    """Whether ``folder`` is a results folder of a fricid process that is gone.

    Its name must be one ``write_results`` gives (with the writer's pid), that pid must be
    gone (as for :func:`~fricid.io.atomic.is_stale_temp`), and it must hold only the
    partitioned Parquet parts fricid writes there: a user's folder of the same name survives.
    """
    match = _RESULTS_SWAP.match(folder.name)
    if match is None or not folder.is_dir() or folder.is_symlink():
        return False
    pid = int(match.group("new") or match.group("old"))
    if pid == os.getpid() or pid_alive(pid):
        return False
    try:
        entries = list(folder.rglob("*"))
    except OSError:
        return False
    files = [p for p in entries if not p.is_dir()]
    return all(
        not p.is_symlink() and _RESULTS_PART.match(p.relative_to(folder).as_posix()) for p in files
    )


def _clean(value: Any) -> Any:
    """JSON-ready: non-finite floats to None, recursively."""
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _iso_date(value: Any) -> bool:
    if not isinstance(value, str) or len(value) != 10:
        return False
    try:
        _dt.date.fromisoformat(value)
    except ValueError:
        return False
    return True


def _record_problem(record: dict[str, Any], spec: JointSpec) -> str | None:
    """Why ``record`` (of fricid's format) cannot be the record of ``spec``, or None."""
    if record.get("robot") != spec.robot or record.get("joint") != spec.joint:
        return "it is the record of another joint"
    if record.get("status") not in ("ok", "failed"):
        return "its status is neither 'ok' nor 'failed'"
    if not _iso_date(record.get("date")):
        return "its date is not a date (YYYY-MM-DD)"
    for key in _TEXT_KEYS:
        if not isinstance(record.get(key), str | None):
            return f"its {key} is not text"
    files = record.get("model_files", {})
    if not isinstance(files, dict) or not all(isinstance(v, str) for v in files.values()):
        return "its model_files is not a mapping of model names to paths"
    texts = record.get("warnings", [])
    if not isinstance(texts, list) or not all(isinstance(t, str) for t in texts):
        return "its warnings are not a list of texts"
    rows = record.get("rows", [])
    if not isinstance(rows, list) or not all(isinstance(r, dict) for r in rows):
        return "its rows are not a list of mappings"
    for row in rows:
        # a robot row's record holds a row per joint of the robot
        other = row.get("joint") != spec.joint and not spec.is_robot
        if row.get("robot") != spec.robot or other:
            return "a row is of another joint"
        if not _iso_date(row.get("date")):
            return "a row's date is not a date (YYYY-MM-DD)"
        why = row_problem(row)
        if why is not None:
            return why
    return None


class FleetStore:
    """The output folder ``root`` of a fleet run; use as a context manager (it locks)."""

    def __init__(self, root: str | os.PathLike[str]) -> None:
        self.root = Path(root)
        self._lock: Any = None

    # -- opening -------------------------------------------------------------------------
    def __enter__(self) -> FleetStore:
        try:
            self.root.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ConfigError(
                f"cannot make the output folder {self.root}: {exc.strerror or exc}"
            ) from None
        self._acquire()
        self._remove_leftovers()
        return self

    def __exit__(self, *exc: object) -> None:
        if self._lock is not None:
            self._lock.close()  # closing the file releases the lock
            self._lock = None

    def _acquire(self) -> None:
        path = self.root / ".lock"
        flags = os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0)
        flags |= getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
        try:
            fd = os.open(path, flags, 0o666)
        except OSError as exc:
            why = "a symbolic link" if exc.errno == errno.ELOOP else exc.strerror or str(exc)
            raise ConfigError(f"cannot lock {path} for this run: it is {why}") from None
        fh = os.fdopen(fd, "r+b")  # held open while the run lasts
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            fh.close()
            raise ConfigError(f"cannot lock {path} for this run: it is {kind_of(mode)}")
        try:
            import fcntl
        except ImportError:  # pragma: no cover - not POSIX: no lock
            self._lock = fh
            return
        try:
            fcntl.flock(fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            fh.close()
            raise ConfigError(
                f"another fricid fleet run is writing {self.root}; wait for it or use --out "
                "with another folder"
            ) from None
        self._lock = fh

    def _remove_leftovers(self) -> None:
        """Temporary files and folders a killed fricid run left (never a finished output,
        never a file fricid did not write, never anything behind a symbolic link)."""
        for folder, _dirs, _files in os.walk(self.root):  # does not follow links
            remove_stale(folder)
        for tmp in self.root.glob(".results-*"):
            if _is_stale_results(tmp):
                shutil.rmtree(tmp, ignore_errors=True)

    def check(self, spec: JointSpec) -> None:
        """Refuse (:class:`~fricid.errors.ConfigError`, one line naming the path) a joint
        whose record or model files could only be written through a symbolic link, or over
        something that is not a regular file (:func:`._fs.require_real`)."""
        require_real(self.root, record_parts(spec.robot, spec.joint))
        for model in spec.models:
            require_real(self.root, model_parts(spec.robot, spec.joint, model))

    def check_outputs(self) -> None:
        """Refuse a results folder or ``results.csv`` that is a link or of the wrong kind."""
        require_real(self.root, ["results"], folder=True)
        require_real(self.root, ["results.csv"])

    # -- paths ---------------------------------------------------------------------------
    def record_path(self, robot: str, joint: str) -> Path:
        return self.root.joinpath(*record_parts(robot, joint))

    def model_path(self, robot: str, joint: str, model: str) -> Path:
        return self.root.joinpath(*model_parts(robot, joint, model))

    # -- records -------------------------------------------------------------------------
    def _ignore(self, path: Path, why: str) -> None:
        warnings.warn(
            f"ignoring the record {path}: {why}; the joint runs again",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )

    def load(self, spec: JointSpec) -> dict[str, Any] | None:
        """The joint's previous record, or None (none, unreadable or of another format).

        A record that is not a regular file under real folders, is larger than
        :data:`MAX_RECORD_BYTES`, is not JSON, names another joint or holds values of the
        wrong kinds is ignored with a warning.
        """
        path = self.record_path(spec.robot, spec.joint)
        try:
            require_real(self.root, record_parts(spec.robot, spec.joint)[:-1], folder=True)
            text = read_regular(path, MAX_RECORD_BYTES, follow=False).decode("utf-8")
            record = json.loads(text)
        except FileNotFoundError:
            return None
        except ConfigError as exc:
            self._ignore(path, str(exc))
            return None
        except OSError as exc:
            self._ignore(path, f"it is {exc.strerror}" if exc.strerror else str(exc))
            return None
        except (ValueError, RecursionError) as exc:  # not UTF-8, not JSON, nested too deep
            self._ignore(path, f"not a record ({type(exc).__name__})")
            return None
        if not isinstance(record, dict) or record.get("format") != RECORD_FORMAT:
            return None
        why = _record_problem(record, spec)
        if why is not None:
            self._ignore(path, why)
            return None
        return record

    def _write_json(self, parts: tuple[str, ...], doc: dict[str, Any]) -> Path:
        path = require_real(self.root, parts)
        with atomic_write(path, "w") as fh:
            json.dump(_clean(doc), fh, indent=1, allow_nan=False)
            fh.write("\n")
        return path

    def _remove_model_file(self, spec: JointSpec, model: Any, rel: Any) -> None:
        """Delete a previous record's model file if it is one this store wrote for the
        joint (the layout's path for the joint and model, under real folders), else leave
        it and warn."""
        record = self.record_path(spec.robot, spec.joint)
        if isinstance(model, str) and _MODEL.match(model):
            parts = model_parts(spec.robot, spec.joint, model)
            if rel == "/".join(parts):
                try:
                    path = require_real(self.root, parts)
                except ConfigError as exc:
                    why = str(exc)
                else:
                    try:
                        path.unlink()
                    except FileNotFoundError:
                        pass
                    except OSError as exc:
                        logger.warning("could not remove %s: %s", path, exc.strerror or exc)
                    return
            else:
                why = f"fricid writes that model's file at {'/'.join(parts)} under {self.root}"
        else:
            why = "that is not a model name"
        warnings.warn(
            f"not deleting the model file {str(rel)[:200]!r} (model {str(model)[:80]!r}) "
            f"that the record {record} names: {why}",
            DataQualityWarning,
            stacklevel=user_stacklevel(),
        )

    def save(
        self,
        spec: JointSpec,
        outcome: JointOutcome,
        *,
        date: str,
        settings: dict[str, Any],
        settings_hash: str,
        input_stat: str | None,
        previous: dict[str, Any] | None = None,
    ) -> dict[str, Any]:
        """Write the joint's model files, then its record; return the record.

        Model files of a previous record that this outcome does not produce are removed,
        so a model file on disk always belongs to the current record.
        """
        files: dict[str, str] = {}
        for model, doc in outcome.models.items():
            parts = model_parts(spec.robot, spec.joint, model)
            self._write_json(parts, doc)
            files[model] = "/".join(parts)
        rows = []
        for row in outcome.rows:
            rows.append(
                {
                    **row,
                    "date": date,
                    "input_hash": outcome.input_hash,
                    "settings_hash": settings_hash,
                    "model_file": files.get(row["model"]),
                    "time_total_s": outcome.seconds,
                    "worker": outcome.worker,
                    "peak_rss_mb": outcome.peak_rss_mb,
                    "fricid_version": __version__,
                }
            )
        record = {
            "format": RECORD_FORMAT,
            "robot": spec.robot,
            "joint": spec.joint,
            "date": date,
            "log": spec.log_text,
            "status": outcome.status,
            "stage": outcome.stage,
            "error": outcome.error,
            "traceback": outcome.traceback,
            "input_hash": outcome.input_hash,
            "input_stat": input_stat,
            "settings_hash": settings_hash,
            "settings": settings,
            "seconds": outcome.seconds,
            "worker": outcome.worker,
            "peak_rss_mb": outcome.peak_rss_mb,
            "model_files": files,
            "warnings": warning_lines(outcome),
            "rows": rows,
        }
        self._write_json(record_parts(spec.robot, spec.joint), record)
        for model, rel in ((previous or {}).get("model_files") or {}).items():
            if model not in files:
                self._remove_model_file(spec, model, rel)
        return _clean(record)

    def refresh(
        self, spec: JointSpec, record: dict[str, Any], *, date: str, input_stat: str | None
    ) -> dict[str, Any]:
        """A reused record of ``spec`` with a new date or stat signature (rewritten, at the
        joint's own record path, only if changed)."""
        if record.get("date") == date and record.get("input_stat") == input_stat:
            return record
        record = {**record, "date": date, "input_stat": input_stat}
        record["rows"] = [{**row, "date": date} for row in record.get("rows", [])]
        self._write_json(record_parts(spec.robot, spec.joint), record)
        return record
