"""Fleet scale: identify every joint of many robots in one call, locally or on a Dask cluster.

>>> from fricid.fleet import make_executor, run_fleet
>>> run = run_fleet("fleet.csv", "results", executor=make_executor(cluster="local:4"))
...                                                               # doctest: +SKIP
>>> run.table.head(), run.failures                                # doctest: +SKIP

Each joint runs :func:`fricid.workflow.run_joint` (the same extraction and fit as
``fricid extract`` and ``fricid fit``). Modules: :mod:`.manifest` (the manifest, validated
with its JSON Schema through :mod:`._manifest_schema`), :mod:`.job` (one joint, as a worker
runs it), :mod:`.executors` and :mod:`._dask` (where the joints run), :mod:`.store` (the
output folder, resumable), :mod:`.table` (the results table), :mod:`.drift` (comparison with
a previous identification), :mod:`.runner` (:func:`run_fleet`).

The names below are imported on first use, so a worker process that only runs
:func:`run_job` does not import pandas, matplotlib or Dask.
"""

from __future__ import annotations

import importlib
from typing import Any

#: Public name -> the module defining it.
_WHERE = {
    "Drift": "drift",
    "compare": "drift",
    "plot_drift": "drift",
    "write_drift": "drift",
    "Executor": "executors",
    "ProcessExecutor": "executors",
    "SerialExecutor": "executors",
    "make_executor": "executors",
    "DaskExecutor": "_dask",
    "JointJob": "job",
    "JointOutcome": "job",
    "run_job": "job",
    "FIELDS": "manifest",
    "JointSpec": "manifest",
    "Manifest": "manifest",
    "read_manifest": "manifest",
    "FleetRun": "runner",
    "JointEvent": "runner",
    "run_fleet": "runner",
    "FleetStore": "store",
    "RUN_COLUMNS": "table",
    "read_results": "table",
    "results_table": "table",
    "write_results": "table",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *_WHERE])
