"""Friction models as mathematics: the analytic models of both papers and the RBF network.

Use :func:`get_model` to look an analytic model up by name (``"<name>_asym"`` gives the
per-direction variant), and :func:`get_predictor` for any model a model file may name, the RBF
network included: every one predicts with ``predict(theta_or_state, X)``, and its ``stateful``
flag says whether it takes a parameter vector (analytic models) or a stored state (the RBF
network, :mod:`fricid.models.rbf`; the hybrid of an analytic backbone and an RBF residual,
:mod:`fricid.models.hybrid`). Training them is :mod:`fricid.identify.rbf`'s and
:mod:`fricid.identify.hybrid`'s job.
"""

from __future__ import annotations

from ..errors import ConfigError
from ._analytic import CoulombViscous, LoadDependent, Stribeck, VelocityLoadTemperature
from ._asymmetric import Asymmetric
from ._base import INPUTS, FrictionModel, Parameter, data_scales
from .dahl import Dahl
from .hybrid import HYBRID, HybridModel
from .lugre import LuGre
from .rbf import NETWORK, RBFNetwork

__all__ = [
    "DYNAMIC",
    "INPUTS",
    "MODELS",
    "STATEFUL",
    "Asymmetric",
    "CoulombViscous",
    "FrictionModel",
    "LoadDependent",
    "Parameter",
    "RBFNetwork",
    "Stribeck",
    "VelocityLoadTemperature",
    "data_scales",
    "get_model",
    "get_predictor",
]


#: The analytic models by registry name, in the order of the BAS-RBFNN paper's Table 1.
MODELS: dict[str, type[FrictionModel]] = {
    cls.name: cls for cls in (CoulombViscous, Stribeck, LoadDependent, VelocityLoadTemperature)
}


#: Dynamic models by registry name (their ``predict`` is the steady state; identified from
#: trajectories by :mod:`fricid.identify.trajectory`); kept out of :data:`MODELS`, whose
#: families are fitted to friction samples.
DYNAMIC: dict[str, type[FrictionModel]] = {cls.name: cls for cls in (LuGre, Dahl)}


def get_model(name: str | FrictionModel, asymmetric: bool = False) -> FrictionModel:
    """The model called ``name`` (see :data:`MODELS`); ``name_asym`` or ``asymmetric=True``
    gives its per-direction variant. A model instance is passed through."""
    if isinstance(name, FrictionModel):
        model = name
    else:
        key = name.strip().lower()
        if key.endswith("_asym"):
            key, asymmetric = key[: -len("_asym")], True
        if key in DYNAMIC and not asymmetric:
            return DYNAMIC[key]()
        if key not in MODELS:
            raise ConfigError(
                f"unknown model '{name}'; choose one of: {', '.join(MODELS)} "
                "(append _asym for separate parameters per direction)"
            )
        model = MODELS[key]()
    if asymmetric and not model.is_asymmetric:
        model = Asymmetric(model)
    return model


#: Models that predict from a stored state rather than a parameter vector, by registry name.
STATEFUL: dict[str, RBFNetwork | HybridModel] = {NETWORK.name: NETWORK, HYBRID.name: HYBRID}


def get_predictor(name: str | FrictionModel) -> FrictionModel | RBFNetwork | HybridModel:
    """The model a model file names: an analytic model (:func:`get_model`) or a stateful one
    (:data:`STATEFUL`: ``"rbf"``, ``"hybrid"``).

    Either predicts with ``predict(theta_or_state, X)``; ``stateful`` tells which argument.
    """
    if isinstance(name, str) and name.strip().lower() in STATEFUL:
        return STATEFUL[name.strip().lower()]
    return get_model(name)
