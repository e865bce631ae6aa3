"""What a learned model's file records about its trust (issue 15): convergence, the effective
number of parameters behind its fit statistics, and the held-out error of its chosen settings.

The learned families (``rbf``, ``hybrid``, ``gp``) are not least-squares fits of named
parameters, so the analytic path's records (:func:`fricid.identify.static.convergence.certify`, the
parameter count of :func:`fricid.metrics.fit_statistics`) do not apply as they are:

- **Convergence.** The ``lsq`` trainer solves the output layer by ridge least squares in
  closed form (centres by k-means and widths by a rule that do not see the targets): exact by
  construction, ``certified_by="closed_form"``. The optimiser trainers (BAS, GA, ...) stop on
  a target MSE or on their budget: converged when the target was met
  (``certified_by="target"``), not converged when the budget ran out first, as the analytic
  path records a budget stop that a polish improves. The Gaussian process: the marginal
  likelihood optimiser's own status (scikit-learn's L-BFGS-B warnings).
- **Effective degrees of freedom.** A ridge-penalised network has far fewer degrees of
  freedom than numbers (the demo's hybrid stores 418 numbers for 330 samples). The right
  count is the trace of the hat matrix, ``df = tr H = sum_j d_j^2 / (d_j^2 + n alpha)`` over
  the singular values ``d_j`` of the (centred) design (Hastie, Tibshirani & Friedman, *The
  Elements of Statistical Learning*, 2nd ed., eq. 3.50; plus one for an unpenalised bias),
  and the GP's is the trace of its posterior-mean smoother at the fitted hyperparameters
  (Rasmussen & Williams 2006, section 2.6). :func:`learned_statistics` puts it in place of
  ``nvarys`` (``nvarys_effective``, ``nfree_effective``, AIC, BIC, reduced chi-square from it,
  ESL eq. 7.29-7.30 with ``d`` the effective count); where it is undefined (an optimiser
  searched the centres and widths with the targets), no AIC, BIC or reduced chi-square is
  given, and ``statistics_note`` says which.
- **Held-out error.** The ``lsq`` structure search's cross-validation already has the
  out-of-fold error of the chosen settings: :func:`cv_validation` records it in the
  ``validation`` schema of :func:`fricid.identify.validate.validate` against the measurement
  scatter, with ``note`` saying what it tests. Its folds hold out whole interior speed levels
  (scheme ``levels:K``, :func:`fricid.identify.learned._rbf_folds.level_folds`), so it tests
  prediction between the measured speeds, not beyond them; with too few levels they are
  dealt at random (scheme ``kfold:K``), and it tests the measured set-points only. Either
  way the settings were chosen by it (optimistic). The trust verdict uses
  leave-one-velocity-out instead, the analytic path's test, when it is affordable
  (:data:`LEARNED_VALIDATE_WORK`; :mod:`fricid.identify.trust`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ...metrics import fitness, verdict
from ...samples import FrictionSamples
from .._scatter import measurement_scatter

__all__ = [
    "CV_SOURCE",
    "LEARNED_VALIDATE_WORK",
    "cv_pieces",
    "cv_validation",
    "hat_trace",
    "hybrid_records",
    "learned_statistics",
    "network_budget",
    "network_convergence",
    "process_convergence",
    "side_states",
]

#: ``validation["source"]`` of a learned model's record of its own structure search's
#: cross-validation (the trust verdict runs leave-one-velocity-out in its place when it can).
CV_SOURCE = "structure_search"

#: Largest leave-one-velocity-out validation of a learned model the trust verdict runs itself, as
#: folds x samples: each fold retrains the model with its structure search (a count, not a
#: measured time, so the verdict does not depend on how busy the machine is). The demo's
#: samples (``fricid demo``), 6 x 330 = 1,980: ``validate(samples, m, "lovo")`` took 1.1 s
#: (rbf), 8.0 s (hybrid) and 10.1 s (gp) on 2 cores shared with other jobs, 2026-11-22.
LEARNED_VALIDATE_WORK = 2_500


def hat_trace(est: Any, X: np.ndarray) -> float | None:
    """Effective degrees of freedom of an ``lsq`` network: the trace of its hat matrix.

    Parameters
    ----------
    est : RBFNetRegressor
        Fitted with ``trainer="lsq"`` on ``X``.
    X : ndarray, shape (n, d)
        Its training inputs.

    Returns
    -------
    float or None
        ``sum_j d_j^2 / (d_j^2 + n alpha)`` over the singular values of the design (Gaussian
        columns, and the linear tail's standardised columns; centred when a bias is fitted,
        which adds 1), ESL eq. 3.50; with ``alpha = 0`` the rank of the design. None for an
        optimiser trainer (the centres and widths were searched with the targets, so the
        fit is not a linear smoother).
    """
    from ...models import _rbf_core as core
    from ._rbf_estimator import _linear_columns

    if str(est.trainer).strip().lower() != "lsq":
        return None
    A = core.design(est._standardise(X), est.centers_, est.widths_)
    if est.linear_tail:
        A = np.hstack([A, _linear_columns(X, tuple(est.linear_magnitude), int(est.tail_order))[0]])
    bias = bool(est.fit_bias) or bool(est.linear_tail)
    if bias:
        A = A - A.mean(axis=0)
    n = A.shape[0]
    d = np.linalg.svd(A, compute_uv=False)
    alpha = float(est.alpha)
    if alpha > 0:
        df = float(np.sum(d * d / (d * d + n * alpha)))
    else:
        df = float(np.sum(d > np.finfo(float).eps * max(A.shape) * (d[0] if d.size else 0.0)))
    return df + float(bias)


def learned_statistics(
    y: np.ndarray, y_hat: np.ndarray, edf: float | None, how: str
) -> tuple[dict[str, float], str]:
    """Fit statistics of a learned model with its effective degrees of freedom.

    Parameters
    ----------
    y, y_hat : ndarray (n,)
        Measured and fitted friction [N m].
    edf : float or None
        The effective number of parameters (module notes); None where it is undefined.
    how : str
        How ``edf`` was counted, or why it is undefined (for ``statistics_note``).

    Returns
    -------
    dict
        ``ndata``, ``chisqr``, ``rsquared`` and, with ``edf``: ``nvarys_effective``,
        ``nfree_effective`` (``ndata - edf``), ``redchi`` (``chisqr / nfree_effective``),
        ``aic`` and ``bic`` (:func:`fricid.metrics.fit_statistics`'s definitions, ``edf`` in
        place of ``nvarys``; ESL eq. 7.29-7.30). No ``nvarys`` or ``nfree``: the numbers a
        network stores are not its degrees of freedom.
    str
        The ``statistics_note`` of the model file.
    """
    y = np.asarray(y, dtype=float)
    r = y - np.asarray(y_hat, dtype=float)
    n = int(y.size)
    chisqr = float(r @ r)
    out: dict[str, float] = {"ndata": float(n), "chisqr": chisqr, "rsquared": fitness(y, y_hat)}
    if edf is None or not np.isfinite(edf) or n == 0:
        return out, f"no AIC, BIC or reduced chi-square: {how}"
    neg2loglik = n * np.log(max(chisqr, np.finfo(float).tiny) / n)
    nfree = n - float(edf)
    out.update(
        nvarys_effective=float(edf),
        nfree_effective=nfree,
        redchi=chisqr / nfree if nfree > 0 else float("nan"),
        aic=float(neg2loglik + 2 * edf),
        bic=float(neg2loglik + np.log(n) * edf),
    )
    return out, f"effective degrees of freedom {edf:.4g}: {how}"


def network_budget(ests: Sequence[Any]) -> int:
    """The evaluation budget of trained networks: their epochs times evaluations per epoch,
    0 for the closed-form ``lsq`` trainer (no budget applies)."""
    if str(ests[0].trainer).strip().lower() == "lsq":
        return 0
    return int(sum(int(e.max_epochs) * int(e.evals_per_epoch) for e in ests))


def network_convergence(ests: Sequence[Any]) -> dict[str, Any]:
    """The convergence block of trained networks (one, or one per direction).

    ``lsq``: converged, certified by its closed form. An optimiser trainer: converged when
    every network met its target MSE (``epochs_to_target_`` set), else not converged, with the
    reason (budget spent at which MSE) and advice.
    """
    trainer = str(ests[0].trainer).strip().lower()
    block: dict[str, Any] = {"converged": True, "polish_sse_ratio": None, "polish_nfev": 0}
    if trainer == "lsq":
        block.update(certified_by="closed_form")
        return block
    missed = [e for e in ests if e.epochs_to_target_ is None]
    if not missed:
        block.update(certified_by="target")
        return block
    e = missed[0]
    target = "no target MSE set" if e.target_mse is None else f"target {e.target_mse:g}"
    block.update(
        converged=False,
        certified_by="",
        reason=(
            f"trainer '{trainer}' spent its budget of {int(e.max_epochs)} epochs at training "
            f"MSE {float(e.train_mse_):.3g} (target-scaled), {target} not met"
        ),
        advice=(
            "raise --max-evals, or train by least squares (--method lsq, exact in closed form)"
        ),
    )
    return block


def process_convergence(runs: Sequence[dict[str, Any]], notes: Sequence[str]) -> dict:
    """The convergence block of a Gaussian process (one, or one per direction).

    Parameters
    ----------
    runs : sequence of dict
        Per process, ``state["optimizer"]``: the marginal-likelihood optimiser's (L-BFGS-B)
        ``starts``, ``nfev``, and ``converged`` and ``message`` of the start that was kept.
    notes : sequence of str
        scikit-learn's warnings (``state["training_notes"]``): a hyperparameter at a bound of
        its box is a note (``bound_notes``), not a failure.

    Returns
    -------
    dict
        Converged when the kept start of every process converged (``certified_by``
        ``"optimizer"``), else the reason and advice.
    """
    failed = [r for r in runs if not r.get("converged")]
    block: dict[str, Any] = {
        "converged": not failed,
        "polish_sse_ratio": None,
        "polish_nfev": 0,
        "certified_by": "optimizer" if not failed else "",
    }
    if notes:
        block["bound_notes"] = list(notes)
    if failed:
        block["reason"] = (
            "the marginal-likelihood optimiser (L-BFGS-B) stopped without converging: "
            f"{failed[0].get('message', '')}"
        )
        block["advice"] = (
            "raise n_restarts (fricid.identify.fit(samples, 'gp', options={'n_restarts': "
            "...})), or check the data"
        )
    return block


def cv_validation(samples: FrictionSamples, pieces: Sequence[tuple[float, int, int]]) -> dict:
    """The ``validation`` record of a learned model's structure-search cross-validation.

    Parameters
    ----------
    samples : FrictionSamples
        The training samples (their measurement scatter is the yardstick).
    pieces : sequence of (rmse, n, folds, kind)
        Per trained network (:func:`cv_pieces`): the chosen settings' out-of-fold RMSE [N m],
        its held-out samples, folds and their kind (``"velocity_levels"`` or ``"random"``);
        two networks per direction are pooled by their sizes.

    Returns
    -------
    dict
        :meth:`fricid.identify.validate.Validation.to_dict`'s keys (``scheme`` ``levels:K``
        or ``kfold:K``,
        ``rmse``, ``scatter``, ``ratio``, ``verdict``, no ``folds``), with ``source``
        (:data:`CV_SOURCE`) and ``note`` (what it tests; module notes).
    """
    sc = measurement_scatter(samples)
    n = sum(p[1] for p in pieces)
    err = float(np.sqrt(sum(p[0] ** 2 * p[1] for p in pieces) / n)) if n else float("nan")
    ratio = err / sc.value if np.isfinite(sc.value) and sc.value > 0 else float("nan")
    k = min(p[2] for p in pieces)
    levels = all(p[3] == "velocity_levels" for p in pieces)
    if levels:
        tests = (
            f"out-of-fold error of the settings the {k}-fold cross-validation chose (whole "
            "interior speed levels held out, the slowest and fastest always in training: it "
            "tests prediction between the measured speeds, not beyond them; and slightly "
            "optimistic, being the best of the candidates)"
        )
    else:
        tests = (
            f"out-of-fold error of the settings the {k}-fold cross-validation chose (random "
            "folds: every velocity level stays in training, so it tests prediction at the "
            "measured set-points only, not between or beyond them; and slightly optimistic, "
            "being the best of the candidates)"
        )

    def finite(x: float) -> float | None:
        return float(x) if np.isfinite(x) else None

    return {
        "scheme": f"{'levels' if levels else 'kfold'}:{k}",
        "rmse": finite(err),
        "scatter": finite(sc.value),
        "scatter_method": sc.method,
        "scatter_caveat": sc.caveat,
        "ratio": finite(ratio),
        "verdict": verdict(ratio),
        "failed": 0,
        "not_converged": 0,
        "folds": [],
        "source": CV_SOURCE,
        "note": f"{tests}. The trust verdict runs leave-one-velocity-out when it is quick, or "
        "fricid fit --validate lovo",
    }


def side_states(state: dict[str, Any]) -> list[dict[str, Any]]:
    """The network(s) of a state: ``pos`` and ``neg`` of a per-direction state, else itself."""
    return [state["pos"], state["neg"]] if "pos" in state else [state]


def cv_pieces(state: dict[str, Any]) -> list[tuple[float, int, int, str]]:
    """Per network of ``state``: (out-of-fold RMSE [N m] of the chosen settings, held-out
    samples, folds, their kind) of its structure search, the level folds' where it had them
    (the test between measured speeds), else the random folds'; empty when any network has
    none. Files written before level folds have neither: random folds, every sample held out
    once."""
    pieces = []
    for side in side_states(state):
        sel = side.get("n_centers_selection") or {}
        if sel.get("cv_rmse_chosen") is None or not sel.get("n_samples"):
            return []
        if sel.get("cv_rmse_levels_chosen") is not None:  # level folds: the between-speeds test
            rmse, n = float(sel["cv_rmse_levels_chosen"]), int(sel["n_held"])
            pieces.append((rmse, n, int(sel["level_folds"]), "velocity_levels"))
        else:
            pieces.append(
                (float(sel["cv_rmse_chosen"]), int(sel["n_samples"]), int(sel["folds"]), "random")
            )
    return pieces


def hybrid_records(
    samples: FrictionSamples, base: Any, res: Any, y_hat: np.ndarray
) -> dict[str, Any]:
    """The trust fields of a hybrid model's :class:`~fricid.fitted.FittedModel`.

    Parameters
    ----------
    samples : FrictionSamples
        The training samples.
    base, res : FittedModel
        The backbone's fit (:func:`fricid.identify.static.least_squares.fit`) and the residual
        network's
        (:func:`fricid.identify.learned.rbf.fit_rbf`).
    y_hat : ndarray (n,)
        The hybrid's fitted friction.

    Returns
    -------
    dict
        ``metrics`` (with the scatter), ``statistics`` and ``statistics_note`` (the
        backbone's free parameters plus the residual network's effective degrees of freedom:
        an upper bound of the hybrid's linearised trace, since the residual smoother and the
        backbone's projection overlap), ``convergence`` (both parts: converged when both
        are; the backbone's block under ``backbone``), ``validation`` (the residual
        network's cross-validation, the backbone held, :func:`cv_validation`) and ``loss``.
    """
    from ...metrics import metrics

    sc = measurement_scatter(samples)
    p = len(base.free)
    edf_res = (res.statistics or {}).get("nvarys_effective")
    if edf_res is not None:
        edf: float | None = p + float(edf_res)
        how = (
            f"the backbone's {p} free parameters plus the residual network's {res.statistics_note}"
            " (an upper bound: the two overlap)"
        )
    else:
        edf, how = None, f"the residual network's are undefined ({res.statistics_note})"
    statistics, note = learned_statistics(samples.y, y_hat, edf, how)
    bconv = dict(base.convergence or {})
    rconv = dict(res.convergence or {})
    conv = {**rconv, "backbone": bconv}
    conv["converged"] = bool(bconv.get("converged")) and bool(rconv.get("converged"))
    if not bconv.get("converged"):
        conv.update(
            certified_by="",
            reason=f"the backbone {base.model} did not converge: {bconv.get('reason', '')}",
            advice=str(bconv.get("advice", "")),
        )
    pieces = cv_pieces(res.state or {})
    validation = None
    if pieces and res.validation is not None:
        validation = cv_validation(samples, pieces)
        validation["note"] += "; the backbone, fitted on every sample, held in every fold"
    return {
        "metrics": metrics(samples.y, y_hat, samples.direction, sc.value),
        "statistics": statistics,
        "statistics_note": note,
        "convergence": conv,
        "validation": validation,
        "loss": {"scatter": sc.to_dict()},
    }
