"""Temperature as an option of any analytic family with a viscous term.

The viscous friction of a lubricated joint follows the viscosity of its lubricant, which falls
steeply with temperature. :class:`WithTemperature` scales the viscous coefficient ``c`` of a
model of the form ``sign(v) G(|v|, load) + c v`` (``FrictionModel.viscous``) by the
Arrhenius-Andrade law of liquid viscosity,

``c(T) = c_ref * exp(e_t * (1 / (T + 273.15) - 1 / (T_ref + 273.15)))``

with ``T`` in degC, the reference temperature ``T_ref`` = :data:`T_REF` = 40 degC (where ISO
3448 defines a lubricant's viscosity grade) and the activation temperature ``e_t = E_a / R``
[K] identified from the data (``e_t > 0``: the viscous term falls as the joint warms). The
Coulomb and Stribeck terms keep the base model's form.

Direction and temperature are options of one family, not one class per combination: the
wrapper takes a symmetric model or its :class:`~fricid.models.Asymmetric` variant, so
``stribeck_temp`` is ``WithTemperature(Stribeck())`` and ``stribeck_temp_asym`` is
``WithTemperature(Asymmetric(Stribeck()))``: per-direction Coulomb, Stribeck and viscous
levels, one activation temperature for both directions (one lubricant). The base model's
parameter vector comes first, unchanged, then ``e_t``.

``e_t`` is determined only by data at two or more temperatures; with one temperature
:func:`fricid.identify.fit` says so (``IdentifiabilityWarning``, the ``"activation"``
parameter kind counts as a temperature parameter). Its bounds scale with the data: they are
multiples of ``1 / (1/T_min - 1/T_max)`` (kelvin), so they bound the log of the viscosity
ratio across the measured temperatures to ``[-2, 8]`` (:func:`fricid.models.data_scales`).

References
----------
E. N. da C. Andrade, "The viscosity of liquids", Nature 125, 309-310, 1930 (the law
``eta = A exp(B / T)``).
A. C. Bittencourt and S. Gunnarsson, "Static friction in a robot joint -- modeling and
identification of load and temperature effects", J. Dyn. Sys., Meas., Control 134(5), 2012
(temperature acts mainly on the viscous, velocity-strengthening part of joint friction).
ISO 3448:1992, industrial liquid lubricants -- ISO viscosity classification (grades at 40 degC).
"""

from __future__ import annotations

import numpy as np

from ..errors import ConfigError
from ._asymmetric import Asymmetric
from ._base import KELVIN, FrictionModel, Parameter

__all__ = ["ACTIVATION", "T_REF", "WithTemperature", "arrhenius_factor"]

#: Reference temperature [degC] of the viscous coefficient of a temperature model.
T_REF = 40.0

#: The parameter a temperature model adds, after the base model's.
ACTIVATION = Parameter(
    "e_t",
    "K",
    "activation",
    0.0,
    -2.0,
    8.0,
    f"activation temperature of the viscous term (Arrhenius, reference {T_REF:g} degC)",
)


def arrhenius_factor(e_t, temperature) -> np.ndarray:
    """``exp(e_t (1 / (T + 273.15) - 1 / (T_ref + 273.15)))``: the viscous coefficient at
    ``temperature`` [degC] over the one at :data:`T_REF`, for activation temperatures
    ``e_t`` [K] (broadcast)."""
    inv = 1.0 / (np.asarray(temperature, dtype=float) + KELVIN) - 1.0 / (T_REF + KELVIN)
    return np.exp(np.asarray(e_t, dtype=float) * inv)


class WithTemperature(FrictionModel):
    """``inner`` with its viscous coefficient(s) scaled by :func:`arrhenius_factor`.

    Parameters
    ----------
    inner : FrictionModel
        An analytic model with a viscous term (``inner.viscous``), symmetric or
        :class:`~fricid.models.Asymmetric` (module notes).

    Raises
    ------
    ConfigError
        A model without a viscous term (``vlt`` has temperature terms of its own), or one that
        already has a temperature law.
    """

    def __init__(self, inner: FrictionModel) -> None:
        base = inner.base if isinstance(inner, Asymmetric) else inner
        if isinstance(base, WithTemperature) or base.viscous is None:
            raise ConfigError(
                f"model '{inner.name}' has no viscous term a temperature law can scale "
                "(temperature applies to coulomb_viscous, stribeck and msk, symmetric or _asym)"
            )
        self.inner = inner
        self.name = f"{base.name}_temp" + ("_asym" if inner.is_asymmetric else "")
        self.title = f"{base.title}, Arrhenius viscous term" + (
            ", per direction" if inner.is_asymmetric else ""
        )
        self.equation = f"{base.equation}; viscous term after Andrade (1930)"
        self.inputs = tuple(dict.fromkeys((*base.inputs, "temperature")))
        self.parameters = (*inner.parameters, ACTIVATION)
        self.linear_params = tuple(getattr(inner, "linear_params", ()))
        suffixes = ("_pos", "_neg") if inner.is_asymmetric else ("",)
        #: The names of the viscous coefficients: one, or ``_pos`` and ``_neg``.
        self.viscous_names = tuple(f"{base.viscous}{s}" for s in suffixes)
        self._viscous_index = [inner.param_names.index(n) for n in self.viscous_names]

    @property
    def is_asymmetric(self) -> bool:
        return self.inner.is_asymmetric

    def split(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(inner theta without viscous, viscous coefficients, e_t)`` of a batch ``(k, d)``:
        shapes ``(k, d - 1)``, ``(k, 1 or 2)`` (``_pos`` then ``_neg``), ``(k, 1)``."""
        inner = theta[:, :-1].copy()
        c = inner[:, self._viscous_index].copy()
        inner[:, self._viscous_index] = 0.0
        return inner, c, theta[:, -1:]

    def _predict(self, theta, X):
        inner, c, e_t = self.split(theta)
        g = self.inner._predict(inner, X)  # sign(v) G(|v|, load, T): viscous set to zero
        v = X[None, :, 0]
        phi = arrhenius_factor(e_t, X[None, :, 2])
        c_v = np.where(v >= 0, c[:, :1], c[:, -1:])
        return g + c_v * phi * v
