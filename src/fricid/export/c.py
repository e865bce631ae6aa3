"""C99 code of any fitted model: one function, fit for a real-time loop.

:func:`c_code` returns a header and a source defining::

    double fricid_friction(double velocity, double load, double temperature);

friction torque [N m] at velocity [rad/s], joint load [N m] and temperature [degC], the same
function as :func:`fricid.models.smoothing.smooth_predict` (``FittedModel.predict`` without
smoothing). The code needs only ``<math.h>`` (link with ``-lm``), allocates nothing, keeps no
state and does no I/O; every parameter is a ``static const double`` written by
:func:`fricid.export._common.fmt_float` (``repr``: reads back bit for bit; NaN and inf are
refused). Every model family is supported: the analytic models (symmetric or per direction,
with or without the temperature term), the RBF network and the Gaussian process
(:mod:`fricid.export._c_gp`).

The expressions follow the Python models operation for operation, so the C function agrees
with ``FittedModel.predict`` to a few units in the last place (tests check 1e-12 relative).

Nothing from the model file is written as code: the header comment is the fixed-format
summary of :func:`fricid.export._common.summary_lines` (registry name, SHA-256, numbers, and
file text only through the escaper :func:`~fricid.export._common.plain`), followed by the
operating range of the identification data. With ``clamp=True`` (``fricid export --clamp``)
the function holds its inputs inside that range first (:mod:`fricid.export.clamp`).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import __version__
from ..fitted import FittedModel
from ..models import Asymmetric, WithTemperature
from ..models.smoothing import VISCOUS_TERM, Smoothing
from ._c_families import FAMILIES, TINY, base_family, no_c_template
from ._c_gp import gp_parts
from ._c_hybrid import hybrid_parts, tail_code
from ._c_temperature import ARRHENIUS_C, temperature_const
from ._common import (
    ExportError,
    check_identifier,
    fmt_float,
    plain,
    range_lines,
    summary_lines,
    write_lines_checked,
)
from .clamp import clamp_code

__all__ = ["CCode", "c_code", "export_c"]


@dataclass(frozen=True)
class CCode:
    """Generated C: ``header`` and ``source`` text, and their file names."""

    header_name: str
    source_name: str
    header: str
    source: str
    function: str


def _analytic_parts(fitted: FittedModel, smoothing: Smoothing) -> tuple[list[str], list[str]]:
    """(constant declarations, function definitions) of an analytic model."""
    model = fitted.friction_model()
    temp = isinstance(model, WithTemperature)  # the Arrhenius viscous term scales c by phi(T)
    asym = isinstance(model.inner if temp else model, Asymmetric)
    base = base_family(model)
    if why := no_c_template(fitted):
        raise ExportError(why)
    builder, guarded = FAMILIES[base.name]
    viscous = VISCOUS_TERM[base.name]
    theta = fitted.theta()
    d = base.n_params
    sides = [("pos", theta[:d]), ("neg", theta[d : 2 * d])] if asym else [("sym", theta[:d])]
    consts = [temperature_const(theta[-1])] if temp else []
    funcs: list[str] = []
    for side, values in sides:
        prefix = "" if side == "sym" else f"{side}_"
        params = dict(zip(base.param_names, values, strict=True))
        for par in base.parameters:
            what = par.description + (
                f" ({'positive' if side == 'pos' else 'negative'} direction)" if asym else ""
            )
            key = f"{par.name}_{side}" if asym else par.name
            consts.append(
                f"static const double {prefix}{par.name} = {fmt_float(params[par.name], key)};"
                f"  /* [{par.unit}] {what} */"
            )
        p = {f"{name}_guard": f"fmax(fabs({prefix}{name}), {fmt_float(TINY)})" for name in guarded}

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
        else f"tanh(velocity / {fmt_float(smoothing.zone, 'zone')})"
    )

    def term(side: str) -> str:
        prefix = "" if side == "sym" else f"{side}_"
        call = f"s * g_{side}(av, load, temperature)"
        phi = " * phi" if temp else ""
        return call if viscous is None else f"{call} + {prefix}{viscous}{phi} * velocity"

    core = [
        "/* The model: F = s G(|v|, load, T) + c v, s = "
        + ("tanh(v / zone)" if smoothing.kind == "tanh" else "sign(v)")
        + " */",
        "static double model(double velocity, double load, double temperature)\n{",
        f"    const double s = {sign};",
        "    const double av = fabs(velocity);",
        *([f"    const double phi = {ARRHENIUS_C};"] if temp else []),
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
        body = ", ".join(fmt_float(x, f"{name}[{i}]") for i, x in enumerate(values))
        return f"static const double {name}[{values.size}] = {{{body}}};  /* {what} */"
    rows = ",\n    ".join(
        "{" + ", ".join(fmt_float(x, f"{name}[{i}][{j}]") for j, x in enumerate(row)) + "}"
        for i, row in enumerate(values)
    )
    return (
        f"static const double {name}[{values.shape[0]}][{values.shape[1]}] = {{\n    {rows}\n}};"
        f"  /* {what} */"
    )


def _rbf_network(state: dict, side: str, magnitude: bool = False) -> tuple[list[str], str]:
    """Constants and the function ``net_<side>`` of one stored network, mirroring
    ``fricid.models.rbf`` (and ``fricid.models._rbf_core``) step by step."""
    pre = "rbf_" if side == "all" else f"rbf_{side}_"
    where = "state" if side == "all" else f"state.{side}"
    inputs = [str(name) for name in state["inputs"]]  # validated: velocity, load, temperature
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
        _array(f"{pre}shift", shift, f"input shift, inputs {', '.join(inputs)}"),
        _array(f"{pre}scale", scale, "input scale"),
        _array(f"{pre}centers", centers, "centres (standardised inputs)"),
        _array(f"{pre}cc", cc, "squared norm of each centre"),
        _array(f"{pre}inv", inv, "0.5 / sigma^2 of each neuron"),
        _array(f"{pre}weights", weights, "output weights [N m]"),
        f"static const double {pre}bias = {fmt_float(bias, f'{where}.bias')};"
        "  /* output bias [N m] */",
    ]
    if vscale is not None:
        consts.append(
            f"static const double {pre}velocity_scale = "
            f"{fmt_float(float(vscale), f'{where}.velocity_scale')};"
            "  /* [rad/s] velocity warped by asinh(v / scale) */"
        )
    tail_consts, tail_body = tail_code(state, pre, where, magnitude, _array)
    consts += tail_consts
    x0 = f"asinh(velocity / {pre}velocity_scale)" if vscale is not None else None
    picks = [x0 if (k == 0 and x0) else name for k, name in enumerate(inputs)]
    unused = [name for name in ("velocity", "load", "temperature") if name not in inputs]
    dot = " + ".join(f"z[{i}] * {pre}centers[j][{i}]" for i in range(d))
    zz = " + ".join(f"z[{i}] * z[{i}]" for i in range(d))
    what = {"all": "", "pos": ", v > 0", "neg": ", v < 0"}[side]
    body = (
        f"/* The RBF network{what} (BAS-RBFNN paper, eq. 14-15): standardised inputs z,\n"
        " * Gaussian units exp(-||z - c_j||^2 / (2 sigma_j^2)) with ||z - c_j||^2 computed as\n"
        " * max(||z||^2 + ||c_j||^2 - 2 z.c_j, 0) as in Python, linear output plus bias. */\n"
        f"static double net_{side}(double velocity, double load, double temperature)\n{{\n"
        + "".join(f"    (void){name};\n" for name in unused)
        + f"    double z[{d}];\n"
        "    double zz, acc = 0.0;\n"
        "    int j;\n"
        + "".join(
            f"    z[{i}] = ({pick} - {pre}shift[{i}]) / {pre}scale[{i}];\n"
            for i, pick in enumerate(picks)
        )
        + f"    zz = {zz};\n"
        f"    for (j = 0; j < {m}; ++j) {{\n"
        f"        const double dot = {dot};\n"
        f"        const double d2 = fmax(zz + {pre}cc[j] - 2.0 * dot, 0.0);\n"
        f"        acc += exp(-d2 * {pre}inv[j]) * {pre}weights[j];\n"
        "    }\n" + tail_body + "}\n"
    )
    return consts, body


def _rbf_parts(fitted: FittedModel, smoothing: Smoothing) -> tuple[list[str], list[str]]:
    """Constants and functions of the RBF network, with its sign as ``state["symmetry"]``
    says (:mod:`fricid.models.rbf`): ``sign(v) g(|v|)`` (odd or one direction), two constant
    sets and ``g_pos``/``g_neg`` per direction, or the network on signed velocity (legacy)."""
    from ..models import rbf

    state = fitted.state
    rbf.predict_state(state, np.zeros((1, 3)))  # validates the state (DataError if malformed)
    symmetry = rbf.symmetry_of(state)
    consts: list[str] = []
    funcs: list[str] = []
    for side, net in rbf.sub_networks(state).items():
        c, f = _rbf_network(dict(net), side, magnitude=symmetry != "signed")
        consts += c
        funcs.append(f)
    if symmetry == "signed":
        core = [
            "/* The model: the network on signed velocity (stored without a sign of its own) */",
            "static double model(double velocity, double load, double temperature)\n{",
            "    return net_all(velocity, load, temperature);",
        ]
    else:
        sign = (
            f"tanh(velocity / {fmt_float(smoothing.zone, 'zone')})"
            if smoothing.kind == "tanh"
            else "(double)((velocity > 0.0) - (velocity < 0.0))"
        )
        core = [
            "/* The model: friction opposes motion, F = s g(|v|, load, T), s = "
            + ("tanh(v / zone)" if smoothing.kind == "tanh" else "sign(v)")
            + (", g = g_pos for v > 0, g_neg for v < 0" if symmetry == "per_direction" else "")
            + " */",
            "static double model(double velocity, double load, double temperature)\n{",
            f"    const double s = {sign};",
            "    const double av = fabs(velocity);",
        ]
        if symmetry == "per_direction":
            core += [
                "    if (velocity > 0.0) return s * net_pos(av, load, temperature);",
                "    if (velocity < 0.0) return s * net_neg(av, load, temperature);",
                "    return 0.0;",
            ]
        else:
            core.append("    return s * net_all(av, load, temperature);")
    core.append("}\n")
    funcs.append("\n".join(core))
    return consts, funcs


# -- assembly ------------------------------------------------------------------------------------


def _linear_zone(zone: float) -> str:
    z = fmt_float(zone, "zone")
    return (
        f"    if (fabs(velocity) < {z}) {{\n"
        f"        const double edge = model(velocity >= 0.0 ? {z} : -{z}, load, temperature);\n"
        f"        return edge * fabs(velocity) / {z};\n"
        "    }\n"
    )


def _comment(lines: list[str]) -> str:
    """A C block comment of ``lines`` (fixed text, numbers and escaped text only)."""
    write_lines_checked(lines, ("*/", "/*", "??"))
    return "/*\n" + "".join(f" * {line}".rstrip() + "\n" for line in lines) + " */\n"


def c_code(
    fitted: FittedModel,
    smoothing: Smoothing | None = None,
    *,
    prefix: str = "fricid",
    source: str | None = None,
    sha256: str | None = None,
    clamp: bool = False,
) -> CCode:
    """C99 header and source for ``fitted`` (see the module docstring).

    Parameters
    ----------
    fitted : FittedModel
        Any fitted model.
    smoothing : Smoothing, optional
        Near zero velocity (:mod:`fricid.models.smoothing`); default none.
    prefix : str
        A C identifier (``[A-Za-z][A-Za-z0-9_]*``); the function is ``<prefix>_friction`` in
        ``<prefix>_friction.h`` and ``.c`` (change it to link several joints into one program).
    source : str, optional
        The model file's name, for the comment (escaped).
    sha256 : str, optional
        SHA-256 of the model file's bytes (:func:`fricid.export._common.file_sha256`); without
        it the comment gives the SHA-256 of the model's canonical JSON.
    clamp : bool
        Hold the inputs inside the model's operating range (module docstring).

    Returns
    -------
    CCode
        The header and source texts and their file names.

    Raises
    ------
    ExportError
        A model family without a C template, tanh smoothing of an RBF network stored on
        signed velocity, a bad prefix,
        ``clamp`` without a recorded operating range.
    DataError
        A non-finite number in the model (named), a malformed RBF state or operating range.
    """
    smoothing = smoothing or Smoothing()
    check_identifier(prefix)
    if (
        smoothing.kind == "tanh"
        and fitted.kind == "rbf"
        and (fitted.state or {}).get("symmetry", "signed") == "signed"
    ):
        raise ExportError(
            "tanh smoothing replaces sign(v) in a model of the form sign(v) G(|v|); this RBF "
            "network was stored on signed velocity and has no sign term: use --smooth "
            "linear, or none, or refit it"
        )
    if fitted.model == "hybrid":  # issue 15: analytic backbone + RBF residual
        consts, funcs = hybrid_parts(fitted, smoothing, _analytic_parts, _rbf_parts)
    elif fitted.model == "gp":
        consts, funcs = gp_parts(fitted, smoothing)
    else:
        parts = _rbf_parts if fitted.kind == "rbf" else _analytic_parts
        consts, funcs = parts(fitted, smoothing)
    function = f"{prefix}_friction"
    guard = f"{prefix.upper()}_FRICTION_H"
    header_name, source_name = f"{function}.h", f"{function}.c"
    if clamp:
        clamp_notes, clamp_body = clamp_code(fitted)
    else:
        clamp_notes = [
            "Inputs are not clamped: outside the operating range the model extrapolates "
            "(export with --clamp to hold them inside)."
        ]
        clamp_body = ""
    about = [
        f"Generated by fricid {plain(__version__)}; do not edit (re-export the model instead).",
        *summary_lines(fitted, source, sha256),
        "Units (SI): velocity [rad/s], load [N m], temperature [degC], friction [N m].",
        f"Smoothing near zero velocity: {smoothing.describe()}.",
        *range_lines(fitted),
        *clamp_notes,
        "Real-time safe: no allocation, no state, no I/O; needs only libm (link with -lm).",
    ]
    comment = _comment(about)
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
        + clamp_body
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
    sha256: str | None = None,
    clamp: bool = False,
) -> list[Path]:
    """Write ``<prefix>_friction.h`` and ``.c`` into ``out_dir`` (created if missing).

    Parameters are those of :func:`c_code`. Both files are generated before anything is
    written, then written through :func:`fricid.io.atomic.atomic_write` (each to a temporary
    file, both renamed only after both are complete), so an error leaves nothing
    half-written. Returns the paths written.
    """
    from ..io.atomic import atomic_write

    code = c_code(fitted, smoothing, prefix=prefix, source=source, sha256=sha256, clamp=clamp)
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise ExportError(
            f"--out {out} exists and is not a directory (the C export writes two files)"
        )
    paths = [out / code.header_name, out / code.source_name]
    for path in paths:
        if path.is_dir():
            raise ExportError(f"{path} is a directory; the C export writes a file there")
    with atomic_write(paths[0]) as fh_h, atomic_write(paths[1]) as fh_c:
        fh_h.write(code.header)
        fh_c.write(code.source)
    return paths
