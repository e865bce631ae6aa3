"""C99 code of any fitted model: one function, fit for a real-time loop.

:func:`c_code` returns a header and a source defining::

    double fricid_friction(double velocity, double load, double temperature);

friction torque [N m] at velocity [rad/s], joint load [N m] and temperature [degC], the same
function as :func:`fricid.export.smoothing.smooth_predict` (``FittedModel.predict`` without
smoothing). The code needs only ``<math.h>`` (link with ``-lm``), allocates nothing, keeps no
state and does no I/O; every parameter is a ``static const double`` written with 17
significant digits, so it reads back bit for bit. Every model family is supported: the
analytic models (symmetric or per direction) and the RBF network.

The expressions follow the Python models operation for operation, so the C function agrees
with ``FittedModel.predict`` to a few units in the last place (tests check 1e-12 relative).
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import __version__
from ..fitted import FittedModel
from ..models import Asymmetric
from ._common import ExportError, describe_model, fmt_float
from .smoothing import VISCOUS_TERM, Smoothing

__all__ = ["CCode", "c_code", "export_c"]

_TINY = 1e-12  # the guard of fricid.models._analytic
_IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


@dataclass(frozen=True)
class CCode:
    """Generated C: ``header`` and ``source`` text, and their file names."""

    header_name: str
    source_name: str
    header: str
    source: str
    function: str


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
        f"{fmt_float(_TINY)});",
        f"const double viscous = ({g('f_v0')} + {g('f_vT')} * temperature) * "
        "(1.0 - exp(-av / denom));",
        "return coulomb + viscous;",
    ]


_FAMILIES: dict[str, tuple[Callable, tuple[str, ...]]] = {
    # family: (G body builder, parameters guarded by max(|x|, 1e-12) as in the Python model)
    "coulomb_viscous": (_g_coulomb_viscous, ()),
    "stribeck": (_g_stribeck, ("w_s",)),
    "msk": (_g_msk, ("v_s",)),
    "vlt": (_g_vlt, ("v_tl0",)),
}


def _analytic_parts(fitted: FittedModel, smoothing: Smoothing) -> tuple[list[str], list[str]]:
    """(constant declarations, function definitions) of an analytic model."""
    model = fitted.friction_model()
    asym = isinstance(model, Asymmetric)
    base = model.base if asym else model
    if base.name not in _FAMILIES or base.name not in VISCOUS_TERM:
        raise ExportError(
            f"the C export has no template for the model family '{base.name}' (it knows "
            f"{', '.join(_FAMILIES)} and rbf); nothing was written"
        )
    builder, guarded = _FAMILIES[base.name]
    viscous = VISCOUS_TERM[base.name]
    theta = fitted.theta()
    d = base.n_params
    sides = [("pos", theta[:d]), ("neg", theta[d:])] if asym else [("sym", theta)]
    consts: list[str] = []
    funcs: list[str] = []
    for side, values in sides:
        prefix = "" if side == "sym" else f"{side}_"
        params = dict(zip(base.param_names, values, strict=True))
        for par in base.parameters:
            what = par.description + (
                f" ({'positive' if side == 'pos' else 'negative'} direction)" if asym else ""
            )
            consts.append(
                f"static const double {prefix}{par.name} = {fmt_float(params[par.name])};"
                f"  /* [{par.unit}] {what} */"
            )
        p = {f"{name}_guard": f"fmax(fabs({prefix}{name}), {fmt_float(_TINY)})" for name in guarded}

        def g(name: str, prefix: str = prefix) -> str:
            return f"{prefix}{name}"

        body = builder(p, g)
        unused = [
            x
            for x in ("av", "load", "temperature")
            if not any(re.search(rf"\b{x}\b", line) for line in body)
        ]
        funcs.append(
            f"/* G(|v|, load, T) of the {base.title} model"
            + (f", {'positive' if side == 'pos' else 'negative'} direction" if asym else "")
            + " */\n"
            f"static double g_{side}(double av, double load, double temperature)\n{{\n"
            + "".join(f"    (void){x};\n" for x in unused)
            + "".join(f"    {line}\n" for line in body)
            + "}\n"
        )
    sign = (
        "(double)((velocity > 0.0) - (velocity < 0.0))"
        if smoothing.kind != "tanh"
        else f"tanh(velocity / {fmt_float(smoothing.zone)})"
    )

    def term(side: str) -> str:
        prefix = "" if side == "sym" else f"{side}_"
        call = f"s * g_{side}(av, load, temperature)"
        return call if viscous is None else f"{call} + {prefix}{viscous} * velocity"

    core = [
        "/* The model: F = s G(|v|, load, T) + c v, s = "
        + ("tanh(v / zone)" if smoothing.kind == "tanh" else "sign(v)")
        + " */",
        "static double model(double velocity, double load, double temperature)\n{",
        f"    const double s = {sign};",
        "    const double av = fabs(velocity);",
    ]
    if asym:
        core += [
            f"    if (velocity >= 0.0) return {term('pos')};",
            f"    return {term('neg')};",
        ]
    else:
        core.append(f"    return {term('sym')};")
    core.append("}\n")
    funcs.append("\n".join(core))
    return consts, funcs


# -- the RBF network -----------------------------------------------------------------------------


def _array(name: str, values: np.ndarray, what: str) -> str:
    values = np.asarray(values, dtype=float)
    if values.ndim == 1:
        body = ", ".join(fmt_float(x) for x in values)
        return f"static const double {name}[{values.size}] = {{{body}}};  /* {what} */"
    rows = ",\n    ".join("{" + ", ".join(fmt_float(x) for x in row) + "}" for row in values)
    return (
        f"static const double {name}[{values.shape[0]}][{values.shape[1]}] = {{\n    {rows}\n}};"
        f"  /* {what} */"
    )


def _rbf_parts(fitted: FittedModel) -> tuple[list[str], list[str]]:
    """Constants and the model function of the RBF network, mirroring
    ``fricid.models.rbf.predict_state`` (and ``fricid.models._rbf_core``) step by step."""
    from ..models import rbf

    state = fitted.state
    rbf.predict_state(state, np.zeros((1, 3)))  # validates the state (DataError if malformed)
    inputs = list(state["inputs"])
    shift = np.asarray(state["input_shift"], dtype=float)
    scale = np.asarray(state["input_scale"], dtype=float)
    centers = np.asarray(state["centers"], dtype=float)
    widths = np.asarray(state["widths"], dtype=float)
    weights = np.asarray(state["weights"], dtype=float)
    bias = float(state["bias"])
    vscale = state.get("velocity_scale")
    m, d = centers.shape
    # the same operations as _rbf_core: ||c||^2 by einsum, 0.5 / sigma^2
    cc = np.einsum("md,md->m", centers, centers)
    inv = 0.5 / np.square(widths)
    consts = [
        _array("rbf_shift", shift, f"input shift, inputs {', '.join(inputs)}"),
        _array("rbf_scale", scale, "input scale"),
        _array("rbf_centers", centers, "centres (standardised inputs)"),
        _array("rbf_cc", cc, "squared norm of each centre"),
        _array("rbf_inv", inv, "0.5 / sigma^2 of each neuron"),
        _array("rbf_weights", weights, "output weights [N m]"),
        f"static const double rbf_bias = {fmt_float(bias)};  /* output bias [N m] */",
    ]
    if vscale is not None:
        consts.append(
            f"static const double rbf_velocity_scale = {fmt_float(float(vscale))};"
            "  /* [rad/s] velocity warped by asinh(v / scale) */"
        )
    raw = {"velocity": "velocity", "load": "load", "temperature": "temperature"}
    x0 = "asinh(velocity / rbf_velocity_scale)" if vscale is not None else None
    picks = [x0 if (k == 0 and x0) else raw[name] for k, name in enumerate(inputs)]
    unused = [name for name in ("velocity", "load", "temperature") if name not in inputs]
    dot = " + ".join(f"z[{i}] * rbf_centers[j][{i}]" for i in range(d))
    zz = " + ".join(f"z[{i}] * z[{i}]" for i in range(d))
    body = (
        "/* The RBF network (BAS-RBFNN paper, eq. 14-15): standardised inputs z, Gaussian\n"
        " * units exp(-||z - c_j||^2 / (2 sigma_j^2)) with ||z - c_j||^2 computed as\n"
        " * max(||z||^2 + ||c_j||^2 - 2 z.c_j, 0) as in Python, linear output plus bias. */\n"
        "static double model(double velocity, double load, double temperature)\n{\n"
        + "".join(f"    (void){name};\n" for name in unused)
        + f"    double z[{d}];\n"
        "    double zz, acc = 0.0;\n"
        "    int j;\n"
        + "".join(
            f"    z[{i}] = ({pick} - rbf_shift[{i}]) / rbf_scale[{i}];\n"
            for i, pick in enumerate(picks)
        )
        + f"    zz = {zz};\n"
        f"    for (j = 0; j < {m}; ++j) {{\n"
        f"        const double dot = {dot};\n"
        "        const double d2 = fmax(zz + rbf_cc[j] - 2.0 * dot, 0.0);\n"
        "        acc += exp(-d2 * rbf_inv[j]) * rbf_weights[j];\n"
        "    }\n"
        "    return acc + rbf_bias;\n"
        "}\n"
    )
    return consts, [body]


# -- assembly ------------------------------------------------------------------------------------


def _linear_zone(zone: float) -> str:
    z = fmt_float(zone)
    return (
        f"    if (fabs(velocity) < {z}) {{\n"
        f"        const double fp = model({z}, load, temperature);\n"
        f"        const double fm = model(-{z}, load, temperature);\n"
        f"        return fm + (fp - fm) * (velocity + {z}) / (2.0 * {z});\n"
        "    }\n"
    )


def c_code(
    fitted: FittedModel,
    smoothing: Smoothing | None = None,
    *,
    prefix: str = "fricid",
    source: str | None = None,
) -> CCode:
    """C99 header and source for ``fitted`` (see the module docstring).

    Parameters
    ----------
    fitted : any fitted model.
    smoothing : near zero velocity (:mod:`fricid.export.smoothing`); default none.
    prefix : C identifier; the function is ``<prefix>_friction`` in ``<prefix>_friction.h``
        and ``.c`` (change it to link several joints into one program).
    source : the model file's name, for the comment.

    Raises
    ------
    ExportError
        A model family without a C template, tanh smoothing of the RBF network, a bad prefix.
    """
    smoothing = smoothing or Smoothing()
    if not _IDENT.match(prefix):
        raise ExportError(f"prefix {prefix!r} is not a C identifier ([A-Za-z_][A-Za-z0-9_]*)")
    if smoothing.kind == "tanh" and fitted.kind == "rbf":
        raise ExportError(
            "tanh smoothing replaces sign(v) in an analytic model; the RBF network has no sign "
            "term (it is continuous already): use --smooth linear, or none"
        )
    consts, funcs = (
        _rbf_parts(fitted) if fitted.kind == "rbf" else _analytic_parts(fitted, smoothing)
    )
    function = f"{prefix}_friction"
    guard = f"{prefix.upper()}_FRICTION_H"
    header_name, source_name = f"{function}.h", f"{function}.c"
    about = [
        f"Generated by fricid {__version__}; do not edit (re-export the model instead).",
        *describe_model(fitted, source),
        "Units (SI): velocity [rad/s], load [N m], temperature [degC], friction [N m].",
        f"Smoothing near zero velocity: {smoothing.describe()}.",
        "Real-time safe: no allocation, no state, no I/O; needs only libm (link with -lm).",
    ]
    comment = "/*\n" + "".join(f" * {line}\n" for line in about) + " */\n"
    header = (
        comment + f"#ifndef {guard}\n#define {guard}\n\n"
        '#ifdef __cplusplus\nextern "C" {\n#endif\n\n'
        "/* Friction torque [N m] of the joint at velocity [rad/s], joint load [N m] and\n"
        " * temperature [degC]. It opposes motion: add it to the motor torque command as\n"
        " * feed-forward. Inputs a model does not use are ignored. */\n"
        f"double {function}(double velocity, double load, double temperature);\n\n"
        "#ifdef __cplusplus\n}\n#endif\n\n"
        f"#endif /* {guard} */\n"
    )
    body = "    return model(velocity, load, temperature);\n"
    if smoothing.kind == "linear":
        body = _linear_zone(smoothing.zone) + body
    src = (
        comment
        + f'#include "{header_name}"\n\n#include <math.h>\n\n'
        + "\n".join(consts)
        + "\n\n"
        + "\n".join(funcs)
        + f"\ndouble {function}(double velocity, double load, double temperature)\n{{\n"
        + body
        + "}\n"
    )
    return CCode(header_name, source_name, header, src, function)


def export_c(
    fitted: FittedModel,
    out_dir: str | os.PathLike[str],
    smoothing: Smoothing | None = None,
    *,
    prefix: str = "fricid",
    source: str | None = None,
) -> list[Path]:
    """Write ``<prefix>_friction.h`` and ``.c`` into ``out_dir`` (created if missing).

    Both files are generated before anything is written, then each is written atomically, so
    an error leaves nothing half-written. Returns the paths written.
    """
    from ..io.atomic import atomic_write

    code = c_code(fitted, smoothing, prefix=prefix, source=source)
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise ExportError(
            f"--out {out} exists and is not a directory (the C export writes two files)"
        )
    paths = [out / code.header_name, out / code.source_name]
    with atomic_write(paths[0]) as fh_h, atomic_write(paths[1]) as fh_c:
        fh_h.write(code.header)
        fh_c.write(code.source)
    return paths
