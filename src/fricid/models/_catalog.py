"""The analytic and dynamic model registries and :func:`get_model` (re-exported by
:mod:`fricid.models`), in a module of their own so that the stateful models (the hybrid's
backbone) can look a family up without importing the package that registers them."""

from __future__ import annotations

import difflib
from collections.abc import Mapping, Sequence

from ..errors import ConfigError
from ._analytic import CoulombViscous, LoadDependent, Stribeck, VelocityLoadTemperature
from ._asymmetric import Asymmetric
from ._base import FrictionModel
from ._temperature import WithTemperature
from .dahl import Dahl
from .lugre import LuGre, LuGreAsym

__all__ = ["DYNAMIC", "MODELS", "get_model", "unknown_model"]


#: The analytic models by registry name, in the order of the BAS-RBFNN paper's Table 1.
MODELS: dict[str, type[FrictionModel]] = {
    cls.name: cls for cls in (CoulombViscous, Stribeck, LoadDependent, VelocityLoadTemperature)
}


#: Dynamic models by registry name (their ``predict`` is the steady state; identified from
#: trajectories by :mod:`fricid.identify.dynamic.trajectory`); kept out of :data:`MODELS`, whose
#: families are fitted to friction samples.
DYNAMIC: dict[str, type[FrictionModel]] = {cls.name: cls for cls in (LuGre, LuGreAsym, Dahl)}


def unknown_model(name: str, more: Mapping[str, Sequence[str]] | None = None) -> str:
    """The message for a model name that is none: every family by kind (``more``: the
    kinds a caller adds, e.g. the learned ones) and the nearest known name."""
    kinds = {
        "analytic": list(MODELS),
        "dynamic, from a trajectory": list(DYNAMIC),
        **{k: list(v) for k, v in (more or {}).items()},
    }
    known = [n for names in kinds.values() for n in names]
    known += [f"{n}_{end}" for n in MODELS for end in ("asym", "temp")]
    near = difflib.get_close_matches(name.strip().lower(), known, n=1)
    hint = f" (did you mean '{near[0]}'?)" if near else ""
    listed = "; ".join(f"{kind}: {', '.join(names)}" for kind, names in kinds.items())
    return (
        f"unknown model '{name}'{hint}; choose one of {listed} (an analytic name takes _asym "
        "for separate parameters per direction, _temp for a temperature-dependent viscous "
        "term, _temp_asym for both)"
    )


def get_model(name: str | FrictionModel, asymmetric: bool = False) -> FrictionModel:
    """The model called ``name`` (see :data:`MODELS`); ``name_asym`` or ``asymmetric=True``
    gives its per-direction variant, ``name_temp`` its temperature-dependent viscous term
    (:class:`WithTemperature`; ``name_temp_asym`` both, one activation temperature shared by
    the directions). The dynamic models (:data:`DYNAMIC`) by name; ``lugre_asym`` is LuGre
    with its levels per direction. A model instance is passed through."""
    if isinstance(name, FrictionModel):
        model = name
    else:
        key = name.strip().lower()
        if asymmetric and key in DYNAMIC and not key.endswith("_asym"):
            key += "_asym"
        if key in DYNAMIC:
            return DYNAMIC[key]()
        if key.endswith("_asym"):
            key, asymmetric = key[: -len("_asym")], True
        if key in DYNAMIC:  # dahl_asym: no such model
            raise ConfigError(
                f"'{name}': {key} has one level for both directions (per direction: "
                f"{', '.join(k for k in DYNAMIC if k.endswith('_asym'))})"
            )
        temperature = key.endswith("_temp")
        if temperature:
            key = key[: -len("_temp")]
        if key not in MODELS:
            raise ConfigError(unknown_model(name))
        model = MODELS[key]()
        if temperature:
            return WithTemperature(Asymmetric(model) if asymmetric else model)
    if asymmetric and not model.is_asymmetric:
        if isinstance(model, WithTemperature):
            return WithTemperature(Asymmetric(model.inner))
        model = Asymmetric(model)
    return model
