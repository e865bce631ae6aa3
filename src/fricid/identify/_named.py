"""Fit one named model to samples: the analytic and learned kinds of :func:`fricid.identify.fit`.

Below :mod:`fricid.identify.dispatch`, :mod:`fricid.identify.validate` and
:mod:`fricid.identify.static.select`, which all refit named models (validation refits per fold,
selection per candidate), so that none of them imports the public entry back.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..fitted import FittedModel
from ..models import STATEFUL, FrictionModel, get_model, unknown_model
from ..samples import FrictionSamples, RawLog, RobotLog

__all__ = ["KINDS", "LEARNED", "SETTINGS", "fit_named", "kind_of"]

#: The kinds of identification and what does each (module notes).
KINDS: dict[str, str] = {
    "analytic": "fricid.identify.static.least_squares.fit",
    "learned": "fricid.identify.learned.train.fit_learned",
    "dynamic": "fricid.identify.dynamic.trajectory.fit_trajectory",
    "auto": "fricid.identify.static.select.select",
    "arm": "fricid.identify.dynamic.arm.fit_arm",
}

#: The ``settings`` each kind (or learned model) takes; anything else is a ConfigError.
SETTINGS: dict[str, tuple[str, ...]] = {
    "analytic": (),
    "rbf": ("inputs", "network"),
    "hybrid": ("inputs", "network", "backbone"),
    "gp": ("inputs", "max_points", "n_restarts"),
    "dynamic": (
        "route",
        "gravity",
        "derivative",
        "parallel",
        "v_slide",
        "guard",
        "v_window",
        "static",
        "n_sub",
        "cluster_time",
        "rate_bias",
        "encoder_counts",
        "output_error",
        "progress",
    ),
    "auto": ("scheme", "scatter", "learned", "progress"),
    "arm": ("robot", "friction", "consistent", "encoder_counts", "cutoff", "validate"),
}

#: The learned models (stored state, no named parameters).
LEARNED = ("rbf", "hybrid", "gp")


def kind_of(data: FrictionSamples | RawLog | RobotLog, model: str | FrictionModel) -> str:
    """The kind of identification for ``data`` and ``model`` (:data:`KINDS`)."""
    if isinstance(data, RawLog):
        return "dynamic"
    if isinstance(data, RobotLog):
        return "arm"
    if not isinstance(data, FrictionSamples):
        raise ConfigError(
            "fit takes FrictionSamples, a RawLog (a trajectory) or a RobotLog (a whole arm); "
            f"got {type(data).__name__}"
        )
    key = model.strip().lower() if isinstance(model, str) else None
    if key == "auto":
        return "auto"
    if key in LEARNED or (key is not None and key in STATEFUL):
        return "learned"
    return "analytic"


def _settings(kind: str, model: Any, settings: Mapping[str, Any] | None) -> dict[str, Any]:
    """``settings`` checked against what ``kind`` (or the learned ``model``) takes."""
    given = dict(settings or {})
    key = model.strip().lower() if kind == "learned" and isinstance(model, str) else kind
    allowed = SETTINGS.get(key, ())
    unknown = sorted(set(given) - set(allowed))
    if unknown:
        what = f"model '{key}'" if kind == "learned" else f"{kind} identification"
        takes = ", ".join(allowed) if allowed else "no settings"
        raise ConfigError(f"{what} takes {takes}; not: {', '.join(unknown)}")
    return given


def _known(name: str) -> None:
    """Raise the catalog's error for an unknown analytic name, with the learned families and
    ``auto`` among those it offers."""
    try:
        get_model(name)
    except ConfigError as exc:
        if not str(exc).startswith("unknown model"):
            raise
        more = {"learned": LEARNED, "selection": ("auto",)}
        raise ConfigError(unknown_model(name, more)) from None


def fit_named(
    samples: FrictionSamples,
    model: str | FrictionModel,
    method: str | None = None,
    *,
    settings: Mapping[str, Any] | None = None,
    **arguments: Any,
) -> FittedModel:
    """:func:`fricid.identify.fit` for an analytic or learned ``model`` (not ``"auto"``, not a
    trajectory): ``arguments`` are that function's keywords (``fixed``, ``bounds``, ``seed``,
    ``loss``, ...), with the same meaning; an unknown one is a TypeError, as there."""
    kind = kind_of(samples, model)
    if kind not in ("analytic", "learned"):
        raise ConfigError(f"fit_named fits one named model to samples; got {kind} identification")
    extra = _settings(kind, model, settings)
    if kind == "analytic":
        from .static.least_squares import fit as fit_analytic

        if isinstance(model, str):
            _known(model)
        if arguments.get("options") is not None:
            arguments["options"] = dict(arguments["options"])
        return fit_analytic(samples, model, method or "lm", **arguments)
    from .learned.train import fit_learned

    shared = ("seed", "max_evals", "options", "fixed", "bounds", "x0")
    unknown = set(arguments) - {*shared, "callback", "intervals", "loss", "f_scale", "weights"}
    if unknown:
        raise TypeError(f"fit() got unexpected keyword arguments: {', '.join(sorted(unknown))}")
    loss, weights = arguments.get("loss", "l2"), arguments.get("weights", "none")
    _refuse(kind, loss=str(loss).lower() not in ("l2", "sse"), weights=not _no_weights(weights))
    _refuse(kind, f_scale=arguments.get("f_scale"), callback=arguments.get("callback"))
    return fit_learned(
        samples,
        str(model).strip().lower(),
        method,
        **{k: arguments[k] for k in shared if k in arguments},
        **extra,
    )


def _refuse(kind: str, **given: Any) -> None:
    """ConfigError naming the arguments given that ``kind`` does not take."""
    named = [k for k, v in given.items() if v is not None and v is not False and v != {}]
    if named:
        raise ConfigError(f"{kind} identification does not take {', '.join(named)}")


def _no_weights(weights: Any) -> bool:
    return weights is None or (isinstance(weights, str) and weights.strip().lower() == "none")


def _int_seed(seed: int | np.random.Generator | None) -> int:
    if isinstance(seed, np.random.Generator):
        return int(seed.integers(2**31))
    return 0 if seed is None else int(seed)
