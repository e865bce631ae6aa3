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
"""

from __future__ import annotations

import contextlib
import json
import logging
import math
import os
import re
import shutil
from pathlib import Path
from typing import Any

from .. import __version__
from ..errors import ConfigError
from ..io import atomic_write
from ..io.atomic import pid_alive, remove_stale
from .hashing import RECORD_FORMAT
from .job import JointOutcome
from .manifest import JointSpec

__all__ = ["FleetStore"]

logger = logging.getLogger(__name__)

#: The folders :func:`fricid.fleet.table.write_results` swaps the results table through.
_RESULTS_SWAP = re.compile(r"\.results-(?:new-(?P<new>[0-9]+)-[0-9a-f]{8}|old-(?P<old>[0-9]+))\Z")

#: What such a folder holds: Parquet parts under robot=/date= partitions, nothing else.
_RESULTS_PART = re.compile(r"robot=[^/]*/date=[^/]*/part-[0-9]+\.parquet\Z")


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


class FleetStore:
    """The output folder ``root`` of a fleet run; use as a context manager (it locks)."""

    def __init__(self, root: str | os.PathLike[str]) -> None:
        self.root = Path(root)
        self._lock: Any = None

    # -- opening -------------------------------------------------------------------------
    def __enter__(self) -> FleetStore:
        self.root.mkdir(parents=True, exist_ok=True)
        self._acquire()
        self._remove_leftovers()
        return self

    def __exit__(self, *exc: object) -> None:
        if self._lock is not None:
            self._lock.close()  # closing the file releases the lock
            self._lock = None

    def _acquire(self) -> None:
        fh = open(self.root / ".lock", "a+b")  # noqa: SIM115 - held open while the run lasts
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
        never a file fricid did not write)."""
        remove_stale(self.root, recursive=True)
        for tmp in self.root.glob(".results-*"):
            if _is_stale_results(tmp):
                shutil.rmtree(tmp, ignore_errors=True)

    # -- paths ---------------------------------------------------------------------------
    def record_path(self, robot: str, joint: str) -> Path:
        return self.root / "records" / robot / f"{joint}.json"

    def model_path(self, robot: str, joint: str, model: str) -> Path:
        return self.root / "models" / robot / f"{joint}.{model}.json"

    # -- records -------------------------------------------------------------------------
    def load(self, spec: JointSpec) -> dict[str, Any] | None:
        """The joint's previous record, or None (none, unreadable or of another format)."""
        path = self.record_path(spec.robot, spec.joint)
        try:
            record = json.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            return None
        except (OSError, ValueError) as exc:
            logger.warning("ignoring unreadable record %s: %s", path, exc)
            return None
        if not isinstance(record, dict) or record.get("format") != RECORD_FORMAT:
            return None
        return record

    def _write_json(self, path: Path, doc: dict[str, Any]) -> None:
        with atomic_write(path, "w") as fh:
            json.dump(_clean(doc), fh, indent=1, allow_nan=False)
            fh.write("\n")

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
            path = self.model_path(spec.robot, spec.joint, model)
            self._write_json(path, doc)
            files[model] = path.relative_to(self.root).as_posix()
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
            "rows": rows,
        }
        self._write_json(self.record_path(spec.robot, spec.joint), record)
        for model, rel in ((previous or {}).get("model_files") or {}).items():
            if model not in files:
                with contextlib.suppress(OSError):
                    (self.root / rel).unlink()
        return _clean(record)

    def refresh(
        self, record: dict[str, Any], *, date: str, input_stat: str | None
    ) -> dict[str, Any]:
        """A reused record with a new date or stat signature (rewritten only if changed)."""
        if record.get("date") == date and record.get("input_stat") == input_stat:
            return record
        record = {**record, "date": date, "input_stat": input_stat}
        record["rows"] = [{**row, "date": date} for row in record.get("rows", [])]
        self._write_json(self.record_path(record["robot"], record["joint"]), record)
        return record
