"""``fit`` for the learned models: the RBF network, the hybrid and the Gaussian process.

:func:`fit_learned` is what :func:`fricid.identify.fit` calls for ``"rbf"``, ``"hybrid"`` and
``"gp"``; ``method`` names the trainer (:data:`TRAINERS`), ``settings`` the model's own
choices (inputs, network, backbone; the GP's ``max_points``, ``n_restarts``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ...errors import ConfigError
from ...fitted import FittedModel
from ...models import INPUTS
from ...samples import FrictionSamples

__all__ = ["TRAINERS", "fit_learned"]

#: The trainers of each learned model: ``lsq`` is closed-form least squares (k-means centres,
#: widths, ridge weights), ``bas`` the BAS-RBFNN paper's, ``ga`` GA-RBFNN; ``ml`` the GP's
#: marginal likelihood. The first is the default.
TRAINERS: dict[str, tuple[str, ...]] = {
    "rbf": ("lsq", "bas", "ga"),
    "hybrid": ("lsq", "bas", "ga"),
    "gp": ("ml",),
}


def fit_learned(
    samples: FrictionSamples,
    model: str,
    method: str | None = None,
    *,
    seed: int | np.random.Generator | None = 0,
    max_evals: int | None = None,
    options: Mapping[str, Any] | None = None,
    fixed: Mapping[str, float] | None = None,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    x0: Mapping[str, float] | None = None,
    inputs: Sequence[str] | None = None,
    network: Mapping[str, Any] | None = None,
    backbone: str | None = None,
    max_points: int | None = None,
    n_restarts: int | None = None,
) -> FittedModel:
    """Train the learned ``model`` (``"rbf"``, ``"hybrid"`` or ``"gp"``) on ``samples``.

    ``method`` is the trainer (:data:`TRAINERS`; default the first); ``max_evals`` becomes
    the network's ``max_epochs = ceil(max_evals / evals_per_epoch)``; ``options`` the
    trainer's optimiser options; ``seed`` the ``random_state``. Named parameters
    (``fixed``, ``bounds``, ``x0``) do not apply: these models have none.
    """
    if model not in TRAINERS:
        raise ConfigError(f"unknown learned model '{model}'; one of {', '.join(TRAINERS)}")
    given = [k for k, v in (("fixed", fixed), ("bounds", bounds), ("x0", x0)) if v]
    if given:
        raise ConfigError(
            f"model '{model}' has no named parameters: {', '.join(given)} do(es) not apply "
            "(set the network through settings={'network': ...})"
        )
    trainer = (method or TRAINERS[model][0]).strip().lower()
    if trainer not in TRAINERS[model]:
        raise ConfigError(
            f"model '{model}' trains with method {', '.join(TRAINERS[model])}; got '{method}'"
        )
    if isinstance(seed, np.random.Generator):
        seed = int(seed.integers(2**31))
    names = None if inputs is None or tuple(inputs) == INPUTS else list(inputs)
    if model == "gp":
        from .gp import fit_gp

        if network or backbone or max_evals is not None or options:
            raise ConfigError("model 'gp' takes no network, backbone, max_evals or options")
        gp_settings = {"max_points": max_points, "n_restarts": n_restarts}
        return fit_gp(
            samples,
            inputs=INPUTS if names is None else names,
            seed=seed,
            **{k: v for k, v in gp_settings.items() if v is not None},
        )
    from .rbf import RBFNetRegressor, fit_rbf

    params = dict(network or {})
    m = params.get("n_centers")
    if m is not None and (isinstance(m, bool) or not isinstance(m, int | np.integer) or m < 1):
        raise ConfigError(
            f"the network's number of centres (--centers, n_centers) must be a whole number "
            f">= 1; got {m!r}"
        )
    params["trainer"] = trainer
    params["random_state"] = seed
    if options is not None:
        params["method_options"] = dict(options)
    if max_evals is not None:
        per_epoch = int(params.get("evals_per_epoch", RBFNetRegressor().evals_per_epoch))
        params["max_epochs"] = max(1, -(-int(max_evals) // per_epoch))
    if model == "hybrid":
        from .hybrid import fit_hybrid

        if backbone:
            params["backbone"] = backbone
        return fit_hybrid(samples, names, **params)
    if backbone:
        raise ConfigError("model 'rbf' has no backbone (model 'hybrid' has)")
    return fit_rbf(samples, names, **params)
