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

from ._analytic import CoulombViscous, LoadDependent, Stribeck, VelocityLoadTemperature
from ._asymmetric import Asymmetric
from ._base import INPUTS, FrictionModel, Parameter, data_scales
from ._catalog import DYNAMIC, MODELS, get_model, unknown_model
from ._temperature import T_REF, WithTemperature
from .gp import GP, GaussianProcess
from .hybrid import HYBRID, HybridModel
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
    "unknown_model",
]


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
