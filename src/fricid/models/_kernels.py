"""Compiled (numba) loss kernels of the built-in analytic models, for the optimisers' fast path.

One kernel, :func:`loss_kernel`, evaluates the identification loss of a batch of candidates
``X (k, d)`` (the free parameters) on the samples in one compiled loop, for coulomb_viscous
(BAS-RBFNN paper eq. 1), stribeck (eq. 2 there; RWSAVSBAS paper eq. 7), msk (BAS-RBFNN eq. 3)
and vlt (BAS-RBFNN eq. 4, as read in :class:`~fricid.models.VelocityLoadTemperature`), their
per-direction ``_asym`` variants, and the ``_temp`` / ``_temp_asym`` variants of the first three
(the viscous coefficient scaled by :func:`~fricid.models._temperature.arrhenius_factor`). It
computes exactly what :meth:`fricid.identify.problem.IdentificationProblem.evaluate` computes
with numpy (the same formulas, weights, robust losses and ``mse`` divisor), up to rounding (the
tests hold the two to 1e-12 relative); it is written once for all models and branches on a model
code, so numba compiles (and caches) one function for every model.

``data`` (:func:`kernel_data`) is a tuple of fixed types: inputs ``(n, 3)``, friction ``(n,)``,
square roots of the weights ``(n,)`` (ones when unweighted), the full parameter vector with the
fixed values ``(p_all,)``, the free parameters' indices ``(d,)`` (int64) and a configuration
vector (model code, parameters per direction for ``_asym`` or 0, loss code, robust scale,
divisor, and for a temperature model the viscous coefficient's index within a direction's
parameters and the index of ``e_t``, else -1 and -1).

A model without a kernel (:func:`kernel_for` returns None: subclasses, wrappers, new families)
keeps the numpy path. numba is optional: without it :data:`HAVE_NUMBA` is False and nothing
here compiles.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ._base import KELVIN
from ._temperature import T_REF

try:
    from .._jit import njit

    HAVE_NUMBA = True
except ImportError:  # pragma: no cover - numba is a dependency
    HAVE_NUMBA = False

__all__ = ["HAVE_NUMBA", "LOSS_CODES", "MODEL_CODES", "kernel_data", "kernel_for", "loss_kernel"]

#: Model name -> code in the kernel.
MODEL_CODES = {"coulomb_viscous": 0, "stribeck": 1, "msk": 2, "vlt": 3}

#: Loss name -> code in the kernel (``l2`` is ``sse``).
LOSS_CODES = {"sse": 0, "mse": 1, "soft_l1": 2, "huber": 3}

_TINY = 1e-12


def _exact_models() -> dict[type, str]:
    from ._analytic import CoulombViscous, LoadDependent, Stribeck, VelocityLoadTemperature

    return {
        CoulombViscous: "coulomb_viscous",
        Stribeck: "stribeck",
        LoadDependent: "msk",
        VelocityLoadTemperature: "vlt",
    }


def kernel_for(model: Any) -> tuple[int, int, int, int] | None:
    """``(model code, parameters per direction or 0, viscous index or -1, e_t index or -1)``
    when ``model`` has a compiled kernel.

    Only the built-in classes themselves (not subclasses, whose formula may differ),
    :class:`~fricid.models.Asymmetric` around one of them, and
    :class:`~fricid.models.WithTemperature` around either qualify; None otherwise, or without
    numba.
    """
    if not HAVE_NUMBA:
        return None
    from ._asymmetric import Asymmetric
    from ._temperature import WithTemperature

    if type(model) is WithTemperature:
        inner = kernel_for(model.inner)
        if inner is None or inner[2] >= 0:
            return None
        base = model.inner.base if type(model.inner) is Asymmetric else model.inner
        return (inner[0], inner[1], base.param_names.index(base.viscous), model.n_params - 1)
    exact = _exact_models()
    if type(model) is Asymmetric:
        name = exact.get(type(model.base))
        return None if name is None else (MODEL_CODES[name], model.base.n_params, -1, -1)
    name = exact.get(type(model))
    return None if name is None else (MODEL_CODES[name], 0, -1, -1)


def kernel_data(
    code: tuple[int, int, int, int],
    X: np.ndarray,
    y: np.ndarray,
    sqrt_w: np.ndarray | None,
    base: np.ndarray,
    free: list[int],
    loss: str,
    f_scale: float | None,
) -> tuple:
    """The kernel's ``data`` tuple (module docstring) for a problem's arrays and loss."""
    n = y.size
    cfg = np.array(
        [
            float(code[0]),
            float(code[1]),
            float(LOSS_CODES[loss]),
            float(f_scale) if f_scale is not None else 1.0,
            float(n) if loss == "mse" else 1.0,
            float(code[2]),
            float(code[3]),
        ]
    )
    return (
        np.ascontiguousarray(X, dtype=float),
        np.ascontiguousarray(y, dtype=float),
        np.ones(n) if sqrt_w is None else np.ascontiguousarray(sqrt_w, dtype=float),
        np.ascontiguousarray(base, dtype=float).copy(),
        np.asarray(free, dtype=np.int64),
        cfg,
    )


def _sign(v: float) -> float:
    return 0.0 if v == 0.0 else (1.0 if v > 0.0 else -1.0)


def _predict(model: int, th: np.ndarray, o: int, v: float, load: float, temp: float) -> float:
    """Friction of one sample with the parameters ``th[o:]`` (the formulas of _analytic.py)."""
    sg = _sign(v)
    av = abs(v)
    if model == 0:  # coulomb_viscous, BAS-RBFNN eq. 1
        return th[o] * sg + th[o + 1] * v
    if model == 1:  # stribeck, BAS-RBFNN eq. 2 / RWSAVSBAS eq. 7
        a = av / max(abs(th[o + 2]), _TINY)
        return sg * (th[o] + (th[o + 1] - th[o]) * math.exp(-_pow(a, th[o + 4]))) + th[o + 3] * v
    if model == 2:  # msk, BAS-RBFNN eq. 3
        al = abs(load)
        a = av / max(abs(th[o + 4]), _TINY)
        g = (
            th[o]
            + th[o + 2] * al
            + (th[o + 1] - th[o] + (th[o + 3] - th[o + 2]) * al) * math.exp(-_pow(a, th[o + 5]))
        )
        return g * sg + th[o + 6] * v
    # vlt, BAS-RBFNN eq. 4 as read in _analytic.py
    coulomb = th[o] + (th[o + 1] + th[o + 2] * math.exp(-av / max(abs(th[o + 5]), _TINY))) * abs(
        load
    )
    denom = max(abs(th[o + 6] + th[o + 7] * temp), _TINY)
    viscous = (th[o + 3] + th[o + 4] * temp) * (1.0 - math.exp(-av / denom))
    return sg * (coulomb + viscous)


def _pow(a: float, e: float) -> float:
    """``a ** e``, with the common exponent 1 (Tustin's, the RWSAVSBAS paper's fixed delta)
    without the cost of ``pow`` (exact: ``a ** 1.0 == a``)."""
    return a if e == 1.0 else a**e


def _term(r: float, loss: int, c: float) -> float:
    """The squared (robust-transformed) residual: ``r^2`` or ``(c sqrt(rho((r / c)^2)))^2``."""
    if loss < 2:
        return r * r
    z = (r / c) ** 2
    if loss == 2:
        rho = 2.0 * (math.sqrt(1.0 + z) - 1.0)
    elif z <= 1.0:
        rho = z
    else:
        rho = 2.0 * math.sqrt(max(z, 1.0)) - 1.0
    t = c * math.sqrt(rho)
    return t * t


def _loss_kernel(X, out, data):  # pragma: no cover - compiled
    """Loss of each candidate row of ``X (k, d)`` into ``out (k,)``: the kernel of
    :class:`fricid.optim.JitObjective`."""
    inputs, y, sw, base, free, cfg = data
    model, half, loss = int(cfg[0]), int(cfg[1]), int(cfg[2])
    c, divisor = cfg[3], cfg[4]
    visc, e_t = int(cfg[5]), int(cfg[6])
    inv_ref = 1.0 / (T_REF + KELVIN)
    th = base.copy()
    for k in range(X.shape[0]):
        for j in range(free.shape[0]):
            th[free[j]] = X[k, j]
        s = 0.0
        for i in range(y.shape[0]):
            v = inputs[i, 0]
            o = half if (half > 0 and v < 0.0) else 0
            if visc >= 0:  # _temp: the viscous coefficient times the Arrhenius factor
                cv = th[o + visc]
                phi = math.exp(th[e_t] * (1.0 / (inputs[i, 2] + KELVIN) - inv_ref))
                th[o + visc] = cv * phi
                f = _predict(model, th, o, v, inputs[i, 1], inputs[i, 2])
                th[o + visc] = cv
            else:
                f = _predict(model, th, o, v, inputs[i, 1], inputs[i, 2])
            s += _term((f - y[i]) * sw[i], loss, c)
        out[k] = s / divisor


if HAVE_NUMBA:
    _sign = njit(cache=True)(_sign)
    _pow = njit(cache=True)(_pow)
    _predict = njit(cache=True)(_predict)
    _term = njit(cache=True)(_term)
    loss_kernel = njit(cache=True)(_loss_kernel)
else:  # pragma: no cover
    loss_kernel = None
