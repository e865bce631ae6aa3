"""The work of one joint, as a worker runs it: hash the log, then
:func:`fricid.workflow.run_joint`.

:func:`run_job` never raises for a bad joint: an unreadable log, a failed extraction or a
failed fit comes back as a :class:`JointOutcome` with the stage and the error (and, for an
error that is not fricid's own, its traceback), so one joint cannot stop the fleet. The worker
only computes; the driver writes every file.
"""

from __future__ import annotations

import os
import resource
import socket
import sys
import time
import traceback
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import FricidError
from ..fitted import FittedModel
from ..samples import FrictionSamples
from .hashing import input_hash
from .manifest import JointSpec

__all__ = [
    "JointJob",
    "JointOutcome",
    "failed_outcome",
    "fit_row",
    "run_job",
    "verdict_columns",
]


@dataclass(frozen=True, eq=False)
class JointJob:
    """What a worker needs for one joint.

    Attributes
    ----------
    spec : the joint's manifest row.
    expect_hash : the content hash of the log when it was last identified with the same
        settings; if the log still hashes to it, the worker returns ``"unchanged"`` at once.
    """

    spec: JointSpec
    expect_hash: str | None = None


@dataclass(eq=False)
class JointOutcome:
    """What a worker returns for one joint (plain data: it travels between processes).

    Attributes
    ----------
    robot, joint : the joint.
    status : ``"ok"`` (every model fitted), ``"failed"`` (the log could not be read or
        extracted, or some model's fit failed) or ``"unchanged"`` (content hash as expected).
    stage, error, traceback : where and why it failed (``read``, ``extract``, ``fit``,
        ``worker``, or ``error`` for an unexpected exception); the traceback only for an
        error that is not a ``FricidError``.
    input_hash : SHA-256 of the log, None if it could not be read.
    rows : one results-table row per model (see :func:`fit_row`).
    models : model name -> ``FittedModel.to_dict()`` of each successful fit.
    seconds : wall time of the whole job [s].
    worker : ``host:pid`` of the process that ran it.
    peak_rss_mb : that process's peak resident memory so far [MB].
    """

    robot: str
    joint: str
    status: str
    stage: str | None = None
    error: str | None = None
    traceback: str | None = None
    input_hash: str | None = None
    rows: list[dict[str, Any]] = field(default_factory=list)
    models: dict[str, dict[str, Any]] = field(default_factory=dict)
    seconds: float = 0.0
    worker: str = ""
    peak_rss_mb: float = 0.0


def _peak_rss_mb() -> float:
    """Peak resident set size of this process [MB].

    Linux: ``VmHWM`` of ``/proc/self/status`` (``ru_maxrss`` would include the parent's peak
    for a process started by fork and exec); elsewhere ``ru_maxrss`` (macOS in bytes).
    """
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except (OSError, ValueError, IndexError):
        pass
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / (1024.0 * 1024.0) if sys.platform == "darwin" else peak / 1024.0


def _range(values) -> tuple[float, float]:
    return float(values.min()), float(values.max())


def fit_row(
    spec: JointSpec,
    model: str,
    fitted: FittedModel | None,
    used: FrictionSamples | None,
    error: str | None = None,
) -> dict[str, Any]:
    """One results-table row: a model's parameters, CIs, metrics and operating range.

    Parameters are ``param_<name>``, their standard errors ``stderr_<name>`` and the
    half-widths of their 95 % confidence intervals ``ci95_<name>`` (SI units, listed in
    ``units``); the verdict columns of :func:`verdict_columns`; a failed fit has ``status``
    ``"failed"`` and its ``error``.
    """
    row: dict[str, Any] = {
        "robot": spec.robot,
        "joint": spec.joint,
        "model": model,
        "status": "ok" if fitted is not None else "failed",
        "stage": None if fitted is not None else "fit",
        "error": error,
        "log": spec.log_text,
        "reader": spec.reader,
        "method": spec.method,
        "seed": spec.seed,
    }
    if used is not None:
        speed = abs(used.velocity)
        row["n_samples"] = len(used)
        row["speed_min"], row["speed_max"] = _range(speed)
        row["load_min"], row["load_max"] = _range(used.load)
        row["temperature_min"], row["temperature_max"] = _range(used.temperature)
        row["directions"] = ";".join(str(d) for d in used.directions())
    if fitted is None:
        return row
    for key in ("fitness", "sse", "rmse", "rmspe", "mae", "max_abs_error"):
        row[key] = fitted.metrics.get(key)
    row.update(verdict_columns(fitted, used))
    row["nfev"] = fitted.optimizer.nfev
    row["at_bound"] = ";".join(fitted.at_bound) or None
    row["fixed"] = ";".join(fitted.fixed) or None
    row["units"] = ";".join(f"{k}={u}" for k, u in fitted.units.items())
    records = fitted.parameters.values()
    row.update({f"param_{p.name}": p.value for p in records})
    row.update({f"stderr_{p.name}": None if p.fixed else p.stderr for p in records})
    row.update({f"ci95_{p.name}": None if p.fixed else p.ci95_halfwidth for p in records})
    return row


