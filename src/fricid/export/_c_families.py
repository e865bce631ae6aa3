"""The analytic families' G(|v|, load, T) in C for :mod:`fricid.export.c`, operation for
operation as in :mod:`fricid.models._analytic`, and which models the C export has a template
for (:func:`no_c_template`)."""

from __future__ import annotations

from collections.abc import Callable

from ..fitted import FittedModel
from ..models import Asymmetric, WithTemperature
from ..models.smoothing import VISCOUS_TERM
from ._common import fmt_float

__all__ = ["FAMILIES", "TINY", "base_family", "no_c_template"]

TINY = 1e-12  # the guard of fricid.models._analytic


# -- analytic families: G(|v|, load, T) in C, operation for operation as in _analytic.py --------


def _g_coulomb_viscous(p: dict[str, str], g: Callable[[str], str]) -> list[str]:
    return [f"return {g('f_c')};"]


def _g_stribeck(p: dict[str, str], g: Callable[[str], str]) -> list[str]:
    return [
        f"const double a = av / {p['w_s_guard']};",
        f"return {g('tau_c')} + ({g('tau_s')} - {g('tau_c')}) * exp(-pow(a, {g('delta')}));",
    ]


def _g_msk(p: dict[str, str], g: Callable[[str], str]) -> list[str]:
    return [
        "const double al = fabs(load);",
        f"const double a = av / {p['v_s_guard']};",
        f"return {g('f_c')} + {g('f_ck')} * al + ({g('f_s')} - {g('f_c')} + "
        f"({g('f_sk')} - {g('f_ck')}) * al) * exp(-pow(a, {g('xi')}));",
    ]


def _g_vlt(p: dict[str, str], g: Callable[[str], str]) -> list[str]:
    return [
        f"const double coulomb = {g('f_c')} + ({g('f_ctl')} + {g('f_stl')} * "
        f"exp(-av / {p['v_tl0_guard']})) * fabs(load);",
        f"const double denom = fmax(fabs({g('v_v0')} + {g('v_vT')} * temperature), "
        f"{fmt_float(TINY)});",
        f"const double viscous = ({g('f_v0')} + {g('f_vT')} * temperature) * "
        "(1.0 - exp(-av / denom));",
        "return coulomb + viscous;",
    ]


FAMILIES: dict[str, tuple[Callable, tuple[str, ...]]] = {
    # family: (G body builder, parameters guarded by max(|x|, 1e-12) as in the Python model)
    "coulomb_viscous": (_g_coulomb_viscous, ()),
    "stribeck": (_g_stribeck, ("w_s",)),
    "msk": (_g_msk, ("v_s",)),
    "vlt": (_g_vlt, ("v_tl0",)),
}


def no_c_template(fitted: FittedModel) -> str:
    """Why the C export cannot write ``fitted``, "" when it can (said before a check that
    would send the user to a flag that cannot help)."""
    if fitted.model in ("hybrid", "gp") or fitted.kind == "rbf":
        return ""
    name = base_family(fitted.friction_model()).name
    return (
        ""
        if name in FAMILIES and name in VISCOUS_TERM
        else (
            f"the C export has no template for the model family '{name}' (it knows "
            f"{', '.join(FAMILIES)}, rbf, hybrid and gp); nothing was written; a dynamic model "
            "exports --to mjcf (MuJoCo's friction), yaml or urdf (its Coulomb-viscous projection)"
        )
    )


def base_family(model):
    """The analytic family under a model's temperature law and per-direction split."""
    inner = model.inner if isinstance(model, WithTemperature) else model
    return inner.base if isinstance(inner, Asymmetric) else inner
