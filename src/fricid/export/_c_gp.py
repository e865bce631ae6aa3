"""The Gaussian-process model in C: its posterior mean as a kernel sum over the stored points.

Mirrors :mod:`fricid.models.gp` step by step: the prior mean (linear in |v|, |load|, T and
|v| T, |load| and T held to their measured range), the inputs (|v|, |load|, T) warped
(``asinh(|v| / velocity_scale)``), standardised and divided by the length scales, squared
distances as ``max(||z||^2 + ||p||^2 - 2 z.p, 0)``, and ``mean + y_scale * sum_j s2
exp(-0.5 d2_j) alpha_j``. The points divided by the length scales
and their squared norms are computed here once, in Python, with the operations the Python
model uses, and written as constants. The standard deviation is not exported (a controller
needs the friction); every number goes through :func:`fricid.export._common.fmt_float`, and
nothing from the file becomes code (input names are checked against the fixed three).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ..fitted import FittedModel
from ..models.gp import gp_sides, predict_gp
from ..models.smoothing import Smoothing
from ._common import fmt_float

__all__ = ["gp_parts"]

_ARGS = {"velocity": "av", "load": "load", "temperature": "temperature"}
_WHERE = {"all": "", "pos": ", v > 0", "neg": ", v < 0"}


def _numbers(name: str, values: Any, what: str) -> str:
    """A ``static const double`` array (1-D or 2-D) of ``values``, each by ``fmt_float``."""
    arr = np.asarray(values, dtype=float)
    dims = "".join(f"[{k}]" for k in arr.shape)
    flat = [fmt_float(float(x), f"{name}{list(i)}") for i, x in np.ndenumerate(arr)]
    if arr.ndim == 2:
        width = arr.shape[1]
        rows = ["{" + ", ".join(flat[i : i + width]) + "}" for i in range(0, len(flat), width)]
        body = ",\n    ".join(rows)
    else:
        body = ", ".join(flat)
    return f"static const double {name}{dims} = {{\n    {body}\n}};  /* {what} */"


def _side(st: Mapping[str, Any], side: str) -> tuple[list[str], str]:
    """Constants and the function ``gp_<side>(av, load, temperature)`` of one process."""
    pre = f"gp_{side}_"
    inputs = [str(x) for x in st["inputs"]]  # validated by predict_gp: the three names only
    lengths = np.asarray(st["length_scales"], dtype=float)
    P = np.asarray(st["points"], dtype=float) / lengths
    pp = np.einsum("md,md->m", P, P)
    coef = np.asarray(st["mean_coef"], dtype=float)
    m, d = P.shape
    consts = [
        _numbers(f"{pre}shift", st["input_shift"], f"input shift, inputs {', '.join(inputs)}"),
        _numbers(f"{pre}scale", st["input_scale"], "input scale"),
        _numbers(f"{pre}len", lengths, "ARD length scales (standardised inputs)"),
        _numbers(f"{pre}points", P, "stored points over the length scales"),
        _numbers(f"{pre}pp", pp, "squared norm of each point"),
        _numbers(f"{pre}alpha", st["alpha"], "weight of each point"),
        _numbers(f"{pre}mean", coef, "prior mean: constant, per input, |v| T [N m ...]"),
    ]
    scalars = {"vscale": "velocity_scale", "s2": "signal_var", "y_scale": "y_scale"}
    for short, key in scalars.items():
        consts.append(
            f"static const double {pre}{short} = {fmt_float(float(st[key]), key)};  /* {key} */"
        )
    raw = ["fabs(load)" if name == "load" else _ARGS[name] for name in inputs]
    warped = [f"asinh(av / {pre}vscale)", *raw[1:]]
    held = list(raw)  # the mean's basis: |load| and T held to their measured range
    if "mean_bounds" in st:
        pairs = [[fmt_float(float(x), "mean_bounds") for x in p] for p in st["mean_bounds"]]
        held[1:] = [
            f"fmin(fmax({a}, {lo}), {hi})" for a, (lo, hi) in zip(raw[1:], pairs[1:], strict=True)
        ]
    mean = " + ".join(f"{a} * {pre}mean[{i + 1}]" for i, a in enumerate(held))
    if len(coef) == d + 2:
        mean += f") + {pre}mean[{d + 1}] * (av * {held[inputs.index('temperature')]}"
    unused = [x for name, x in _ARGS.items() if name not in inputs]
    dot = " + ".join(f"z[{i}] * {pre}points[j][{i}]" for i in range(d))
    body = (
        f"/* The Gaussian process{_WHERE[side]}"
        " (fricid.models.gp): g = mean + y_scale sum_j s2 exp(-d2_j / 2) alpha_j */\n"
        f"static double gp_{side}(double av, double load, double temperature)\n{{\n"
        + "".join(f"    (void){x};\n" for x in unused)
        + f"    double z[{d}];\n    double zz, acc = 0.0;\n    int j;\n"
        + "".join(
            f"    z[{i}] = ({w} - {pre}shift[{i}]) / {pre}scale[{i}] / {pre}len[{i}];\n"
            for i, w in enumerate(warped)
        )
        + f"    zz = {' + '.join(f'z[{i}] * z[{i}]' for i in range(d))};\n"
        f"    for (j = 0; j < {m}; ++j) {{\n"
        f"        const double dot = {dot};\n"
        f"        const double d2 = fmax(zz + {pre}pp[j] - 2.0 * dot, 0.0);\n"
        f"        acc += {pre}s2 * exp(-0.5 * d2) * {pre}alpha[j];\n"
        "    }\n"
        f"    return ({pre}mean[0] + ({mean})) + {pre}y_scale * acc;\n"
        "}\n"
    )
    return consts, body


def gp_parts(fitted: FittedModel, smoothing: Smoothing) -> tuple[list[str], list[str]]:
    """Constants and functions of a fitted GP (``model == "gp"``): ``F = s g(|v|, load, T)``
    with ``s = sign(v)`` or ``tanh(v / zone)``, per direction when the state has two.

    Raises
    ------
    DataError
        A malformed state (checked by evaluating it once).
    """
    predict_gp(fitted.state, np.zeros((1, 3)))  # validates the state
    consts: list[str] = []
    funcs: list[str] = []
    sides = gp_sides(fitted.state)
    for side, st in sides.items():
        c, f = _side(st, side)
        consts += c
        funcs.append(f)
    sign = (
        f"tanh(velocity / {fmt_float(smoothing.zone, 'zone')})"
        if smoothing.kind == "tanh"
        else "(double)((velocity > 0.0) - (velocity < 0.0))"
    )
    core = [
        "/* The model: friction opposes motion, F = s g(|v|, load, T) */",
        "static double model(double velocity, double load, double temperature)\n{",
        f"    const double s = {sign};",
        "    const double av = fabs(velocity);",
    ]
    if "all" in sides:
        core.append("    return s * gp_all(av, load, temperature);")
    else:
        core += [
            "    if (velocity > 0.0) return s * gp_pos(av, load, temperature);",
            "    if (velocity < 0.0) return s * gp_neg(av, load, temperature);",
            "    return 0.0;",
        ]
    funcs.append("\n".join([*core, "}\n"]))
    return consts, funcs
