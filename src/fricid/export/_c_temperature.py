"""The Arrhenius viscous term of the ``*_temp`` models in C (:mod:`fricid.models._temperature`).

``phi = exp(e_t * (1 / (T + 273.15) - 1 / (T_ref + 273.15)))`` with the same operations, in
the same order, as :func:`fricid.models._temperature.arrhenius_factor`; the viscous term is
then ``c * phi * v`` as in ``WithTemperature._predict``.
"""

from __future__ import annotations

from ..models import T_REF
from ..models._base import KELVIN
from ._common import fmt_float

__all__ = ["ARRHENIUS_C", "temperature_const"]

#: The C expression of the factor: needs the constants of :func:`temperature_const`.
ARRHENIUS_C = f"exp(e_t * (1.0 / (temperature + {fmt_float(KELVIN)}) - inv_t_ref))"


def temperature_const(e_t: float) -> str:
    """The constants of the factor: the activation temperature and ``1 / (T_ref + 273.15)``."""
    inv_ref = 1.0 / (T_REF + KELVIN)
    return (
        f"static const double e_t = {fmt_float(float(e_t), 'e_t')};  /* [K] activation "
        "temperature of the viscous term (Arrhenius) */\n"
        f"static const double inv_t_ref = {fmt_float(inv_ref)};  /* [1/K] "
        f"1 / ({T_REF:g} degC + 273.15): the viscous coefficients hold there */"
    )
