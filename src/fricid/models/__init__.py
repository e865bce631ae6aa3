"""Friction models as mathematics: the analytic models of both papers and the learned ones.

Use :func:`get_model` to look an analytic model up by name (``"<name>_asym"`` gives the
per-direction variant, ``"<name>_temp"`` the Arrhenius viscous term of
:mod:`fricid.models._temperature`, ``"<name>_temp_asym"`` both), and :func:`get_predictor`
for any model a model file may name, the learned ones included: every one predicts with
``predict(theta_or_state, X)``, and its ``stateful`` flag says whether it takes a parameter
vector (analytic models) or a stored state (the RBF network, :mod:`fricid.models.rbf`; the
hybrid of an analytic backbone and an RBF residual, :mod:`fricid.models.hybrid`; the Gaussian
process, :mod:`fricid.models.gp`). Training them is :mod:`fricid.identify`'s job.
"""

from __future__ import annotations

from ..errors import ConfigError
from ._analytic import CoulombViscous, LoadDependent, Stribeck, VelocityLoadTemperature
from ._asymmetric import Asymmetric
from ._base import INPUTS, FrictionModel, Parameter, data_scales
from ._temperature import T_REF, WithTemperature
from .dahl import Dahl
from .gp import GP, GaussianProcess
from .hybrid import HYBRID, HybridModel
from .lugre import LuGre
from .rbf import NETWORK, RBFNetwork

__all__ = [
    "DYNAMIC",
    "INPUTS",
    "MODELS",
    "STATEFUL",
    "T_REF",
    "Asymmetric",
    "CoulombViscous",
    "FrictionModel",
    "GaussianProcess",
    "LoadDependent",
    "Parameter",
    "RBFNetwork",
    "Stribeck",
    "VelocityLoadTemperature",
    "WithTemperature",
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
    gives its per-direction variant, ``name_temp`` its temperature-dependent viscous term
    (:class:`WithTemperature`; ``name_temp_asym`` both, one activation temperature shared by
    the directions). A model instance is passed through."""
    if isinstance(name, FrictionModel):
        model = name
    else:
        key = name.strip().lower()
        if key.endswith("_asym"):
            key, asymmetric = key[: -len("_asym")], True
        if key in DYNAMIC and not asymmetric:
            return DYNAMIC[key]()
        temperature = key.endswith("_temp")
        if temperature:
            key = key[: -len("_temp")]
        if key not in MODELS:
            raise ConfigError(
                f"unknown model '{name}'; choose one of: {', '.join(MODELS)} "
                "(append _asym for separate parameters per direction, _temp for a "
                "temperature-dependent viscous term, _temp_asym for both)"
            )
        model = MODELS[key]()
        if temperature:
            return WithTemperature(Asymmetric(model) if asymmetric else model)
    if asymmetric and not model.is_asymmetric:
        if isinstance(model, WithTemperature):
            return WithTemperature(Asymmetric(model.inner))
        model = Asymmetric(model)
    return model


#: Models that predict from a stored state rather than a parameter vector, by registry name.
STATEFUL: dict[str, RBFNetwork | HybridModel | GaussianProcess] = {
    NETWORK.name: NETWORK,
    HYBRID.name: HYBRID,
    GP.name: GP,
}


def get_predictor(
    name: str | FrictionModel,
) -> FrictionModel | RBFNetwork | HybridModel | GaussianProcess:
    """The model a model file names: an analytic model (:func:`get_model`) or a stateful one
    (:data:`STATEFUL`: ``"rbf"``, ``"hybrid"``, ``"gp"``).

    Either predicts with ``predict(theta_or_state, X)``; ``stateful`` tells which argument.
    """
    if isinstance(name, str) and name.strip().lower() in STATEFUL:
        return STATEFUL[name.strip().lower()]
    return get_model(name)
