"""The hybrid friction model (issue 15) as mathematics: an analytic backbone plus a learned RBF
residual, ``F = F_backbone(v, load, T) + r(v, load, T)``.

The backbone is any analytic model of the registry (:func:`fricid.models.get_model`: Stribeck,
MSK, VLT, their ``_asym`` variants, ...) with fixed parameters; the residual is an RBF network
stored as :mod:`fricid.models.rbf` reads it, with its sign of motion (``symmetry``), *without*
bias or linear tail, so that far from its centres it vanishes and the model returns to the
backbone: to physics outside the data. The paper's RBF network (BAS-RBFNN paper eq. 14-15)
models all of the friction; here it models only what the analytic law misses (a grey-box
model: a physical law plus a learned correction; issue 15 asks for it, the paper does not
have it).

A state (``FittedModel.state`` of a model ``"hybrid"``) holds ``kind`` (``"hybrid"``),
``state_version`` (2), ``symmetry`` (the residual's), ``inputs`` (every input either part
uses), ``backbone`` (``{"model": name, "params": {name: value}}``) and ``residual`` (an RBF
state), plus training notes (``prediction_interval``, ``backbone_selection``) that prediction
ignores. Identification: :mod:`fricid.identify.learned.hybrid`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from ..errors import ConfigError, DataError
from ._catalog import get_model
from .rbf import predict_state

__all__ = ["HYBRID", "STATE_KIND", "HybridModel", "backbone_of", "predict_hybrid"]

#: ``state["kind"]`` of a hybrid model.
STATE_KIND = "hybrid"


def backbone_of(state: Mapping[str, Any]):
    """The backbone's analytic model and parameter vector.

    Raises
    ------
    DataError
        A state without a well-formed ``backbone`` (an object naming a registered analytic
        model and all of its parameters as numbers inside their valid regions).
    """
    bb = state.get("backbone")
    if not isinstance(bb, Mapping) or not isinstance(bb.get("model"), str):
        raise DataError(
            "a hybrid model needs its analytic backbone in 'state.backbone' (model, params)",
            column="state.backbone",
        )
    try:
        model = get_model(bb["model"])
        params = {str(k): float(v) for k, v in dict(bb.get("params") or {}).items()}
        theta = model.param_vector(params)
    except (ConfigError, TypeError, ValueError) as exc:
        raise DataError(
            f"the hybrid model's backbone is not usable: {exc}", column="state.backbone"
        ) from None
    if not np.isfinite(theta).all():
        raise DataError(
            "the hybrid model's backbone has non-finite parameters", column="state.backbone"
        )
    bad = model.region_violation(theta)
    if bad is not None:
        raise DataError(
            f"the hybrid model's backbone parameter {bad[0].name} = {bad[1]!r} lies outside "
            f"model '{model.name}''s valid region ({bad[0].rule})",
            column=f"state.backbone.params.{bad[0].name}",
        )
    return model, theta


def predict_hybrid(state: Mapping[str, Any] | None, X) -> np.ndarray:
    """Friction [N m] of a stored hybrid model at ``X (n, 3)``: the backbone plus the residual
    network (module notes).

    Raises
    ------
    DataError
        A malformed state, or ``X`` without three columns.
    """
    if not isinstance(state, Mapping) or state.get("kind") != STATE_KIND:
        raise DataError(
            f"a hybrid model needs its state (an object of kind '{STATE_KIND}')",
            column="state.kind",
        )
    residual = state.get("residual")
    if not isinstance(residual, Mapping):
        raise DataError(
            "a hybrid model needs its residual network in 'state.residual' (an object)",
            column="state.residual",
        )
    model, theta = backbone_of(state)
    out = predict_state(residual, X)  # checks X's shape
    return model.predict(theta, np.asarray(X, dtype=float)) + out


class HybridModel:
    """The hybrid model as a registered stateful model (:data:`fricid.models.STATEFUL`)."""

    name: ClassVar[str] = "hybrid"
    title: ClassVar[str] = "analytic backbone plus RBF residual"
    equation: ClassVar[str] = "backbone + BAS-RBFNN paper eq. 14-15 on the residual"
    stateful: ClassVar[bool] = True

    def predict(self, state: Mapping[str, Any] | None, X) -> np.ndarray:
        """Friction [N m] at ``X (n, 3)``; see :func:`predict_hybrid`."""
        return predict_hybrid(state, X)

    def describe(self, state: Mapping[str, Any] | None) -> str:
        """One line on a stored hybrid model, for fit reports."""
        from .rbf import NETWORK

        st = dict(state or {})
        bb = st.get("backbone") or {}
        params = ", ".join(f"{k} = {float(v):.6g}" for k, v in dict(bb.get("params") or {}).items())
        return (
            f"backbone {bb.get('model')} ({params}); residual: "
            f"{NETWORK.describe(st.get('residual') or {})}"
        )


#: The one instance the model registry hands out.
HYBRID = HybridModel()
