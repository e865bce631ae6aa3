"""The held-out validation the trust verdict runs itself (:mod:`fricid.identify.trust`) when
the fit brought none: leave-one-velocity-out of an analytic model when folds x samples x
parameters is at most :data:`VALIDATE_WORK`, of a learned model (``rbf`` and ``hybrid`` trained
by least squares, ``gp``; each fold retrained as ``fit`` trains it) when folds x samples is at
most :data:`fricid.identify.learned._trust.LEARNED_VALIDATE_WORK`, with at least
:data:`MIN_LEVELS` velocity levels either way.

The limits are counts, not measured times, so the verdict does not depend on how busy the
machine is; a larger problem is validated by ``fricid fit --validate lovo``.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from ..errors import FricidError
from ..fitted import FittedModel
from ..samples import FrictionSamples
from ._scatter import level_labels
from .learned._trust import CV_SOURCE, LEARNED_VALIDATE_WORK

__all__ = ["LEARNED_VALIDATE_WORK", "MIN_LEVELS", "VALIDATE_WORK", "own_cv", "run_validation"]

#: Largest leave-one-velocity-out validation of an analytic model the verdict runs itself, as
#: folds x samples x parameters (larger problems: ``fricid fit --validate lovo``).
VALIDATE_WORK = 50_000

#: The verdict runs its own leave-one-velocity-out validation only with at least this many
#: velocity levels (with fewer, each held-out level is an extrapolation from a handful).
MIN_LEVELS = 5


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
    if fitted.kind == "rbf":  # the learned models: each fold retrains, structure search too
        return _run_learned(fitted, samples, folds, fallback)
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
    return _lovo(
        samples,
        fitted.model,
        "lm",
        f"{folds} folds, each fitted by lm",
        fallback,
        fixed=fixed,
        **options,
    )


def _lovo(
    samples: FrictionSamples,
    model: str,
    method: str | None,
    how: str,
    fallback: str,
    **options: Any,
) -> tuple[dict[str, Any] | None, str]:
    """:func:`fricid.identify.validate.validate` with ``lovo``, its warnings silenced."""
    from .validate import validate

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            val = validate(samples, model, "lovo", method, **options)
    except FricidError as exc:
        return None, f"could not be run here ({exc}); {fallback}"
    return val.to_dict(), f"lovo run here: {how}"


def _run_learned(
    fitted: FittedModel, samples: FrictionSamples, folds: int, fallback: str
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
    return _lovo(samples, fitted.model, None, how, fallback, seed=seed, **options)


def own_cv(validation: dict[str, Any] | None) -> bool:
    """The validation is a learned model's record of its own structure search's CV (folds of
    whole interior speed levels, or random folds where there are too few levels; the record's
    scheme says which: :mod:`fricid.identify.learned._trust`)."""
    return bool(validation) and validation.get("source") == CV_SOURCE
