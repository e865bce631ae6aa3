"""Identify every joint of a manifest: :func:`run_fleet`.

For each joint the driver decides whether it must run (new, changed log, changed settings,
failed before, or ``force``), sends the jobs to an executor, writes each joint's record and
model files as its result arrives, and finally writes the results table. A joint that fails
is reported in the table and in :attr:`FleetRun.failures`; the others complete. An
interrupted run (Ctrl-C, or SIGTERM turned into an exception by the CLI) keeps every joint
finished so far and raises :class:`FleetInterrupted`, which says what was kept and how to
resume.
"""

from __future__ import annotations

import datetime as _dt
import logging
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from ..errors import ConfigError
from .executors import Executor, ProcessExecutor
from .hashing import input_stat, settings_hash
from .job import JointJob, JointOutcome, failed_outcome, run_job, show_warnings
from .manifest import JointSpec, Manifest, check_names, read_manifest
from .store import FleetStore
from .table import results_table, write_results

__all__ = ["FleetInterrupted", "FleetRun", "JointEvent", "run_fleet"]

logger = logging.getLogger(__name__)


class FleetInterrupted(KeyboardInterrupt):
    """A fleet run was interrupted; the joints finished so far are kept.

    Raised from the original ``KeyboardInterrupt`` (or the CLI's SIGTERM exception, a
    subclass of it), so ``except KeyboardInterrupt`` still catches it.

    Parameters
    ----------
    out : Path
        The output folder.
    kept : int
        Joints whose record is on disk (finished now or unchanged since the last run).
    failed : int
        Of those, the joints that failed (they run again next time).
    total : int
        Joints in the manifest.
    """

    def __init__(self, out: Path, kept: int, failed: int, total: int) -> None:
        self.out, self.kept, self.failed, self.total = Path(out), kept, failed, total
        failed_text = f" ({failed} of them failed and will run again)" if failed else ""
        super().__init__(
            f"kept {kept} of {total} joints finished{failed_text} in "
            f"{self.out / 'records'} (no results table yet); run the same command again "
            "to resume: finished joints are skipped"
        )


@dataclass(frozen=True, eq=False)
class JointEvent:
    """A joint finished: ``status`` is ``"computed"``, ``"skipped"`` (input and settings
    unchanged) or ``"failed"``; ``record`` is what the store holds for it."""

    spec: JointSpec
    status: str
    record: dict[str, Any]


@dataclass(frozen=True, eq=False)
class FleetRun:
    """The outcome of :func:`run_fleet`.

    Attributes
    ----------
    out : the output folder.
    results, results_csv : the Parquet dataset (folder) and the CSV written.
    table : the results table (one row per joint and model, manifest order).
    records : every joint's record, in manifest order.
    computed, skipped, failed : joint counts (failed joints are also counted as computed).
    failures : ``(robot, joint, stage, error)`` of each failed joint.
    seconds : wall time of the run [s].
    executor, workers : what ran the jobs.
    """

    out: Path
    results: Path
    results_csv: Path
    table: pd.DataFrame
    records: list[dict[str, Any]]
    computed: int
    skipped: int
    failed: int
    failures: list[tuple[str, str, str, str]] = field(default_factory=list)
    seconds: float = 0.0
    executor: str = ""
    workers: int = 0


@dataclass(frozen=True)
class _Pending:
    index: int
    spec: JointSpec
    settings: dict[str, Any]
    settings_hash: str
    stat: str | None
    previous: dict[str, Any] | None
    reusable: bool


def _today() -> str:
    return _dt.datetime.now(_dt.UTC).date().isoformat()


def _outcome(spec: JointSpec, result: JointOutcome | BaseException) -> JointOutcome:
    if isinstance(result, BaseException):
        return failed_outcome(spec, "worker", f"{type(result).__name__}: {result}")
    return result


