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
  (:data:`fricid.metrics.NOISE_RATIO` times the measurement scatter).

:func:`fit` is :func:`fricid.identify._fit.fit` with ``model="auto"`` routed here (it is
``fricid.identify.fit``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..fitted import FittedModel
from ..metrics import NOISE_RATIO
from ..models import get_model
from ..samples import FrictionSamples
from . import _fit
from ._scatter import Scatter, level_labels, measurement_scatter
from .validate import validate

__all__ = [
    "FAMILIES",
    "LEARNED",
    "PREFER_SIMPLER",
    "Candidate",
    "candidates",
    "fit",
    "select",
]

#: Analytic families tried by ``"auto"``, simplest first (their ``_asym`` variants follow), with
#: parameters held fixed: Stribeck with ``delta = 1`` is the RWSAVSBAS paper's eq. 7 as it
#: identifies it, one parameter fewer than the free shape, which extrapolates poorly from few
#: velocity levels.
FAMILIES: tuple[tuple[str, dict[str, float]], ...] = (
    ("coulomb_viscous", {}),
    ("stribeck", {"delta": 1.0}),
    ("stribeck", {}),
    ("msk", {}),
    ("vlt", {}),
)

#: A simpler model within this fraction of the best held-out RMSE is preferred.
PREFER_SIMPLER = 0.05

#: Learned families ``"auto"`` also tries (issue 15), when the data suit them.
LEARNED: tuple[str, ...] = ("rbf", "hybrid")

#: Fewest velocity levels per direction for a learned candidate.
LEARNED_MIN_LEVELS = 5

#: Most samples for a learned candidate (each fold of its validation retrains it).
LEARNED_MAX_SAMPLES = 600


@dataclass(frozen=True)
class Candidate:
    """A model ``"auto"`` may fit.

    Attributes
    ----------
    label : str
        ``model`` with its fixed parameters, e.g. ``"stribeck (delta=1)"``.
    model : str
        Registry name.
    fixed : dict of str to float
        Parameters held fixed (``*_asym``: in both directions).
    n_params : int
        Free parameters.
    note : str
        Why the data cannot support it; ``""`` when they can.
    """

    label: str
    model: str
    fixed: dict[str, float]
    n_params: int
    note: str = ""


def _varies(x: np.ndarray, atol: float) -> bool:
    return bool(np.ptp(x) > atol)


def candidates(samples: FrictionSamples, learned: bool = False) -> list[Candidate]:
    """The families of :data:`FAMILIES` and their ``_asym`` variants, simplest first, each
    with the reason the data cannot support it (module docstring), or ``""``; then, with
    ``learned``, the learned families :data:`LEARNED`.

    Parameters
    ----------
    samples : FrictionSamples
    learned : bool, default False
        Add the learned families.

    Returns
    -------
    list of Candidate
    """
    dirs = set(samples.directions())
    levels = level_labels(samples)
    load_varies = _varies(samples.load, 1e-9)
    temp_varies = _varies(samples.temperature, 0.5)
    points = np.unique(
        np.column_stack([levels, np.round(samples.load, 6), np.round(samples.temperature, 1)]),
        axis=0,
    ).shape[0]
    out: list[Candidate] = []
    for asym in (False, True):
        for family, fixed in FAMILIES:
            name = f"{family}_asym" if asym else family
            p = len(get_model(family).param_names) - len(fixed)
            reason = ""
            if family == "msk" and not load_varies:
                reason = "the load does not vary"
            elif family == "vlt" and not (load_varies and temp_varies):
                reason = "the load and the temperature do not both vary"
            elif asym and not {-1, 1} <= dirs:
                reason = "needs samples of both directions"
            elif asym and 0 in dirs:
                reason = "the samples combine both directions (eq. 11)"
            if not reason:
                if asym:
                    have = min(np.unique(levels[samples.direction == d]).size for d in (-1, 1))
                    what = "velocity levels per direction"
                else:
                    have = np.unique(levels).size
                    what = "velocity levels"
                if family in ("msk", "vlt"):
                    have, what = points, "operating points"
                if have <= p:
                    reason = f"{have} {what} for {p} parameters"
            held = {f"{k}_{d}": v for k, v in fixed.items() for d in ("pos", "neg")} if asym else {}
            label = name + (
                f" ({', '.join(f'{k}={v:g}' for k, v in fixed.items())})" if fixed else ""
            )
            out.append(Candidate(label, name, held or dict(fixed), p * (2 if asym else 1), reason))
    return out + (_learned(samples, levels) if learned else [])


def _learned(samples: FrictionSamples, levels: np.ndarray) -> list[Candidate]:
    """The learned families (issue 15): ``rbf`` (the structured network) and ``hybrid``
    (analytic backbone plus RBF residual). Their ``n_params`` is the number of samples (an
    upper bound: their size is chosen by cross-validation), so the rule "the simplest within
    5 % of the best" picks one only when it is clearly better than every analytic family."""
    n = len(samples)
    dirs = [d for d in (-1, 0, 1) if d in set(samples.directions())]
    have = min(np.unique(levels[samples.direction == d]).size for d in dirs)
    reason = ""
    if have < LEARNED_MIN_LEVELS:
        reason = (
            f"{have} velocity levels per direction (a learned model needs {LEARNED_MIN_LEVELS})"
        )
    elif n > LEARNED_MAX_SAMPLES:
        reason = (
            f"{n} samples: validating a learned model refits it per fold (slow over "
            f"{LEARNED_MAX_SAMPLES}); fit 'rbf' or 'hybrid' by name"
        )
    elif 0 in dirs and len(dirs) > 1:
        reason = "the samples mix combined and per-direction rows"
    return [Candidate(name, name, {}, n, reason) for name in LEARNED]


def select(
    samples: FrictionSamples,
    method: str = "lm",
    *,
    scheme: str = "lovo",
    scatter: Scatter | None = None,
    seed: int | np.random.Generator | None = 0,
    learned: bool = False,
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
    **fit_options
        Passed to every fit (``max_evals``, ``loss``, ``weights``, ...).

    Returns
    -------
    FittedModel
        The chosen model fitted on all the samples, with ``selection`` (scheme, chosen,
        reason, table) and ``validation`` (the chosen model's).

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
    for c in found.values():
        row: dict[str, Any] = {"model": c.label, "n_params": c.n_params}
        if c.model in LEARNED and robust and not c.note:
            c = Candidate(c.label, c.model, c.fixed, c.n_params, "trains by least squares only")
        if c.note:
            table.append({**row, "heldout_rmse": None, "ratio": None, "note": c.note})
            continue
        v = validate(
            samples, c.model, scheme, method, scatter=sc, seed=seed, fixed=c.fixed, **fit_options
        )
        runs[c.label] = v
        ok = np.isfinite(v.rmse) and v.failed == 0
        table.append(
            {
                **row,
                "heldout_rmse": float(v.rmse) if np.isfinite(v.rmse) else None,
                "ratio": float(v.ratio) if np.isfinite(v.ratio) else None,
                "note": v.verdict if ok else f"{v.failed} folds could not be fitted",
            }
        )
    scored = [r for r in table if r["heldout_rmse"] is not None and runs[r["model"]].failed == 0]
    if not scored:
        raise ConfigError(
            "model 'auto': no candidate family could be validated on these samples: "
            + "; ".join(f"{r['model']}: {r['note']}" for r in table)
        )
    best = min(scored, key=lambda r: r["heldout_rmse"])
    limit = best["heldout_rmse"] * (1.0 + PREFER_SIMPLER)
    noise = NOISE_RATIO * sc.value if np.isfinite(sc.value) else 0.0
    ok = [r for r in scored if r["heldout_rmse"] <= max(limit, noise)]
    chosen = min(ok, key=lambda r: (r["n_params"], "_asym" in r["model"]))
    reason = _reason(chosen, best, sc, scheme, noise)
    pick = found[chosen["model"]]
    fitted = _fit.fit(
        samples, pick.model, method, seed=seed, fixed=pick.fixed or None, **fit_options
    )
    fitted.selection = {
        "scheme": scheme,
        "chosen": chosen["model"],
        "reason": reason,
        "table": table,
    }
    fitted.validation = runs[chosen["model"]].to_dict()
    return fitted


def _reason(
    chosen: dict[str, Any], best: dict[str, Any], sc: Scatter, scheme: str, noise: float
) -> str:
    """Why ``chosen`` won, in one sentence."""
    name, err = chosen["model"], chosen["heldout_rmse"]
    head = f"{name} ({chosen['n_params']} parameters): held-out RMSE ({scheme}) {err:.3g} N m"
    if chosen is best:
        return f"{head}, the lowest of the candidates"
    if err <= best["heldout_rmse"] * (1.0 + PREFER_SIMPLER):
        why = f"within {PREFER_SIMPLER:.0%} of the best"
    else:
        why = f"within the noise ({NOISE_RATIO:g}x the scatter {sc.value:.3g} N m)"
    return f"{head}, {why} ({best['model']}, {best['heldout_rmse']:.3g} N m), and simpler"


@functools.wraps(_fit.fit)
def fit(samples: FrictionSamples, model: Any, method: str = "lm", **kwargs: Any) -> FittedModel:
    if isinstance(model, str) and model.strip().lower() == "auto":
        opts = {k: v for k, v in kwargs.items() if k not in ("network", "inputs", "callback")}
        if len(opts) != len(kwargs):
            raise ConfigError(
                "model 'auto' tries analytic families: no network, inputs or callback"
            )
        return select(samples, method, **opts)
    return _fit.fit(samples, model, method, **kwargs)


fit.__doc__ = (
    (_fit.fit.__doc__ or "")
    + """
    Notes
    -----
    ``model="auto"`` selects among the analytic families by held-out error
    (:func:`fricid.identify.select.select`; the comparison is saved as
    ``FittedModel.selection``).
    """
)
