"""``fit`` and ``evaluate``: samples + model + optimiser -> :class:`~fricid.fitted.FittedModel`.

``fit`` states the problem (:class:`~fricid.identify.problem.IdentificationProblem`: the sum of
squared errors between the model and the measured friction, the RWSAVSBAS paper's objective,
eq. 11 there), minimises it with any method of :mod:`fricid.optim`, certifies convergence by a
short local polish (:mod:`fricid.identify.static.convergence`), then gives the parameters'
uncertainty only where it means something: standard errors from the Jacobian and
profile-likelihood intervals inside the search box (:mod:`fricid.identify.static.uncertainty`,
:mod:`fricid.identify.static.profile`). The RBF network (``model="rbf"``) is trained by
:func:`fricid.identify.learned.rbf.fit_rbf`.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from ...errors import (
    ConfigError,
    ConvergenceWarning,
    IdentifiabilityWarning,
    IgnoredArgumentWarning,
    user_stacklevel,
)
from ...fitted import FittedModel, OptimizerRecord, Parameter, is_not_determined
from ...metrics import fit_statistics, metrics
from ...models import INPUTS, FrictionModel, get_model
from ...optim import METHODS, OptimizeResult, minimize
from ...samples import FrictionSamples
from .._intervals import delta_record
from .._records import operating_range, provenance
from .._scatter import measurement_scatter, sample_weights
from ..problem import ROBUST_LOSSES, IdentificationProblem
from .checks import check_identifiable
from .convergence import certify
from .informed import uninformed
from .shared_error import own_variance, shared_covariance
from .uncertainty import INTERVALS, Uncertainty, assess
from .varpro import varpro

__all__ = ["evaluate", "fit"]

#: A correlation smaller than this is rounding (the covariance's arithmetic), written as 0.
ROUNDING = 1e-10


def fit(
    samples: FrictionSamples,
    model: str | FrictionModel,
    method: str = "lm",
    *,
    fixed: Mapping[str, float] | None = None,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    seed: int | np.random.Generator | None = 0,
    max_evals: int | None = None,
    options: dict[str, Any] | None = None,
    x0: Mapping[str, float] | None = None,
    callback: Callable[[OptimizeResult], Any] | None = None,
    network: Mapping[str, Any] | None = None,
    inputs: Sequence[str] = INPUTS,
    intervals: str = "auto",
    loss: str = "l2",
    f_scale: float | None = None,
    weights: str | Any = "none",
) -> FittedModel:
    """Identify ``model`` from ``samples`` by least squares with ``method``.

    Parameters
    ----------
    samples : FrictionSamples
        The measured friction.
    model : str or FrictionModel
        A model name (``fricid.models.MODELS``, ``*_asym`` for per-direction), an instance,
        ``*_temp`` / ``*_temp_asym`` with an Arrhenius viscous term, ``"rbf"`` for the RBF
        network (:mod:`fricid.identify.learned.rbf`), ``"hybrid"`` for an analytic backbone plus an
        RBF
        residual (:mod:`fricid.identify.learned.hybrid`; ``network`` may name its ``backbone``) or
        ``"gp"`` for the Gaussian process (:mod:`fricid.identify.learned.gp`; its options, e.g.
        ``max_points``, through ``options``).
    method : str, default "lm"
        Any method of ``fricid.optim.METHODS`` (``"lm"``: the default least-squares method,
        scipy's bounded trust-region reflective solver, a Levenberg-Marquardt-type method, with
        multi-start; :mod:`fricid.optim._least_squares`), or ``"varpro"``: the exact
        least-squares optimum by variable projection for models that declare
        ``linear_params`` (:mod:`fricid.identify.static.varpro`). For ``"rbf"``: ``"lsq"`` (k-means,
        widths, ridge least squares) or an optimiser trainer (``"bas"`` for BAS-RBFNN,
        ``"ga"`` for GA-RBFNN, ...); the default ``"lm"`` means ``"lsq"`` there.
    fixed : mapping of str to float, optional
        Parameters held at a value, e.g. ``{"delta": 1.0}`` for the RWSAVSBAS paper's
        Stribeck model.
    bounds : mapping of str to (float, float), optional
        Per-parameter search bounds overriding the model's data-scaled defaults.
    seed : int or numpy.random.Generator, optional
        Makes the fit reproducible (default 0); the RBF network's ``random_state``.
    max_evals : int, optional
        Budget in evaluations (the RBF network: ``max_epochs = ceil(max_evals /
        evals_per_epoch)``).
    options : dict, optional
        Options of the method (the RBF network's ``method_options``).
    x0 : mapping of str to float, optional
        Starting values of free parameters (default: the model's data-scaled defaults).
    callback : callable, optional
        Passed to ``fricid.optim.minimize`` (analytic models only).
    network : mapping, optional
        ``"rbf"`` only: parameters of :class:`~fricid.identify.learned.rbf.RBFNetRegressor`
        (``n_centers``, ``velocity_scale``, ``encoding``, ...).
    inputs : sequence of str, default ("velocity", "load", "temperature")
        ``"rbf"`` only: the network's input columns.
    intervals : {"auto", "profile", "jacobian", "none"}, default "auto"
        95 % intervals of the parameters: profile likelihood inside the search box
        (:mod:`fricid.identify.static.profile`; ``"auto"`` uses it for at most
        :data:`~fricid.identify.static.uncertainty.PROFILE_AUTO_MAX` free parameters and
        re-fits only the sides where the quadratic approximation fails,
        :mod:`fricid.identify.static.curvature`; ``"profile"`` re-fits every side), the
        Jacobian's
        ``value +/- t se`` cut at the box, or none. A fit that did not converge, or whose
        optimum is degenerate (rank-deficient Jacobian), gets none whatever is asked.
    loss : {"l2", "soft_l1", "huber"}, default "l2"
        Least squares, or a robust loss for logs with spikes
        (:data:`fricid.identify.problem.ROBUST_LOSSES`).
    f_scale : float, optional
        N m, the robust loss's scale; default: the measurement scatter
        (:func:`fricid.identify.validate.measurement_scatter`).
    weights : {"none", "std"} or array_like (n,), default "none"
        ``"std"``: weighted least squares with ``1 / se^2`` from the samples' own standard
        errors (:func:`fricid.identify.validate.sample_weights`), or the weights themselves.

    Returns
    -------
    FittedModel
        With the optimiser's record (``optimizer``: method, seed, status, message,
        evaluations, budget, history), the ``convergence`` verdict (a local polish's,
        :func:`~fricid.identify.static.convergence.certify`), fit statistics, one record per
        parameter (:class:`~fricid.fitted.Parameter`: start, search bounds, standard error
        from the SVD pseudo-inverse, the 95 % interval and its open ends (``ci_method`` says
        how it was found), the note saying why a parameter has none, the flags) and
        correlations.

    Raises
    ------
    ConfigError
        Unknown model, method, parameter or option; bad bounds; too few samples; arguments
        of an analytic fit given for ``"rbf"`` (``fixed``, ``bounds``, ``x0``).

    Warns
    -----
    ConvergenceWarning
        The fit did not converge: a local least-squares polish from its result lowers the
        SSE (the message says by how much and what to do); its intervals are withheld.
    IdentifiabilityWarning
        The data do not determine some parameter: too few velocity levels, no load or
        temperature variation for a model that uses them (checked before fitting,
        :func:`~fricid.identify.static.checks.check_identifiable`); a rank-deficient Jacobian at the
        optimum (which combination is free); or an interval that reaches a bound of the
        search box other than 0 (which bound, and its strongest correlation).
    IgnoredArgumentWarning
        An argument the chosen model does not use (``network``, ``inputs`` for analytic
        models; ``callback`` for ``"rbf"``).
    """
    if network is not None or tuple(inputs) != INPUTS:
        warnings.warn(
            "`network` and `inputs` apply to model 'rbf' only; ignored",
            IgnoredArgumentWarning,
            stacklevel=user_stacklevel(),
        )
    model = get_model(model)
    samples.require(model.inputs, f"model '{model.name}'")
    scatter = measurement_scatter(samples)
    w = sample_weights(samples, weights, scatter) if isinstance(weights, str) else weights
    loss_key = str(loss).strip().lower()
    if loss_key in ROBUST_LOSSES and f_scale is None:
        f_scale = scatter.value if np.isfinite(scatter.value) and scatter.value > 0 else None
    problem = IdentificationProblem(
        model, samples, loss=loss_key, bounds=bounds, fixed=fixed, weights=w, f_scale=f_scale
    )
    X, y = problem.X, problem.y
    if problem.n_obs < problem.n_free:
        raise ConfigError(
            f"{problem.n_obs} samples cannot identify {problem.n_free} free parameters of "
            f"'{model.name}'"
        )
    check_identifiable(samples, model, fixed=problem.fixed, stacklevel=3)
    key = str(method).strip().lower()
    start = problem.start(x0) if key in METHODS else None
    uses_residuals = key in METHODS and METHODS[key].uses_residuals
    if key in METHODS and "restart_above" in METHODS[key].options:
        options = _restart_above(dict(options or {}), problem, scatter.value)
    if key == "varpro":  # separable least squares over the whole box (identify/varpro.py)
        if x0:
            warnings.warn(
                "method 'varpro' searches the whole search box; x0 is not used",
                IgnoredArgumentWarning,
                stacklevel=user_stacklevel(),
            )
        result = varpro(problem, seed=seed, max_evals=max_evals, options=options, callback=callback)
    else:
        result = minimize(
            problem.objective(),
            problem.bounds,
            method=method,
            seed=seed,
            max_evals=max_evals,
            options=options,
            callback=callback,
            x0=start,
            residuals=problem.residuals if uses_residuals else None,
        )
    key_i = str(intervals).strip().lower()
    if key_i not in INTERVALS:
        raise ConfigError(f"intervals must be one of {', '.join(INTERVALS)}; got {intervals!r}")
    convergence = certify(problem, result)
    if not convergence["converged"]:
        warnings.warn(
            f"fitting '{model.name}' did not converge: {convergence['reason']}; "
            f"{convergence['advice']}",
            ConvergenceWarning,
            stacklevel=user_stacklevel(),
        )
    theta = problem.expand(result.x)[0]
    shared = shared_covariance(samples)
    if shared is not None and shared.shape[0] != problem.n_obs:
        shared = None
    unc = assess(
        problem,
        result.x,
        converged=convergence["converged"],
        reason=convergence.get("reason", ""),
        intervals=key_i,
        units=model.units,
        shared=shared,
        own=None if shared is None else own_variance(samples, shared),
    )
    if unc.identifiability:
        warnings.warn(
            f"fitting '{model.name}': the data " + "; the data ".join(unc.identifiability),
            IdentifiabilityWarning,
            stacklevel=user_stacklevel(),
        )
    if unc.lower_sse < float(result.fun) * (1 - 1e-6):
        warnings.warn(
            f"fitting '{model.name}': a profile re-fit found SSE {unc.lower_sse:.6g} below the "
            f"fit's {float(result.fun):.6g}; the fit is a local optimum (use more starts)",
            ConvergenceWarning,
            stacklevel=user_stacklevel(),
        )
    cov = unc.cov
    corr = None
    if cov is not None:
        d = np.sqrt(np.diag(cov))
        with np.errstate(invalid="ignore", divide="ignore"):
            r = cov / np.outer(d, d)
        # the parameters' correlations, not the arithmetic's: 1 on the diagonal (was
        # 0.9999999999999998), 0 below ROUNDING (forwards and backwards levels, which share no
        # sample, were written as correlated by -2.79e-16)
        r[np.abs(r) < ROUNDING] = 0.0
        ok = np.isfinite(d) & (d > 0)
        r[ok, ok] = 1.0
        corr = r.tolist()

    y_hat = model.predict(theta, X)
    return FittedModel(
        model=model.name,
        parameters=_records(
            problem,
            theta,
            unc,
            start,
            problem.at_bound(result.x),
            convergence["converged"],
            uninformed(model.name, theta, samples),
        ),
        ci_method=unc.method,
        correlation=corr,
        optimizer=OptimizerRecord(
            method=result.method,
            seed=result.seed,
            status=int(result.status),
            message=str(result.message),
            nfev=int(result.nfev),
            max_evals=int(result.get("max_evals", result.nfev)),
            history=np.asarray(result.history).tolist(),
        ),
        convergence=convergence,
        metrics=metrics(y, y_hat, samples.direction, scatter.value),
        operating_range=operating_range(samples, X),
        provenance=provenance(samples, **_shared_record(problem, unc)),
        statistics=fit_statistics(y, y_hat, problem.n_free, w),
        prediction_interval=delta_record(
            model.name,
            theta,
            problem.free_names,
            X,
            y,
            None if scatter.estimated else scatter.value,
            scatter.value,
            shared=unc.shared_cov,
        ),
        loss={
            "loss": "l2" if problem.loss == "sse" else problem.loss,
            "f_scale": problem.f_scale,
            "weights": _weights_name(weights),
            "scatter": scatter.to_dict(),
        },
    )


def _shared_record(problem: IdentificationProblem, unc: Uncertainty) -> dict[str, Any]:
    """``provenance["shared_error"]``: what the intervals include beyond the residuals' scatter
    (the arm's identified gravity, :mod:`~fricid.identify.static.shared_error`), with each free
    parameter's share of variance from it; nothing when there is none."""
    if unc.shared is None:
        return {}
    return {
        "shared_error": {
            "source": "the arm's base gravity parameters, identified from the sweeps and "
            "removed from every sample",
            "variance_share": {
                n: round(float(s), 4) for n, s in zip(problem.free_names, unc.shared, strict=True)
            },
        }
    }


def _records(
    problem: IdentificationProblem,
    theta: np.ndarray,
    unc: Uncertainty,
    start: np.ndarray | None,
    at_bound: Sequence[str],
    converged: bool,
    outside: Mapping[str, str] | None = None,
) -> dict[str, Parameter]:
    """One :class:`~fricid.fitted.Parameter` per parameter of ``problem`` at ``theta``: the
    free ones with their start, search bounds, standard error, interval (``unc``) and flags;
    ``outside`` names those outside the range the data can inform, with why
    (:func:`~fricid.identify.static.informed.uninformed`: not determined)."""
    units = problem.model.units
    out = {
        n: Parameter(n, float(v), unit=units.get(n, ""), fixed=n in problem.fixed)
        for n, v in zip(problem.names, theta, strict=True)
    }
    for j, n in enumerate(problem.free_names):
        note = unc.notes.get(n, "")
        if outside and n in outside and not note.startswith(("not determined", "not identified")):
            note = outside[n] + (f"; {note}" if note else "")
        out[n] = replace(
            out[n],
            init=None if start is None else float(start[j]),
            bounds=(float(problem.bounds[j, 0]), float(problem.bounds[j, 1])),
            stderr=float(unc.stderr[j]),
            ci95=(float(unc.low[j]), float(unc.high[j])),
            ci95_halfwidth=float(unc.ci95[j]),
            low_open=bool(unc.open[j, 0]),
            high_open=bool(unc.open[j, 1]),
            note=note,
            at_bound=n in at_bound,
            not_determined=is_not_determined(note, float(unc.stderr[j]), converged),
        )
    return out


#: ``lm`` restarts (multi-start) when its first start's RMS residual exceeds this many times
#: the measurement scatter (issue 14: restart only when the fit is doubtful).
RESTART_SCATTER_FACTOR = 3.0


def _restart_above(options: dict[str, Any], problem: IdentificationProblem, scatter: float):
    """``options`` with ``restart_above``: the loss of residuals of
    :data:`RESTART_SCATTER_FACTOR` times the scatter at every sample (weighted as the problem
    weighs them), unless given. When the scatter is unknown the residual cannot be judged, so
    every start runs (``restart="always"``, unless given)."""
    if "restart_above" in options:
        return options
    if not np.isfinite(scatter) or scatter <= 0:
        options.setdefault("restart", "always")
        return options
    w = problem.weights
    total = float(problem.n_obs if w is None else np.sum(w))
    target = (RESTART_SCATTER_FACTOR * scatter) ** 2 * total
    options["restart_above"] = target / problem.n_obs if problem.loss == "mse" else target
    return options


def _no_weights(weights: Any) -> bool:
    return weights is None or (isinstance(weights, str) and weights.strip().lower() == "none")


def _weights_name(weights: Any) -> str:
    """What the model file records: ``none``, ``std`` or ``given`` (an array)."""
    if _no_weights(weights):
        return "none"
    return weights.strip().lower() if isinstance(weights, str) else "given"


def evaluate(model: FittedModel, samples: FrictionSamples) -> dict[str, float]:
    """Metrics of a fitted model on (other) samples (``fricid.metrics.metrics``), with RMSE and
    R^2 of the magnitude per direction and the RMSE over the samples' measurement scatter."""
    scatter = measurement_scatter(samples)
    return metrics(samples.y, model.predict(samples.X), samples.direction, scatter.value)
