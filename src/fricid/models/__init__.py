"""Friction models: the analytic models of both papers (and, later, the RBF network).

Use :func:`get_model` to look one up by name; ``"<name>_asym"`` gives the per-direction variant.
"""

from __future__ import annotations

from ..errors import ConfigError
from ._analytic import CoulombViscous, LoadDependent, Stribeck, VelocityLoadTemperature
from ._asymmetric import Asymmetric
from ._base import INPUTS, FrictionModel, Parameter, data_scales

__all__ = [
    "INPUTS",
    "MODELS",
    "Asymmetric",
    "CoulombViscous",
    "FrictionModel",
    "LoadDependent",
    "Parameter",
    "RBFNetRegressor",
    "Stribeck",
    "VelocityLoadTemperature",
    "data_scales",
    "get_model",
]


def __getattr__(name: str):
    # the RBF network needs scikit-learn; import it only when asked for (fast CLI start-up)
    if name == "RBFNetRegressor":
        from .rbf import RBFNetRegressor

        return RBFNetRegressor
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


#: The analytic models by registry name, in the order of the BAS-RBFNN paper's Table 1.
MODELS: dict[str, type[FrictionModel]] = {
    cls.name: cls for cls in (CoulombViscous, Stribeck, LoadDependent, VelocityLoadTemperature)
}


def get_model(name: str | FrictionModel, asymmetric: bool = False) -> FrictionModel:
    """The model called ``name`` (see :data:`MODELS`); ``name_asym`` or ``asymmetric=True``
    gives its per-direction variant. A model instance is passed through."""
    if isinstance(name, FrictionModel):
        model = name
    else:
        key = name.strip().lower()
        if key.endswith("_asym"):
            key, asymmetric = key[: -len("_asym")], True
        if key not in MODELS:
            raise ConfigError(
                f"unknown model '{name}'; choose one of: {', '.join(MODELS)} "
                "(append _asym for separate parameters per direction)"
            )
        model = MODELS[key]()
    if asymmetric and not model.is_asymmetric:
        model = Asymmetric(model)
    return model
