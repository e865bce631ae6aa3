"""The work of one joint, as a worker runs it: hash the log, then
:func:`fricid.workflow.run_joint`; or of one whole robot (a manifest row with a URDF):
:func:`fricid.workflow.run_robot`, a results row per joint (:func:`arm_rows`) and the
whole-arm fit file.

:func:`run_job` never raises for a bad joint: an unreadable log, a failed extraction or a
failed fit comes back as a :class:`JointOutcome` with the stage and the error (and, for an
error that is not fricid's own, its traceback), so one joint cannot stop the fleet. The worker
only computes; the driver writes every file. The warnings a joint raises travel with its
outcome too (:func:`shown_warning`): the driver shows them as its own, one line each, and
keeps them in the joint's record, instead of the worker printing them in Python's raw format.
"""

from __future__ import annotations

import importlib
import os
import resource
import socket
import sys
import time
import traceback
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import FricidError
from ..fitted import FittedModel, Parameter
from ..fitted.arm import ArmFit
from ..identify.trust import Trust
from ..metrics import verdict
from ..samples import FrictionSamples
from .hashing import input_hash
from .manifest import JointSpec

__all__ = [
    "JointJob",
    "JointOutcome",
    "arm_rows",
    "failed_outcome",
    "fit_row",
    "run_job",
    "show_warnings",
    "verdict_columns",
    "warning_lines",
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
    warnings : the warnings the joint raised, as ``{"category": "module:Name", "message",
        "filename", "lineno"}`` (see :func:`show_warnings`).
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
    warnings: list[dict[str, Any]] = field(default_factory=list)


def _warning_dict(w: warnings.WarningMessage) -> dict[str, Any]:
    category = w.category
    return {
        "category": f"{category.__module__}:{category.__qualname__}",
        "message": " ".join(str(w.message).split()),
        "filename": str(w.filename),
        "lineno": int(w.lineno or 0),
    }


def _category(path: str) -> type[Warning]:
    """The warning class ``module:Name`` (a worker's warning), UserWarning if unknown."""
    module_name, _, name = str(path).partition(":")
    try:
        found: Any = sys.modules.get(module_name) or importlib.import_module(module_name)
        for part in name.split("."):
            found = getattr(found, part)
    except Exception:  # an unknown module or class: shown as a UserWarning
        return UserWarning
    return found if isinstance(found, type) and issubclass(found, Warning) else UserWarning


def warning_lines(outcome: JointOutcome) -> list[str]:
    """The warnings a joint raised, as text (``Category: message``), for its record."""
    return [
        f"{_category(w.get('category', '')).__name__}: {w.get('message', '')}"
        for w in outcome.warnings
    ]


def show_warnings(outcome: JointOutcome) -> None:
    """Raise again, in this process, the warnings a joint raised in its worker.

    Each is raised with its category, its message prefixed by the joint (``robot/joint:
    ...``) and the place the worker raised it, so the warning filters and display of this
    process apply: the CLI shows each as one line, as its other warnings.
    """
    for w in outcome.warnings:
        warnings.warn_explicit(
            f"{outcome.robot}/{outcome.joint}: {w.get('message', '')}",
            _category(w.get("category", "")),
            str(w.get("filename", "")),
            int(w.get("lineno", 0) or 0),
        )


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
    trust: Trust | None = None,
) -> dict[str, Any]:
    """One results-table row: a model's parameters, CIs, metrics and operating range.

    Parameters are ``param_<name>``, their standard errors ``stderr_<name>``, the ends of
    their 95 % intervals ``ci95_low_<name>``, ``ci95_high_<name>`` and the half-widths
    ``ci95_<name>`` (SI units, listed in ``units``; empty where an end is open); the verdict
    columns of :func:`verdict_columns` of ``trust`` (the fit's trust
    record, default the one the model carries); a failed fit has ``status`` ``"failed"`` and
    its ``error``. ``chosen`` is the model fitted: the family selected where ``model`` is
    ``"auto"``.
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
    row["chosen"] = fitted.model  # the family "auto" selected; else the model itself
    for key in ("fitness", "sse", "rmse", "rmspe", "mae", "max_abs_error"):
        row[key] = fitted.metrics.get(key)
    if trust is None and fitted.trust is not None:
        trust = Trust.from_dict(fitted.trust)
    if trust is not None:
        row.update(verdict_columns(trust))
    row["nfev"] = fitted.optimizer.nfev
    row["at_bound"] = ";".join(fitted.at_bound) or None
    row["fixed"] = ";".join(fitted.fixed) or None
    row["units"] = ";".join(f"{k}={u}" for k, u in fitted.units.items())
    records = fitted.parameters.values()
    row.update({f"param_{p.name}": p.value for p in records})
    row.update({f"stderr_{p.name}": None if p.fixed else p.stderr for p in records})
    for p in records:
        row.update(_interval_columns(p))
    return row


def _interval_columns(p: Parameter) -> dict[str, float | None]:
    """A parameter's 95 % interval as the model file records it: its ends and half-width (NaN
    where it has none), each empty for a fixed parameter or where an end is open (the search
    bound closes it: the data do not bound the parameter there)."""
    if p.fixed:
        return {f"ci95_low_{p.name}": None, f"ci95_high_{p.name}": None, f"ci95_{p.name}": None}
    return {
        f"ci95_low_{p.name}": None if p.low_open else float(p.ci95[0]),
        f"ci95_high_{p.name}": None if p.high_open else float(p.ci95[1]),
        f"ci95_{p.name}": None if p.low_open or p.high_open else float(p.ci95_halfwidth),
    }


def verdict_columns(trust: Trust) -> dict[str, Any]:
    """The per-joint verdict columns of a fit (issue 11, "Where it shows"), read from its
    trust record (:func:`fricid.identify.trust.assess_trust`, computed once by
    :func:`fricid.workflow.fit_samples`, as ``fricid fit`` computes it; nothing is computed
    here): ``trust`` (``yes``, ``with caveats``, ``no``), ``converged`` (None when not
    recorded), ``heldout_ratio`` (RMSE over the measurement scatter), ``heldout_source``
    (where it came from: ``lovo run here``, ``the fit's --validate``, ``the learned model's
    own CV``, or ``in-sample only``) and ``heldout_scheme`` (``lovo``, ``kfold:K``, ...;
    empty in-sample), ``verdict`` (within noise, or misses by a factor),
    ``n_not_determined`` (free parameters the data do not determine), ``not_bounded`` (those
    an end of the search range bounds instead) and ``extrapolation_free_range`` (the
    operating range as text).
    """
    ratio = trust.heldout_ratio
    return {
        "trust": trust.level,
        "converged": trust.converged,
        "heldout_ratio": float(ratio) if np.isfinite(ratio) else None,
        "heldout_source": trust.heldout_source or None,
        "heldout_scheme": trust.heldout_scheme or None,
        "verdict": trust.verdict,
        "n_not_determined": len(trust.not_determined),
        "not_bounded": ";".join(trust.open_sides) or None,
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


def _finite(value: Any) -> float | None:
    return None if value is None or not np.isfinite(value) else float(value)


def _arm_row(spec: JointSpec, fit: ArmFit, joint: str) -> dict[str, Any]:
    """One joint of a whole-arm fit as a results row (its record, nothing recomputed)."""
    entry = fit.friction[joint]
    check = fit.validation.get(joint, {})
    ratio = _finite(check.get("ratio"))
    params = [fit.parameter(joint, name) for name in entry["parameters"]]
    lo, hi = entry.get("velocity_range", (None, None))
    row: dict[str, Any] = {
        "robot": spec.robot,
        "joint": joint,
        "model": "arm",
        "chosen": entry["family"],
        "status": "ok",
        "stage": None,
        "error": None,
        "log": spec.log_text,
        "reader": spec.reader,
        "method": fit.provenance.get("estimator"),
        "trust": fit.verdict(joint),
        "heldout_ratio": ratio,
        "heldout_source": check.get("source"),
        "heldout_scheme": "whole-arm",
        "verdict": verdict(np.nan if ratio is None else ratio),
        "n_not_determined": sum(p.not_determined for p in params),
        "extrapolation_free_range": (
            None if lo is None else f"velocity {float(lo):.4g} to {float(hi):.4g} rad/s"
        ),
        "reasons": "; ".join(map(str, check.get("reasons", []))) or None,
        "n_samples": fit.provenance.get("samples"),
        "rmse": _finite(check.get("rmse")),
        "units": ";".join(f"{p.name}={p.unit}" for p in params),
    }
    row.update({f"param_{p.name}": _finite(p.value) for p in params})
    row.update({f"stderr_{p.name}": _finite(p.stderr) for p in params})
    for p in params:
        row.update(_interval_columns(p))
    return row


def arm_rows(spec: JointSpec, fit: ArmFit) -> list[dict[str, Any]]:
    """A whole robot's results rows, one per joint: robot, joint, ``model`` ``arm`` and the
    joint's friction family (``chosen``), its parameters with standard errors and 95 %
    half-widths, the held-out error over the noise, the verdict and its reasons, as the
    identification recorded them (:class:`~fricid.fitted.arm.ArmFit`)."""
    return [_arm_row(spec, fit, joint) for joint in fit.joints]


def _compute_robot(spec: JointSpec, digest: str) -> JointOutcome:
    from ..workflow import run_robot

    t0 = time.perf_counter()
    assert spec.urdf is not None  # a robot row
    fit = run_robot(spec.log, spec.urdf, **spec.robot_kwargs())
    seconds = time.perf_counter() - t0
    rows = [{**row, "time_fit_s": seconds} for row in arm_rows(spec, fit)]
    return JointOutcome(
        spec.robot,
        spec.joint,
        "ok",
        input_hash=digest,
        rows=rows,
        models={"arm": fit.to_dict()},
    )


def _compute(spec: JointSpec, digest: str) -> JointOutcome:
    from ..workflow import run_joint

    if spec.is_robot:
        return _compute_robot(spec, digest)

    run = run_joint(spec.log, **spec.run_kwargs())
    rows, models = [], {}
    for name in spec.models:
        fitted = run.fits.get(name)
        err = run.errors.get(name)
        row = fit_row(
            spec,
            name,
            fitted,
            run.used.get(name),
            None if err is None else str(err),
            run.trust.get(name),
        )
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
    executor ran them. The warnings the joint raises are caught and returned in the outcome
    (:func:`show_warnings`).
    """
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        out = _run(job)
    out.warnings = [_warning_dict(w) for w in caught]
    out.seconds = time.perf_counter() - t0
    out.worker = f"{socket.gethostname()}:{os.getpid()}"
    out.peak_rss_mb = _peak_rss_mb()
    return out


def _read_error(spec: JointSpec, exc: OSError) -> str:
    text = f"cannot read the log {spec.log}: {exc.strerror or exc}"
    if exc.filename is not None and str(exc.filename) != str(spec.log):
        text += f" ({exc.filename})"
    return text


def _run(job: JointJob) -> JointOutcome:
    from threadpoolctl import threadpool_limits

    spec = job.spec
    try:
        digest = input_hash(spec.log, spec.reader, spec.reader_options)
    except OSError as exc:
        out = failed_outcome(spec, "read", _read_error(spec, exc))
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
    return out