def run_fleet(
    manifest: Manifest | str | os.PathLike[str],
    out: str | os.PathLike[str],
    *,
    executor: Executor | None = None,
    force: bool = False,
    date: str | None = None,
    progress: Callable[[JointEvent], None] | None = None,
) -> FleetRun:
    """Extract and fit every joint of ``manifest``, writing the results under ``out``.

    Parameters
    ----------
    manifest : a :class:`Manifest` or the path of one (:func:`read_manifest`).
    out : output folder (see :mod:`fricid.fleet.store` for its layout).
    executor : what runs the joints (:mod:`fricid.fleet.executors`); default a local process
        pool over every core. An executor passed in stays open.
    force : recompute every joint, even those whose input and settings are unchanged.
    date : the measurement date (YYYY-MM-DD) of joints whose manifest row gives none
        (default: today, UTC).
    progress : called once per joint as it finishes or is skipped.

    Returns
    -------
    FleetRun

    Notes
    -----
    A joint is skipped when its previous record succeeded with the same settings hash and
    its log has the same content hash. The log's size and modification time are compared
    first; if they differ, the worker hashes the content and skips the work when the hash
    still matches. Failed joints always run again. The table holds the manifest's joints
    only; records of joints no longer listed stay in ``records/`` but leave the table.

    The process pool starts its workers with ``spawn``: a script that calls ``run_fleet``
    with it must do so under ``if __name__ == "__main__":``, as ``multiprocessing`` requires.
    """
    t0 = time.perf_counter()
    if not isinstance(manifest, Manifest):
        manifest = read_manifest(manifest)
    if date is not None:
        try:
            date = _dt.date.fromisoformat(date).isoformat()
        except ValueError:
            raise ConfigError(f"date must be YYYY-MM-DD, got '{date}'") from None
    run_date = date or _today()
    for spec in manifest:  # before any work: names the file system cannot hold
        check_names(spec, manifest.path, out=out)
    owned = executor is None
    runner: Any = ProcessExecutor() if executor is None else executor
    notify = progress or (lambda event: None)
    records: list[dict[str, Any] | None] = [None] * len(manifest)
    computed = skipped = 0
    try:
        with FleetStore(out) as store:
            store.check_outputs()
            for spec in manifest:  # before any work: nothing is written through a link
                store.check(spec)
            pending: list[_Pending] = []
            for k, spec in enumerate(manifest):
                settings = spec.settings()
                digest = settings_hash(settings)
                stat = input_stat(spec.log, spec.reader, spec.reader_options)
                previous = store.load(spec)
                reusable = (
                    not force
                    and previous is not None
                    and previous.get("status") == "ok"
                    and previous.get("settings_hash") == digest
                )
                if reusable and stat is not None and previous.get("input_stat") == stat:
                    records[k] = store.refresh(
                        spec, previous, date=spec.date or previous["date"], input_stat=stat
                    )
                    skipped += 1
                    notify(JointEvent(spec, "skipped", records[k]))
                    continue
                pending.append(_Pending(k, spec, settings, digest, stat, previous, reusable))
            jobs = [
                JointJob(p.spec, p.previous.get("input_hash") if p.reusable else None)
                for p in pending
            ]
            for j, result in runner.run(run_job, jobs):
                p = pending[j]
                outcome = _outcome(p.spec, result)
                if outcome.status == "unchanged" and p.reusable:
                    record = store.refresh(
                        p.spec,
                        p.previous,
                        date=p.spec.date or p.previous["date"],
                        input_stat=p.stat,
                    )
                    skipped += 1
                    status = "skipped"
                else:
                    record = store.save(
                        p.spec,
                        outcome,
                        date=p.spec.date or run_date,
                        settings=p.settings,
                        settings_hash=p.settings_hash,
                        input_stat=p.stat,
                        previous=p.previous,
                    )
                    computed += 1
                    status = "computed" if outcome.status == "ok" else "failed"
                records[p.index] = record
                show_warnings(outcome)  # the worker's, as this process's (after the record)
                notify(JointEvent(p.spec, status, record))
            done = [r for r in records if r is not None]
            table = results_table(done)
            results, csv_path = write_results(table, store.root)
    except KeyboardInterrupt as exc:
        kept = [r for r in records if r is not None]
        failed = sum(1 for r in kept if r.get("status") != "ok")
        raise FleetInterrupted(Path(out), len(kept), failed, len(manifest)) from exc
    finally:
        if owned:
            runner.close()
    failures = [
        (r["robot"], r["joint"], r.get("stage") or "", r.get("error") or "")
        for r in done
        if r.get("status") != "ok"
    ]
    logger.info(
        "fleet: %d joints, %d computed, %d skipped, %d failed",
        len(done),
        computed,
        skipped,
        len(failures),
    )
    return FleetRun(
        out=Path(out),
        results=results,
        results_csv=csv_path,
        table=table.to_pandas(),
        records=done,
        computed=computed,
        skipped=skipped,
        failed=len(failures),
        failures=failures,
        seconds=time.perf_counter() - t0,
        executor=runner.name,
        workers=runner.workers,
    )
