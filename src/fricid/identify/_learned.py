"""``fit`` for every family: the learned ones (``"rbf"``, ``"hybrid"``, ``"gp"``) routed to
their trainers, the analytic ones to :func:`fricid.identify._fit.fit`.

A module of its own, above both: the hybrid's trainer fits its analytic backbone with
:mod:`fricid.identify._fit`, which therefore must not import the trainers back.
"""

from __future__ import annotations

import functools
import inspect
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from ..errors import ConfigError, IgnoredArgumentWarning
from ..fitted import FittedModel
from ..models import INPUTS, STATEFUL
from ..optim import OptimizeResult
from ..samples import FrictionSamples
from . import _fit
from ._fit import _no_weights

__all__ = ["fit"]

_SIGNATURE = inspect.signature(_fit.fit)


@functools.wraps(_fit.fit)
def fit(samples: FrictionSamples, model: Any, method: str = "lm", **kwargs: Any) -> FittedModel:
    key = model.strip().lower() if isinstance(model, str) else None
    if key != "gp" and key not in STATEFUL:
        return _fit.fit(samples, model, method, **kwargs)
    bound = _SIGNATURE.bind(samples, model, method, **kwargs)
    bound.apply_defaults()
    a = bound.arguments
    loss, weights, fixed, bounds = a["loss"], a["weights"], a["fixed"], a["bounds"]
    seed, options, inputs = a["seed"], a["options"], a["inputs"]
    max_evals, network, callback, x0 = a["max_evals"], a["network"], a["callback"], a["x0"]
    if key == "gp":
        from .gp import fit_gp  # the Gaussian process: its options through `options`

        if str(loss).lower() not in ("l2", "sse") or not _no_weights(weights) or fixed or bounds:
            raise ConfigError(
                "model 'gp' learns by marginal likelihood: no robust loss, weights, fixed or bounds"
            )
        return fit_gp(samples, inputs=inputs, seed=seed, **(options or {}))
    if str(loss).lower() not in ("l2", "sse") or not _no_weights(weights):
        raise ConfigError("model 'rbf' trains by least squares: no robust loss or weights")
    return _fit_network(
        samples,
        method,
        seed,
        max_evals,
        options,
        network,
        inputs,
        callback,
        model_name=key,
        fixed=fixed,
        bounds=bounds,
        x0=x0,
    )


def _fit_network(
    samples: FrictionSamples,
    method: str,
    seed: int | np.random.Generator | None,
    max_evals: int | None,
    options: dict[str, Any] | None,
    network: Mapping[str, Any] | None,
    inputs: Sequence[str],
    callback: Callable[[OptimizeResult], Any] | None,
    **analytic: Any,
) -> FittedModel:
    """``fit(samples, "rbf", ...)``: :func:`fricid.identify.rbf.fit_rbf` with fit's arguments
    translated (``method`` -> ``trainer``, ``seed`` -> ``random_state``, ``options`` ->
    ``method_options``, ``max_evals`` -> ``max_epochs``)."""
    from .rbf import RBFNetRegressor, fit_rbf

    fit_network = fit_rbf
    if analytic.pop("model_name", "rbf") == "hybrid":  # issue 15: backbone + RBF residual
        from .hybrid import fit_hybrid as fit_network
    given = [name for name, value in analytic.items() if value]
    if given:
        raise ConfigError(
            f"model 'rbf' has no named parameters: {', '.join(given)} do(es) not apply "
            "(set the network with `network=`)"
        )
    if callback is not None:
        warnings.warn(
            "model 'rbf' does not take a callback; ignored", IgnoredArgumentWarning, stacklevel=3
        )
    params = dict(network or {})
    m = params.get("n_centers")
    if m is not None and (isinstance(m, bool) or not isinstance(m, int | np.integer) or m < 1):
        raise ConfigError(
            f"the network's number of centres (--centers, n_centers) must be a whole number "
            f">= 1; got {m!r}"
        )
    key = str(method).strip().lower()
    params["trainer"] = "lsq" if key == "lm" else key
    if isinstance(seed, np.random.Generator):
        seed = int(seed.integers(2**31))
    params["random_state"] = seed
    if options is not None:
        params["method_options"] = dict(options)
    if max_evals is not None:
        per_epoch = int(params.get("evals_per_epoch", RBFNetRegressor().evals_per_epoch))
        params["max_epochs"] = max(1, -(-int(max_evals) // per_epoch))
    # the default inputs are the measured ones (a column not measured is no error here)
    names = None if tuple(inputs) == INPUTS else inputs
    return fit_network(samples, names, **params)