def verdict_columns(fitted: FittedModel, used: FrictionSamples | None) -> dict[str, Any]:
    """The per-joint verdict columns of a fit (issue 11, "Where it shows").

    From :func:`fricid.report.trust.assess_trust` of the model and the samples it was fitted
    on (no validation is run here): ``trust`` (``yes``, ``with caveats``, ``no``),
    ``converged`` (None when not recorded), ``heldout_ratio`` (held-out RMSE over the
    measurement scatter from the model's validation, else the fit's in-sample
    ``rmse_over_scatter``; ``heldout_source`` says which), ``verdict`` (within noise, or
    misses by a factor), ``n_not_determined`` (free parameters the data do not determine)
    and ``extrapolation_free_range`` (the operating range as text).
    """
    from ..report.trust import assess_trust

    trust = assess_trust(fitted, used, run_validation=False)
    ratio = trust.heldout_ratio
    return {
        "trust": trust.level,
        "converged": trust.converged,
        "heldout_ratio": float(ratio) if np.isfinite(ratio) else None,
        "heldout_source": trust.heldout_source or None,
        "verdict": trust.verdict,
        "n_not_determined": len(trust.not_determined),
        "extrapolation_free_range": trust.range or None,
    }


def failed_outcome(
    spec: JointSpec, stage: str, error: str, tb: str | None = None, **kw: Any
) -> JointOutcome:
    """The outcome of a joint that failed at ``stage``: one failed row per model."""
    rows = [fit_row(spec, m, None, None, error) for m in spec.models]
    for row in rows:
        row["stage"] = stage
    return JointOutcome(spec.robot, spec.joint, "failed", stage, error, tb, rows=rows, **kw)


def _compute(spec: JointSpec, digest: str) -> JointOutcome:
    from ..workflow import run_joint

    run = run_joint(spec.log, **spec.run_kwargs())
    rows, models = [], {}
    for name in spec.models:
        fitted = run.fits.get(name)
        err = run.errors.get(name)
        row = fit_row(spec, name, fitted, run.used.get(name), None if err is None else str(err))
        row["time_extract_s"] = run.extract_seconds
        row["time_fit_s"] = run.fit_seconds.get(name)
        rows.append(row)
        if fitted is not None:
            models[name] = fitted.to_dict()
    failed = [n for n in spec.models if n in run.errors]
    return JointOutcome(
        spec.robot,
        spec.joint,
        "failed" if failed else "ok",
        stage="fit" if failed else None,
        error=f"{failed[0]}: {run.errors[failed[0]]}" if failed else None,
        input_hash=digest,
        rows=rows,
        models=models,
    )


def run_job(job: JointJob) -> JointOutcome:
    """Identify one joint; never raises for bad data (see :class:`JointOutcome`).

    BLAS and OpenMP run single-threaded inside the job, so a joint's numbers do not depend on
    how many threads its process happened to have: results are bit-identical whichever
    executor ran them.
    """
    from threadpoolctl import threadpool_limits

    spec = job.spec
    t0 = time.perf_counter()
    try:
        digest = input_hash(spec.log, spec.reader, spec.reader_options)
    except OSError as exc:
        out = failed_outcome(spec, "read", f"cannot read the log {spec.log}: {exc.strerror or exc}")
    else:
        if job.expect_hash is not None and digest == job.expect_hash:
            out = JointOutcome(spec.robot, spec.joint, "unchanged", input_hash=digest)
        else:
            try:
                with threadpool_limits(limits=1):
                    out = _compute(spec, digest)
            except FricidError as exc:
                out = failed_outcome(spec, "extract", str(exc), input_hash=digest)
            except Exception as exc:  # isolate the joint, but keep the cause and its traceback
                out = failed_outcome(
                    spec,
                    "error",
                    f"unexpected {type(exc).__name__}: {exc}",
                    traceback.format_exc(),
                    input_hash=digest,
                )
    out.seconds = time.perf_counter() - t0
    out.worker = f"{socket.gethostname()}:{os.getpid()}"
    out.peak_rss_mb = _peak_rss_mb()
    return out
