"""Model selection by held-out error: ``fit(samples, "auto")``.

:func:`candidates` lists the analytic families the data can support, :func:`select` validates
each (:func:`fricid.identify.validate.validate`, leave-one-velocity-level-out by default),
picks one by held-out error, not by training R^2, and refits it on all the samples; the
comparison table and the reason travel with the model (``FittedModel.selection``).

The rules (issue 11, "Validation built in"):

* a family is a candidate when the samples have more distinct velocity levels than the
  model has velocity parameters (per direction for ``*_asym``; the load and temperature
  models count distinct operating points instead, since their extra parameters are
  determined by load and temperature); ``msk`` needs the load to vary, ``vlt`` the load and
  the temperature; ``*_asym`` needs samples of both directions, apart;
* with ``learned=True`` (``fricid fit --model auto --learned``), the learned families
  :data:`LEARNED` (``rbf``, ``hybrid``; issue 15) are candidates too, with at least
  :data:`LEARNED_MIN_LEVELS` velocity levels per direction, at most
  :data:`LEARNED_MAX_SAMPLES` samples (validation retrains them per fold) and the
  least-squares loss without weights (how they train); they count as many parameters as
  samples, so one is chosen only when clearly better than every analytic family;
* the choice is the simplest candidate (fewest parameters, symmetric before ``_asym``) whose
  held-out RMSE is within :data:`PREFER_SIMPLER` (5 %) of the best, or within the noise
  (:data:`fricid.metrics.NOISE_RATIO` times the measurement scatter);
* a candidate whose error on every sample already exceeds (by :data:`PRUNE_MARGIN`) the
  held-out error a choice may have is listed "not validated" instead: its held-out error
  cannot be lower (candidates are validated closest fit first);
* on tiny data (at most :data:`TINY_SAMPLES` samples) the held-out RMSE of each candidate is
  itself noisy, so a simpler candidate is also kept when the best one's advantage is not
  significant: the mean over the samples of the paired difference of squared held-out errors
  (simpler minus best) is at most :data:`TINY_SIGMAS` standard errors of that mean.

``fricid.identify.fit(samples, "auto")`` calls :func:`select`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ...errors import ConfigError
from ...fitted import FittedModel
from ...metrics import NOISE_RATIO, rmse
from ...optim import single_blas_thread
from ...samples import FrictionSamples
from .._named import fit_named
from .._scatter import Scatter, measurement_scatter
from ..validate import scheme_label, validate
from .candidates import FAMILIES, LEARNED, PREFER_SIMPLER, Candidate, candidates

__all__ = [
    "FAMILIES",
    "LEARNED",
    "PREFER_SIMPLER",
    "PRUNE_MARGIN",
    "TINY_SAMPLES",
    "TINY_SIGMAS",
    "Candidate",
    "candidates",
    "select",
]


#: Samples up to which a simpler candidate is kept unless the best is significantly better.
TINY_SAMPLES = 20

#: ... significantly: by more than this many standard errors of the mean paired difference.
TINY_SIGMAS = 2.0


@single_blas_thread
def select(
    samples: FrictionSamples,
    method: str = "lm",
    *,
    scheme: str = "lovo",
    scatter: Scatter | None = None,
    seed: int | np.random.Generator | None = 0,
    learned: bool = False,
    progress: Callable[[int, int, str], Any] | None = None,
    **fit_options: Any,
) -> FittedModel:
    """Fit the candidates, pick by held-out error, refit the choice on all the samples.

    Parameters
    ----------
    samples : FrictionSamples
    method : str, default "lm"
        The optimiser of every fit.
    scheme : str, default "lovo"
        Validation scheme (:func:`fricid.identify.validate.validate`).
    scatter : Scatter, optional
        Default: :func:`~fricid.identify.validate.measurement_scatter` of ``samples``.
    seed : int or numpy.random.Generator, optional
    learned : bool, default False
        Try the learned families too (``rbf``, ``hybrid``; :func:`candidates`). Off by
        default: validating one retrains it, its structure search included, for every fold
        (about 20 times an analytic family's time).
    progress : callable, optional
        ``progress(i, n, label)`` before the ``i``-th (0-based) of the ``n`` candidates is
        fitted (``label`` its name), and ``progress(n, n, label)`` before the chosen
        family is refitted on all the samples.
    **fit_options
        Passed to every fit (``max_evals``, ``loss``, ``weights``, ...).

    Returns
    -------
    FittedModel
        The chosen model fitted on all the samples, with ``selection`` (scheme, chosen,
        reason, table, and ``advice`` when every analytic family misses the data by more
        than :data:`fricid.identify.trust.MISS_RATIO` scatters and the learned families were
        not tried: run again with ``learned=True``) and ``validation`` (the chosen model's).

    Raises
    ------
    ConfigError
        No family can be fitted to the data, or ``fixed``/``bounds``/``x0`` given (they
        name one model's parameters).
    """
    named = [k for k in ("fixed", "bounds", "x0") if fit_options.get(k)]
    if named:
        raise ConfigError(
            f"model 'auto' tries several families: {', '.join(named)} cannot name their "
            "parameters; fit a named model instead"
        )
    for key in ("fixed", "bounds", "x0"):
        fit_options.pop(key, None)  # empty: nothing named
    sc = scatter if scatter is not None else measurement_scatter(samples)
    table: list[dict[str, Any]] = []
    runs = {}
    found = {c.label: c for c in candidates(samples, learned)}
    robust = str(fit_options.get("loss", "l2")).lower() not in ("l2", "sse") or (
        fit_options.get("weights") not in (None, "none", "")
    )
    todo = [c.label for c in found.values() if not c.note]
    plans: dict[str, tuple[Candidate, dict[str, Any], float]] = {}
    for c in found.values():  # every candidate's fit on all the samples, its start
        if progress is not None and not c.note:
            progress(todo.index(c.label), len(todo), c.label)
        row: dict[str, Any] = {"model": c.label, "n_params": c.n_params}
        if c.model in LEARNED and robust and not c.note:
            c = Candidate(c.label, c.model, c.fixed, c.n_params, "trains by least squares only")
        if c.note:
            row.update(heldout_rmse=None, ratio=None, note=c.note)
        else:
            options, train = _screening(samples, c, method, seed, _options(c.model, fit_options))
            plans[c.label] = (c, options, train)
        table.append(row)
    rows = {r["model"]: r for r in table}
    prune = not robust and len(samples) > TINY_SAMPLES
    noise = NOISE_RATIO * sc.value if np.isfinite(sc.value) else 0.0
    best_rmse = np.inf
    order = sorted(plans, key=lambda k: (not np.isfinite(plans[k][2]), np.nan_to_num(plans[k][2])))
    for label in order:  # the closest fit first
        c, options, train = plans[label]
        bar = max(best_rmse * (1.0 + PREFER_SIMPLER), noise)
        if prune and train > PRUNE_MARGIN * bar:
            rows[label].update(
                heldout_rmse=None,
                ratio=None,
                note=(
                    f"not validated: its RMSE on every sample, {train:.3g} N m, already exceeds "
                    f"{PRUNE_MARGIN:g}x the held-out error a choice may have ({bar:.3g} N m), "
                    "and a held-out error is not below it"
                ),
            )
            continue
        v = validate(
            samples,
            c.model,
            scheme,
            _method(c.model, method),
            scatter=sc,
            seed=seed,
            fixed=c.fixed,
            **options,
        )
        runs[label] = v
        ok = np.isfinite(v.rmse) and v.failed == 0
        rows[label].update(
            heldout_rmse=float(v.rmse) if np.isfinite(v.rmse) else None,
            ratio=float(v.ratio) if np.isfinite(v.ratio) else None,
            note=v.verdict if ok else f"{v.failed} folds could not be fitted",
        )
        if ok:
            best_rmse = min(best_rmse, float(v.rmse))
    scored = [r for r in table if r["heldout_rmse"] is not None and runs[r["model"]].failed == 0]
    if not scored:
        raise ConfigError(
            "model 'auto': no candidate family could be validated on these samples: "
            + "; ".join(f"{r['model']}: {r['note']}" for r in table)
        )
    best = min(scored, key=lambda r: r["heldout_rmse"])
    limit = best["heldout_rmse"] * (1.0 + PREFER_SIMPLER)
    ok = [r for r in scored if r["heldout_rmse"] <= max(limit, noise)]
    if len(samples) <= TINY_SAMPLES:
        best_pred = runs[best["model"]].predictions
        ok += [
            r
            for r in scored
            if r not in ok and not _better(best_pred, runs[r["model"]].predictions, samples.y)
        ]
    chosen = min(ok, key=lambda r: (r["n_params"], "_asym" in r["model"]))
    reason = _reason(chosen, best, sc, scheme, noise, len(samples))
    pick = found[chosen["model"]]
    if progress is not None:
        progress(len(todo), len(todo), f"refitting {chosen['model']} on every sample")
    fitted = fit_named(
        samples,
        pick.model,
        _method(pick.model, method),
        seed=seed,
        fixed=pick.fixed or None,
        **_options(pick.model, fit_options),
    )
    fitted.selection = {
        "scheme": scheme,
        "chosen": chosen["model"],
        "reason": reason,
        "table": table,
    }
    advice = _learned_advice(best, table, learned)
    if advice:
        fitted.selection["advice"] = advice
    fitted.validation = runs[chosen["model"]].to_dict()
    return fitted


#: ``lm``'s patience when screening a candidate (:mod:`fricid.optim._least_squares`): a
#: restart that finds nothing better ends it; the chosen family is refitted with the default.
SCREEN_PATIENCE = 1

#: A candidate whose RMSE on every sample exceeds this many times the held-out error a choice
#: may have (within :data:`PREFER_SIMPLER` of the best so far, or within the noise) is not
#: validated: its held-out error cannot be lower than its error on every sample (exact for
#: linear least squares, where each left-out residual is ``(I - H)^-1`` times the in-sample
#: one and ``H``'s eigenvalues lie in ``[0, 1)``); the margin covers the nonlinear families.
#: Candidates are validated closest fit first. Only without weights or a robust loss (where the
#: fit does not minimise the plain squared error) and above :data:`TINY_SAMPLES` samples.
PRUNE_MARGIN = 1.1


def _screening(
    samples: FrictionSamples,
    c: Candidate,
    method: str,
    seed: int | np.random.Generator | None,
    options: dict[str, Any],
) -> tuple[dict[str, Any], float]:
    """The validation options of a candidate and its RMSE on every sample (N m; NaN when not
    known). An analytic candidate fitted by the default ``lm`` without optimiser options is
    fitted once on all the samples (no intervals): every fold starts from that optimum, as a
    fold leaves out a little of the data, and the folds are refitted together
    (:func:`fricid.identify.validate.validate`'s ``start``). Otherwise (a learned family,
    another method, options given) ``options`` as they are."""
    if c.model in LEARNED or str(method).strip().lower() != "lm" or options.get("options"):
        return options, float("nan")
    full = fit_named(
        samples,
        c.model,
        "lm",
        seed=seed,
        fixed=c.fixed or None,
        **{**options, "intervals": "none", "options": {"patience": SCREEN_PATIENCE}},
    )
    start = {n: p.value for n, p in full.parameters.items() if not p.fixed}
    train = rmse(samples.y, full.predict(samples.X, warn=False))
    return {**options, "start": start}, float(train)


def _better(best: np.ndarray, other: np.ndarray, y: np.ndarray) -> bool:
    """The held-out predictions ``best`` beat ``other`` significantly (module notes): the mean
    paired difference of squared errors exceeds :data:`TINY_SIGMAS` standard errors."""
    d = (other - y) ** 2 - (best - y) ** 2
    d = d[np.isfinite(d)]
    if d.size < 2:
        return True
    return bool(d.mean() > TINY_SIGMAS * d.std(ddof=1) / np.sqrt(d.size))


def _reason(
    chosen: dict[str, Any],
    best: dict[str, Any],
    sc: Scatter,
    scheme: str,
    noise: float,
    n_samples: int,
) -> str:
    """Why ``chosen`` won, in one sentence; a ratio it prints is the held-out RMSE it prints
    over the scatter it prints (the noise bar, :data:`fricid.metrics.NOISE_RATIO` times the
    scatter, is named as such)."""
    name, err = chosen["model"], chosen["heldout_rmse"]
    label = scheme_label(scheme)
    head = f"{name} ({chosen['n_params']} parameters): held-out RMSE ({label}) {err:.3g} N m"
    if chosen is best:
        return f"{head}, the lowest of the candidates"
    if err <= best["heldout_rmse"] * (1.0 + PREFER_SIMPLER):
        why = f"within {PREFER_SIMPLER:.0%} of the best"
    elif err <= noise:
        why = (
            f"within the noise ({err / sc.value:.2f}x the scatter {sc.value:.3g} N m; within "
            f"noise is up to {NOISE_RATIO:g}x)"
        )
    else:
        why = (
            f"on {n_samples} samples not significantly worse (by {TINY_SIGMAS:g} standard "
            "errors of the paired squared held-out errors) than the best"
        )
    return f"{head}, {why} ({best['model']}, {best['heldout_rmse']:.3g} N m), and simpler"


def _learned_advice(best: dict[str, Any], table: list[dict[str, Any]], learned: bool) -> str:
    """What to try when no analytic family follows the data: the learned families, when
    the best held-out error misses by more than the trust verdict's threshold and they were
    not among the candidates; ``""`` otherwise."""
    from ..trust import MISS_RATIO

    ratio = best.get("ratio")
    if learned or ratio is None or not ratio > MISS_RATIO:
        return ""
    if any(r["model"] in LEARNED for r in table):
        return ""
    return (
        f"no analytic family follows these data (the best, {best['model']}, misses by "
        f"{ratio:.3g}x the scatter held out): try the learned families too "
        "(fricid fit SAMPLES --model auto --learned, or --model hybrid)"
    )


def _method(model: str, method: str) -> str | None:
    """The analytic candidates' optimiser; a learned candidate trains with its own default."""
    return None if model in LEARNED else method


def _options(model: str, fit_options: dict[str, Any]) -> dict[str, Any]:
    """What a candidate's fit takes: a learned one neither optimiser options nor intervals."""
    if model not in LEARNED:
        return fit_options
    return {k: v for k, v in fit_options.items() if k not in ("options", "intervals", "f_scale")}
