"""Identification: samples + model + optimiser -> :class:`~fricid.fitted.FittedModel`.

``fit`` minimises the sum of squared errors between the model and the measured friction
(the RWSAVSBAS paper's objective, eq. 11 there) with any method of :mod:`fricid.optim`,
then estimates the parameters' uncertainty from the Jacobian at the optimum.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from scipy import stats

from .. import __version__
from ..errors import ConfigError
from ..fitted import FittedModel
from ..io.atomic import created_timestamp
from ..metrics import metrics
from ..models import FrictionModel, get_model
from ..optim import METHODS, OptimizeResult, minimize
from ..samples import FrictionSamples, samples_hash

__all__ = ["evaluate", "fit", "jacobian_uncertainty", "samples_hash"]


def _check_directions(samples: FrictionSamples, model: FrictionModel) -> None:
    dirs = set(samples.directions())
    if model.is_asymmetric:
        if 0 in dirs:
            raise ConfigError(
                f"model '{model.name}' has parameters per direction, but the samples combine "
                "both directions (eq. 11); extract per-direction samples or fit the symmetric "
                "model"
            )
        if not {-1, 1} <= dirs:
            only = "positive" if 1 in dirs else "negative"
            raise ConfigError(
                f"model '{model.name}' has parameters per direction, but the samples hold the "
                f"{only} direction only"
            )


def _resolve_bounds(
    model: FrictionModel,
    X: np.ndarray,
    y: np.ndarray,
    bounds: Mapping[str, tuple[float, float]] | None,
) -> np.ndarray:
    b = model.bounds(X, y)
    for name, pair in (bounds or {}).items():
        if name not in model.param_names:
            raise ConfigError(
                f"bounds given for unknown parameter '{name}' of model '{model.name}'; "
                f"its parameters: {', '.join(model.param_names)}"
            )
        lo, hi = (float(v) for v in pair)
        if not lo < hi:
            raise ConfigError(f"bounds for '{name}' need lower < upper; got ({lo}, {hi})")
        b[model.param_names.index(name)] = (lo, hi)
    return b


def jacobian_uncertainty(
    residual: Callable[[np.ndarray], np.ndarray], theta: np.ndarray, n_obs: int
) -> tuple[np.ndarray, np.ndarray | None]:
    """Standard errors and covariance of ``theta`` from a central-difference Jacobian.

    ``residual`` maps a batch ``(k, p) -> (k, n)``. Returns ``(stderr, cov)``; entries are NaN
    (and ``cov`` None) when the Jacobian is rank-deficient or there are no spare observations.
    """
    p = theta.size
    nan = np.full(p, np.nan)
    dof = n_obs - p
    if p == 0 or dof <= 0:
        return nan, None
    h = 1e-6 * np.maximum(np.abs(theta), 1e-3)
    steps = np.vstack([theta + np.diag(h), theta - np.diag(h)])
    r = residual(np.vstack([theta[None, :], steps]))
    r0, rp, rm = r[0], r[1 : p + 1], r[p + 1 :]
    J = ((rp - rm) / (2 * h[:, None])).T  # (n, p)
    s2 = float(r0 @ r0) / dof
    jtj = J.T @ J
    if not np.isfinite(jtj).all() or np.linalg.matrix_rank(jtj) < p:
        return nan, None
    cov = s2 * np.linalg.inv(jtj)
    return np.sqrt(np.clip(np.diag(cov), 0.0, None)), cov


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
) -> FittedModel:
    """Identify ``model`` from ``samples`` by least squares with ``method``.

    Parameters
    ----------
    samples : the measured friction (``FrictionSamples``).
    model : a model name (``fricid.models.MODELS``, ``*_asym`` for per-direction) or instance.
    method : any method of ``fricid.optim.METHODS`` (default ``"lm"``, Levenberg-Marquardt
        with multi-start).
    fixed : parameters held at a value, e.g. ``{"delta": 1.0}`` for the RWSAVSBAS paper's
        Stribeck model.
    bounds : per-parameter search bounds overriding the model's data-scaled defaults.
    seed : makes the fit reproducible (default 0).
    max_evals, options, callback : passed to ``fricid.optim.minimize``.
    x0 : starting values of free parameters (default: the model's data-scaled defaults).
    """
    model = get_model(model)
    _check_directions(samples, model)
    X, y = samples.X, samples.y
    names = model.param_names
    fixed = dict(fixed or {})
    unknown = [k for k in fixed if k not in names]
    if unknown:
        raise ConfigError(
            f"cannot fix unknown parameter(s) {', '.join(unknown)} of model '{model.name}'; "
            f"its parameters: {', '.join(names)}"
        )
    free = [i for i, n in enumerate(names) if n not in fixed]
    if not free:
        raise ConfigError("every parameter is fixed; nothing to identify")
    if len(y) < len(free):
        raise ConfigError(
            f"{len(y)} samples cannot identify {len(free)} free parameters of '{model.name}'"
        )
    full_bounds = _resolve_bounds(model, X, y, bounds)
    base = model.defaults(X, y)
    for name, value in fixed.items():
        base[names.index(name)] = float(value)
    free_bounds = full_bounds[free]

    def expand(T: np.ndarray) -> np.ndarray:
        full = np.broadcast_to(base, (T.shape[0], base.size)).copy()
        full[:, free] = T
        return full

    def residuals(T: np.ndarray) -> np.ndarray:
        return model.predict(expand(np.atleast_2d(T)), X) - y

    start = None
    if METHODS.get(str(method).lower()) is not None:
        start = np.clip(base[free], free_bounds[:, 0], free_bounds[:, 1])
        for name, value in (x0 or {}).items():
            if name not in names or name in fixed:
                raise ConfigError(f"x0 names '{name}', which is not a free parameter")
            start[free.index(names.index(name))] = float(value)
    result = minimize(
        None,
        free_bounds,
        method=method,
        seed=seed,
        max_evals=max_evals,
        options=options,
        callback=callback,
        x0=start,
        residuals=residuals,
    )
    if not result.success:
        raise ConfigError(f"identification failed: {result.message}")
    theta = expand(result.x[None, :])[0]
    stderr, cov = jacobian_uncertainty(residuals, result.x, len(y))
    dof = max(len(y) - len(free), 1)
    t95 = float(stats.t.ppf(0.975, dof))
    span = free_bounds[:, 1] - free_bounds[:, 0]
    at_bound = [
        names[i]
        for j, i in enumerate(free)
        if min(result.x[j] - free_bounds[j, 0], free_bounds[j, 1] - result.x[j]) <= 1e-6 * span[j]
    ]
    corr = None
    if cov is not None:
        d = np.sqrt(np.diag(cov))
        with np.errstate(invalid="ignore", divide="ignore"):
            corr = (cov / np.outer(d, d)).tolist()
    free_names = [names[i] for i in free]
    return FittedModel(
        model=model.name,
        params={n: float(v) for n, v in zip(names, theta, strict=True)},
        units=model.units,
        fixed=sorted(fixed),
        stderr={n: float(s) for n, s in zip(free_names, stderr, strict=True)},
        ci95={n: float(s) * t95 for n, s in zip(free_names, stderr, strict=True)},
        at_bound=at_bound,
        correlation=corr,
        metrics=metrics(y, model.predict(theta, X)),
        method=result.method,
        seed=result.seed,
        nfev=int(result.nfev),
        history=np.asarray(result.history).tolist(),
        bounds={
            n: [float(lo), float(hi)] for n, (lo, hi) in zip(free_names, free_bounds, strict=True)
        },
        operating_range={
            "velocity": [float(X[:, 0].min()), float(X[:, 0].max())],
            "load": [float(X[:, 1].min()), float(X[:, 1].max())],
            "temperature": [float(X[:, 2].min()), float(X[:, 2].max())],
        },
        provenance={
            "source": samples.source,
            "n_samples": len(samples),
            "samples_sha256_16": samples_hash(samples),
            "directions": list(samples.directions()),
            "fricid_version": __version__,
            "created": created_timestamp(),
        },
    )


def evaluate(model: FittedModel, samples: FrictionSamples) -> dict[str, float]:
    """Metrics of a fitted model on (other) samples."""
    return metrics(samples.y, model.predict(samples.X))
