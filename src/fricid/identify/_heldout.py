"""The held-out validation the trust verdict runs itself (:mod:`fricid.identify.trust`) when
the fit brought none: leave-one-velocity-out of an analytic model when folds x samples x
parameters is at most :data:`VALIDATE_WORK`, of a learned model (``rbf`` and ``hybrid`` trained
by least squares, ``gp``; each fold retrained as ``fit`` trains it) when folds x samples is at
most :data:`fricid.identify.learned._trust.LEARNED_VALIDATE_WORK`, with at least
:data:`MIN_LEVELS` velocity levels either way (levels that cannot chain:
:func:`fricid.identify._scatter.speed_levels`).

On tiny data (at most :data:`TINY_SAMPLES` samples) :func:`run_kfold` adds random folds
(``kfold:K``, ``K = min(5, n // 2)``): there, a handful of velocity levels each hold out only
the speed a flexible model interpolates well, and random folds hold out single samples it has
bent to fit; the verdict takes the worse of the two.

The limits are counts, not measured times, so the verdict does not depend on how busy the
machine is; a larger problem is validated by ``fricid fit --validate lovo``.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from ..errors import FricidError
from ..fitted import FittedModel
from ..metrics import rmse, verdict
from ..samples import FrictionSamples, row_digests, samples_hash
from ._scatter import level_labels, measurement_scatter
from .learned._trust import CV_SOURCE, LEARNED_VALIDATE_WORK
from .validate import interior_rmse

__all__ = [
    "LEARNED_VALIDATE_WORK",
    "LOVO_INTERIOR",
    "MIN_LEVELS",
    "NEW_SAMPLES",
    "RANK_RTOL",
    "TINY_SAMPLES",
    "VALIDATE_WORK",
    "end_levels",
    "grade_new_samples",
    "graded_rmse",
    "is_new_samples",
    "is_own_samples",
    "model_error",
    "on_new_clause",
    "other_side_caveat",
    "own_cv",
    "own_directions",
    "own_rows",
    "run_kfold",
    "run_validation",
    "shared_mse",
    "worse_kfold",
]

#: ... the model file's own error on samples other than the set it was identified on (their
#: content hash differs: :func:`grade_new_samples`; they may share rows with it).
NEW_SAMPLES = "the model on other samples than its own"
#: The scheme the verdict names for leave-one-velocity-out graded on its interior folds.
LOVO_INTERIOR = "lovo, interior levels"

#: Largest leave-one-velocity-out validation of an analytic model the verdict runs itself, as
#: folds x samples x parameters (larger problems: ``fricid fit --validate lovo``).
VALIDATE_WORK = 50_000

#: The verdict runs its own leave-one-velocity-out validation only with at least this many
#: velocity levels (with fewer, each held-out level is an extrapolation from a handful).
MIN_LEVELS = 5

#: Samples up to which the verdict also runs random folds (:func:`run_kfold`) and takes the
#: worse ratio.
TINY_SAMPLES = 20


def run_validation(
    fitted: FittedModel, samples: FrictionSamples, max_work: int
) -> tuple[dict[str, Any] | None, str]:
    """Leave-one-velocity-out validation of ``fitted``'s model on ``samples`` when folds x
    samples x parameters is at most ``max_work`` (a learned model: :func:`_run_learned`).

    Returns
    -------
    dict or None
        ``Validation.to_dict()``, None when not run.
    str
        How it was run, or why not.
    """
    fallback = "in-sample only" if fitted.validation is None else "the fit's own CV only"
    folds = int(np.unique(level_labels(samples)).size)
    if folds < MIN_LEVELS:
        return None, (
            f"not run here: {folds} velocity level(s), and holding one out of so few asks "
            f"the model to extrapolate; {fallback}"
        )
    return _run(fitted, samples, "lovo", folds, max_work, fallback)


def run_kfold(
    fitted: FittedModel, samples: FrictionSamples, max_work: int
) -> tuple[dict[str, Any] | None, str]:
    """Random-fold validation (``kfold:K``, ``K = min(5, n // 2)``) of ``fitted``'s model on
    tiny ``samples`` (module notes), as :func:`run_validation` runs leave-one-velocity-out.

    Returns
    -------
    dict or None
        ``Validation.to_dict()``, None when not run (more than :data:`TINY_SAMPLES` samples,
        fewer than four, or a model the verdict does not retrain).
    str
        How it was run, or why not.
    """
    n = len(samples)
    k = min(5, n // 2)
    if n > TINY_SAMPLES or k < 2:
        return None, ""
    return _run(fitted, samples, f"kfold:{k}", k, max_work, "leave-one-velocity-out only")


def _run(
    fitted: FittedModel,
    samples: FrictionSamples,
    scheme: str,
    folds: int,
    max_work: int,
    fallback: str,
) -> tuple[dict[str, Any] | None, str]:
    """``scheme``'s validation of ``fitted``'s model, each fold fitted as ``fit`` fits it."""
    if fitted.kind == "rbf":  # the learned models: each fold retrains, structure search too
        return _run_learned(fitted, samples, folds, fallback, scheme)
    work = folds * len(samples) * max(len(fitted.free), 1)
    if work > max_work:
        return None, (
            f"not run here ({folds} folds x {len(samples)} samples x parameters = {work:,}, "
            f"over the limit of {max_work:,}; use fricid fit --validate lovo); {fallback}"
        )
    fixed = {n: fitted.params[n] for n in fitted.fixed}
    options: dict[str, Any] = {"intervals": "none"}
    if isinstance(fitted.loss.get("loss"), str):
        options["loss"] = fitted.loss["loss"]
    if fitted.loss.get("weights") == "std":  # each training fold weighted as the fit was
        options["weights"] = "std"
    return _validate(
        samples,
        fitted.model,
        scheme,
        "lm",
        f"{folds} folds, each fitted by lm",
        fallback,
        fixed=fixed,
        **options,
    )


def _validate(
    samples: FrictionSamples,
    model: str,
    scheme: str,
    method: str | None,
    how: str,
    fallback: str,
    **options: Any,
) -> tuple[dict[str, Any] | None, str]:
    """:func:`fricid.identify.validate.validate` with ``scheme``, its warnings silenced."""
    from .validate import validate

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            val = validate(samples, model, scheme, method, **options)
    except FricidError as exc:
        return None, f"could not be run here ({exc}); {fallback}"
    return val.to_dict(), f"{scheme} run here: {how}"


def _run_learned(
    fitted: FittedModel, samples: FrictionSamples, folds: int, fallback: str, scheme: str
) -> tuple[dict[str, Any] | None, str]:
    """Leave-one-velocity-out of a learned model (``rbf``, ``hybrid``: trained by least
    squares; ``gp``), each fold retrained as ``fit`` trains it (the structure search, the
    backbone's selection, the GP's hyperparameters), when folds x samples is at most
    :data:`LEARNED_VALIDATE_WORK`."""
    work = folds * len(samples)
    trainer = str((fitted.state or {}).get("trainer") or "")
    residual = (fitted.state or {}).get("residual") or {}
    trainer = trainer or str(residual.get("trainer") or "")
    if fitted.model != "gp" and trainer != "lsq":
        return None, (
            f"not run here for a network trained by '{trainer}' (each fold would rerun its "
            f"optimiser; use fricid fit --validate lovo); {fallback}"
        )
    if work > LEARNED_VALIDATE_WORK:
        return None, (
            f"not run here ({folds} folds x {len(samples)} samples = {work:,}, over the "
            f"limit of {LEARNED_VALIDATE_WORK:,} for a learned model, each fold retrained; "
            f"use fricid fit --validate lovo); {fallback}"
        )
    options: dict[str, Any] = {}
    if fitted.model == "gp":
        params = (fitted.provenance or {}).get("estimator_params") or {}
        options["settings"] = {k: params[k] for k in ("max_points", "n_restarts") if k in params}
    seed = fitted.optimizer.seed if fitted.optimizer.seed is not None else 0
    how = f"{folds} folds, each retrained as fit trains {fitted.model}"
    return _validate(samples, fitted.model, scheme, None, how, fallback, seed=seed, **options)


def own_cv(validation: dict[str, Any] | None) -> bool:
    """The validation is a learned model's record of its own structure search's CV (folds of
    whole interior speed levels, or random folds where there are too few levels; the record's
    scheme says which: :mod:`fricid.identify.learned._trust`)."""
    return bool(validation) and validation.get("source") == CV_SOURCE


def graded_rmse(validation: dict[str, Any]) -> tuple[float, str]:
    """(RMSE, scheme) the verdict grades a validation record by.

    Leave-one-velocity-out over its interior folds (:data:`LOVO_INTERIOR`;
    :func:`fricid.identify.validate.interior_rmse`): holding out the slowest or the fastest
    level asks for an extrapolation that a correct model fails too when the levels are few
    (2x and 4.5x the noise on 6 levels: :mod:`fricid.identify.validate`), so the verdict,
    which is about the measured range, leaves them out; the end folds stay in the record (the
    advice reads them). With fewer than three folds, and for any other scheme, the pooled RMSE.
    """
    scheme = str(validation.get("scheme", ""))
    err = float(validation["rmse"]) if validation.get("rmse") is not None else np.nan
    if scheme == "lovo":
        inner = interior_rmse(validation.get("folds") or [])
        if np.isfinite(inner):
            return inner, LOVO_INTERIOR
    return err, scheme


def end_levels(validation: dict[str, Any] | None, scatter: float) -> str:
    """What a verdict graded on the interior levels (:data:`LOVO_INTERIOR`) leaves out:
    ``" on the 14 interior speed levels; held out, the slowest (0.221 rad/s) is missed by 2.25x
    the scatter and the fastest (20.8 rad/s) by 0.961x: extrapolations, not graded"``; ``""``
    without folds to name."""
    rows = sorted(
        (f for f in (validation or {}).get("folds") or [] if f.get("rmse") is not None),
        key=lambda f: float(f["speed"]),
    )
    if len(rows) < 3 or not (np.isfinite(scatter) and scatter > 0):
        return ""
    (slow, fast), s = (rows[0], rows[-1]), float(scatter)
    return (
        f" on the {len(rows) - 2} interior speed levels; held out, the slowest "
        f"({float(slow['speed']):.3g} rad/s) is missed by {float(slow['rmse']) / s:.3g}x the "
        f"scatter and the fastest ({float(fast['speed']):.3g} rad/s) by "
        f"{float(fast['rmse']) / s:.3g}x: extrapolations, not graded"
    )


def worse_kfold(
    fitted: FittedModel,
    samples: FrictionSamples,
    max_work: int,
    ratio: float,
    scheme: str,
) -> tuple[dict[str, Any] | None, str]:
    """On tiny data, random folds (:func:`run_kfold`) beside the held-out ``ratio`` already
    found (``scheme``; NaN when none): a flexible model can pass the level folds of a handful
    of speeds and still miss single held-out samples by far. For an analytic model, not
    graded when a fold could not be fitted without its samples: the design then determines
    the model with little to spare, and the folds that were fitted predict from as few
    samples, so their errors are the leverage of the noise, not the model's (an arm's
    per-direction Coulomb-viscous law on three speeds a direction,
    ``benchmarks/bench_arm_sweeps.py``: a correct law was judged "no" on 25 of 75 joints, by
    the one fold of three that could be fitted). A learned model's folds still count: it is
    the flexible model they are there to catch.

    Returns
    -------
    dict or None
        The random folds' ``Validation.to_dict()`` when their ratio is the worse (or the only)
        one, else None.
    str
        What they found ("" when not run).
    """
    val, how = run_kfold(fitted, samples, max_work)
    if val is None or val.get("ratio") is None:
        return None, how
    failed = int(val.get("failed") or 0)
    if failed and fitted.kind == "analytic":  # the rest predict from as few: leverage
        return None, (
            f"{len(samples)} samples, so random folds too: {how}, but {failed} of "
            f"{len(val.get('folds') or [])} could not be fitted without their samples (the "
            "design determines the model with little to spare), so they are not graded"
        )
    k_ratio = float(val["ratio"])
    note = f"{len(samples)} samples, so random folds too: {how} ({k_ratio:.3g}x"
    if np.isfinite(ratio) and k_ratio <= ratio:
        return None, f"{note}; {scheme} ({ratio:.3g}x) is the worse and graded)"
    if np.isfinite(ratio):
        return val, f"{note}, worse than {scheme} ({ratio:.3g}x): graded)"
    return val, f"{note})"


#: A fold whose training Jacobian (columns scaled to unit norm) has a singular value below
#: this fraction of its largest is left out of :func:`shared_mse`.
RANK_RTOL = 1e-6


def shared_mse(
    fitted: FittedModel, samples: FrictionSamples | None, validation: dict[str, Any] | None
) -> float:
    """N^2 m^2, the mean squared error an error every sample shares (an arm's identified
    gravity, :mod:`fricid.identify.static.shared_error`) puts into the errors the verdict
    grades; 0 without one. Held out (``validation``): its folds as the validation dealt them
    (``lovo``'s interior ones when it grades those, :func:`graded_rmse`), each fold's
    prediction linearised at the fit, ``e_h = J_h J_t^+ eps_t - eps_h``, averaged over the
    held-out samples of ``trace(B Sigma B^T)`` (a fold whose training samples leave the
    law's Jacobian rank-deficient is left out: its linear reading amplifies without bound);
    in-sample, ``trace((I - H) Sigma (I - H)) / n``. No fit removes this error (a law fitted
    on other samples carries it too, except its offsets), so a correct law's error shows it
    beside the noise (module notes of :mod:`fricid.identify.trust`, "Shared error")."""
    from ..fitted._interval import gradient
    from .static.shared_error import shared_covariance
    from .validate import fold_labels

    if samples is None or fitted.kind == "rbf" or not fitted.free:
        return 0.0
    sigma = shared_covariance(samples)
    n = len(samples)
    if sigma is None or sigma.shape != (n, n):
        return 0.0
    J = gradient(fitted.model, fitted.theta(), fitted.free, samples.X).T  # (n, p)
    if not np.isfinite(J).all():
        return 0.0
    if not validation:
        B = np.eye(n) - J @ np.linalg.pinv(J)
        return float(np.trace(B @ sigma @ B.T)) / n
    scheme = str(validation.get("scheme") or "")
    try:
        labels = fold_labels(samples, scheme, 0)
    except FricidError:
        return 0.0
    folds = np.unique(labels)
    if scheme == "lovo" and graded_rmse(validation)[1] == LOVO_INTERIOR:
        folds = folds[1:-1]  # the labels run slowest first: the end levels are not graded
    norms = np.linalg.norm(J, axis=0)
    J = J / np.where(norms > 0, norms, 1.0)  # each parameter on its own scale
    total, count = 0.0, 0
    for fold in folds:
        held = labels == fold
        sv = np.linalg.svd(J[~held], compute_uv=False)
        if sv.size < J.shape[1] or not sv[-1] > RANK_RTOL * sv[0]:
            continue  # the fold's training leaves the law undetermined: no linear reading
        B = -np.eye(n)[held]
        B[:, ~held] += J[held] @ np.linalg.pinv(J[~held])
        total += float(np.trace(B @ sigma @ B.T))
        count += int(held.sum())
    return total / count if count else 0.0


def own_directions(
    fitted: FittedModel, samples: FrictionSamples | None
) -> tuple[FrictionSamples | None, FrictionSamples | None]:
    """``(samples, None)``, or the rows of the directions the model was identified on when
    those are its own set and the other rows (``fricid fit --direction pos`` on a file of
    both: a report of that file judges the model on its own rows, and says what it makes of
    the others: :func:`other_side_caveat`)."""
    prov = fitted.provenance or {}
    own, dirs = prov.get("samples_sha256_16"), prov.get("directions")
    if samples is None or not isinstance(own, str) or not isinstance(dirs, list):
        return samples, None
    keep = np.isin(samples.direction, np.asarray(dirs, dtype=float))
    if keep.all() or not keep.any():
        return samples, None
    subset = samples.subset(keep)
    if samples_hash(subset) != own:
        return samples, None
    return subset, samples.subset(~keep)


def other_side_caveat(fitted: FittedModel, others: FrictionSamples | None, scatter: float) -> str:
    """What the model makes of the rows of a direction it was not identified on, beside its
    own (:func:`own_directions`): their error over ``scatter``, an extrapolation."""
    if others is None or not len(others):
        return ""
    error = rmse(others.y, fitted.predict(others.X, warn=False))
    told = f"{error / scatter:.3g}x the scatter" if scatter > 0 else f"{error:.3g} N m RMS"
    return (
        f"the samples also hold {len(others)} rows of a direction the model was not identified "
        f"on, which it predicts as its mirror image: they are missed by {told} (an "
        "extrapolation, not graded)"
    )


def own_rows(fitted: FittedModel, samples: FrictionSamples) -> np.ndarray | None:
    """Which rows of ``samples`` are rows the model was identified on (its file's
    ``provenance["rows_sha256_12"]``, whatever their order), or None when it keeps none."""
    digests = (fitted.provenance or {}).get("rows_sha256_12")
    if not isinstance(digests, list):
        return None
    return np.isin(row_digests(samples), np.asarray(digests, dtype=object))


def is_new_samples(
    fitted: FittedModel, samples: FrictionSamples | None, digest: str | None
) -> bool:
    """Whether ``samples`` (content hash ``digest``) are not those the model was identified
    on: the file records the hash of its own (``provenance["samples_sha256_16"]``) and it
    differs, unless every row is one of its own rows in another order (:func:`own_rows`). A
    file without the hash (older, or of a trajectory) counts them as its own."""
    own = (fitted.provenance or {}).get("samples_sha256_16")
    if samples is None or digest is None or not isinstance(own, str) or own == digest:
        return False
    mine = own_rows(fitted, samples)
    return mine is None or not bool(mine.all())


def is_own_samples(fitted: FittedModel, samples: FrictionSamples) -> bool:
    """Whether ``samples`` are those the model file says it was identified on (its content
    hash, or every row one of its own rows in another order): an error on them is in-sample."""
    own = (fitted.provenance or {}).get("samples_sha256_16")
    return isinstance(own, str) and not is_new_samples(fitted, samples, samples_hash(samples))


def grade_new_samples(trust: Any, fitted: FittedModel, samples: FrictionSamples) -> str:
    """Grade the model file's own error on samples it was not identified on
    (:data:`NEW_SAMPLES`): a held-out error of the model itself, where leave-one-velocity-out
    would refit its family on them and grade the family (a worn joint's samples, friction
    x1.3, passed the lead screw's model at 0.53x while the model missed them by 15x). Samples
    outside the model's operating range (an extrapolation: another side, slower, faster, other
    loads or temperatures; a gap between its speeds is not) are left out of the error graded
    while any inside remain. Returns the caveat on them ("" when none)."""
    trust.heldout_source = NEW_SAMPLES
    trust.heldout_scheme = "no refit"
    trust.validation_note = (
        f"these samples (content hash {trust.samples_hash}) are not those the model was "
        f"identified on ({fitted.provenance['samples_sha256_16']}): the model's own error on "
        "them is graded, not a refit of its family"
    )
    mine = own_rows(fitted, samples)
    mine = np.zeros(len(samples), dtype=bool) if mine is None else mine
    out = fitted.outside_range(samples.X) & ~mine
    rest = ~mine & ~out
    judged = samples.subset(rest) if rest.any() else samples.subset(~mine)
    model_error(trust, fitted, judged)
    trust.verdict = verdict(trust.heldout_ratio)
    said = []
    if mine.any():
        said.append(
            f"{int(mine.sum())} of {len(samples)} rows are rows the model was identified on, "
            "left out of the error graded (it is judged on the others)"
        )
    if out.any():
        why = "; ".join(v.message for v in fitted.range_check(samples.X[out]))
        said.append(
            f"every row it is judged on lies outside the range it was identified on: {why}"
            if not rest.any()
            else f"{int(out.sum())} of {len(samples)} rows lie outside the range the model was "
            f"identified on, left out of the error graded: {why}"
        )
    return "; ".join(said)


def model_error(trust: Any, fitted: FittedModel, samples: FrictionSamples) -> bool:
    """Set ``trust``'s scatter method, and its RMSE, scatter and ratio from the model's own
    error on ``samples`` when their scatter is known; whether it was."""
    sc = measurement_scatter(samples)
    trust.scatter_method = sc.method
    if not (np.isfinite(sc.value) and sc.value > 0):
        return False
    trust.heldout_rmse = rmse(samples.y, fitted.predict(samples.X, warn=False))
    trust.scatter = sc.value
    trust.heldout_ratio = trust.heldout_rmse / sc.value
    return True


def on_new_clause(trust: Any) -> str:
    """The clause that says the error graded is the model's on samples it was not identified
    on (:data:`NEW_SAMPLES`), else ``""``."""
    if trust.heldout_source != NEW_SAMPLES:
        return ""
    return " on these samples, not the set it was identified on"
