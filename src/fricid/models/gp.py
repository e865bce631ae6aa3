"""The Gaussian-process friction model as mathematics: prediction, with its standard deviation,
from a stored state (issue 15).

Training (scikit-learn's ``GaussianProcessRegressor`` for the kernel's hyperparameters, the
inducing-point subset) is :mod:`fricid.identify.learned.gp`'s job; this module only evaluates what a
model file holds, so that ``FittedModel.predict``, the C export and a loaded file agree.

Structure that physics guarantees: friction opposes motion and is, per direction, a function
of the speed, the load and the temperature,

``F(v, load, T) = sign(v) g(|v|, load, T)``,

with ``g`` a Gaussian process around a linear mean (the prior mean ``m`` extrapolates as
Coulomb-viscous friction does, linear in |v|, |load| and T, instead of falling back to a
constant far from the data):

``g(x) = m(x) + y_scale * sum_j alpha_j k(z(x), p_j)``,

``m(x) = c_0 + c_v |v| + c_l |load| + c_T T + c_vT |v| T`` (the inputs the state names; the
last term, a viscous coefficient linear in temperature as in [B] eq. 4, when both are used),
with |load| and T held to the range they were measured over (``mean_bounds``, optional in a
state): a basis bounded in the inputs friction does not grow linearly with, so that
coefficients that cancel over a narrow temperature range (a drift of a few tenths of a degree
gives ``c_0`` and ``c_T`` of thousands) cannot run away outside it; |v| is left free, so the
mean extrapolates as viscous friction does,

``k(z, p) = s2 * exp(-0.5 * sum_i ((z_i - p_i) / l_i)^2)`` (an anisotropic, ARD, squared
exponential kernel; Rasmussen & Williams 2006, eq. 5.1),

on the warped, standardised inputs ``z = (w(x) - shift) / scale`` with
``w(|v|) = asinh(|v| / velocity_scale)`` (log-like above ``velocity_scale``, linear through
zero), |load| (friction grows with the magnitude of the load, [B] eq. 3-4) and the
temperature. The points ``p_j`` are the training points or an
inducing subset of them. The posterior standard deviation of ``g`` (the latent friction,
without the white measurement noise) is

``std(x) = y_scale * sqrt(max(s2 - k^T B k + (h - G k)^T C (h - G k), 0))``,

``B`` the stored ``(m, m)`` matrix: ``K^-1`` of the exact GP (``K`` with the white noise
on its diagonal, R&W eq. 2.26), ``K_mm^-1 - noise (noise K_mm + K_mn K_nm)^-1`` of the
deterministic training conditional with inducing points (Quinonero-Candela & Rasmussen 2005,
eq. 20-21); the last term, with the basis ``h(x)`` of the mean, ``G = H K^-1``
(``mean_gain``) and ``C = (H K^-1 H^T)^-1`` (``mean_cov``), is the uncertainty of the mean's
coefficients, estimated with the process (R&W eq. 2.41-2.42), optional in a state.

A state (``FittedModel.state`` of a model ``"gp"``) holds ``kind`` (``"gaussian_process"``),
``symmetry`` (``"odd"``, ``"pos"``, ``"neg"`` or ``"per_direction"``, as for the RBF network:
:data:`fricid.models.rbf.SYMMETRIES`) and, for one process or in each of ``state["pos"]`` and
``state["neg"]``: ``inputs`` (velocity first), ``velocity_scale``, ``input_shift``,
``input_scale``, ``mean_coef`` (``c_0``, one per input, then ``c_vT``), ``length_scales``,
``signal_var`` (``s2``), ``noise_var``, ``y_scale``, ``points (m, d)``, ``alpha (m,)``,
``var_matrix (m, m)`` and, optionally, ``mean_gain (q, m)``, ``mean_cov (q, q)`` and
``mean_bounds (d, 2)`` (each input's measured [low, high], |load| for the load), plus training
notes that prediction ignores.

References
----------
[B] "An Optimized RBF Neural Network Based on Beetle Antennae Search Algorithm for Modeling
    the Static Friction in a Robotic Manipulator Joint" (the BAS-RBFNN paper), eq. 3-4.
C. E. Rasmussen and C. K. I. Williams, *Gaussian Processes for Machine Learning*, MIT Press,
2006, eq. 2.25-2.26 and 5.1.
J. Quinonero-Candela and C. E. Rasmussen, "A unifying view of sparse approximate Gaussian
process regression", JMLR 6, 1939-1959, 2005 (DTC, eq. 20-21).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

from ..errors import DataError
from ._base import INPUTS, state_array

__all__ = [
    "GP",
    "GP_KIND",
    "GP_SYMMETRIES",
    "GaussianProcess",
    "gp_sides",
    "left_out",
    "predict_gp",
]

#: ``state["kind"]`` of a Gaussian process in a model file.
GP_KIND = "gaussian_process"

#: The symmetries a GP state may have (their meaning as in :mod:`fricid.models.rbf`).
GP_SYMMETRIES = ("odd", "pos", "neg", "per_direction")

#: Rows of inputs evaluated at once, so that the kernel matrix stays small.
_CHUNK = 4096


def _array(state: Mapping[str, Any], key: str, shape: tuple[int | None, ...], where: str):
    return state_array(state, key, shape, "GP model", where)


def gp_sides(state: Mapping[str, Any] | None) -> dict[str, Mapping[str, Any]]:
    """The processes of a state by side: ``{"pos": ..., "neg": ...}`` for ``per_direction``,
    else ``{"all": state}``.

    Raises
    ------
    DataError
        Not a GP state (kind, symmetry), or a per-direction state without its two processes.
    """
    if not isinstance(state, Mapping):
        raise DataError("a GP model needs its process in 'state' (an object)")
    if state.get("kind") != GP_KIND:
        raise DataError(
            f"unknown GP state kind {state.get('kind')!r}; expected '{GP_KIND}'",
            column="state.kind",
        )
    sym = state.get("symmetry")
    if sym not in GP_SYMMETRIES:
        raise DataError(
            f"GP state symmetry must be one of {', '.join(GP_SYMMETRIES)}; got {sym!r}",
            column="state.symmetry",
        )
    if sym != "per_direction":
        return {"all": state}
    out = {}
    for side in ("pos", "neg"):
        if not isinstance(state.get(side), Mapping):
            raise DataError(
                f"a per-direction GP state needs the process '{side}' (an object)",
                column=f"state.{side}",
            )
        out[side] = state[side]
    return out


class _Side:
    """One stored process, checked once: its arrays and how to evaluate them."""

    def __init__(self, st: Mapping[str, Any], where: str) -> None:
        inputs = st.get("inputs")
        if (
            not isinstance(inputs, Sequence)
            or isinstance(inputs, str)
            or not inputs
            or inputs[0] != "velocity"
            or any(name not in INPUTS for name in inputs)
            or len(set(inputs)) != len(inputs)
        ):
            raise DataError(
                f"GP state 'inputs' must be distinct names among {', '.join(INPUTS)}, velocity "
                f"first; got {inputs!r}",
                column=f"{where}.inputs",
            )
        d = len(inputs)
        self.columns = [INPUTS.index(name) for name in inputs]
        self.vscale = float(_array(st, "velocity_scale", (), where))
        self.shift = _array(st, "input_shift", (d,), where)
        self.scale = _array(st, "input_scale", (d,), where)
        self.vt = 2 in self.columns  # the |v| T term of the mean
        self.mean_coef = _array(st, "mean_coef", (d + 1 + self.vt,), where)
        self.lengths = _array(st, "length_scales", (d,), where)
        self.s2 = float(_array(st, "signal_var", (), where))
        self.noise = float(_array(st, "noise_var", (), where))
        self.y_scale = float(_array(st, "y_scale", (), where))
        self.points = _array(st, "points", (None, d), where)
        m = self.points.shape[0]
        self.alpha = _array(st, "alpha", (m,), where)
        self.B = _array(st, "var_matrix", (m, m), where)
        q = len(self.mean_coef)  # the mean's coefficients' uncertainty: optional
        has_gain = "mean_gain" in st or "mean_cov" in st
        self.gain = _array(st, "mean_gain", (q, m), where) if has_gain else None
        self.cov = _array(st, "mean_cov", (q, q), where) if has_gain else None
        has_bounds = "mean_bounds" in st  # optional: files before it extrapolate the mean
        self.bounds = _array(st, "mean_bounds", (d, 2), where) if has_bounds else None
        if self.bounds is not None and np.any(self.bounds[:, 0] > self.bounds[:, 1]):
            raise DataError("GP state 'mean_bounds' needs low <= high", column=where)
        positive = (self.vscale, self.s2, self.y_scale, *self.scale, *self.lengths)
        if m == 0 or min(positive) <= 0 or self.noise < 0:
            raise DataError(
                "GP state needs points, positive scales, lengths and signal variance, and a "
                "noise variance >= 0",
                column=where,
            )

    def raw(self, Xa: np.ndarray) -> np.ndarray:
        """The inputs the process uses, |v| first, |load| and the temperature as given, from
        ``Xa (n, 3)`` with |v| in column 0."""
        R = Xa[:, self.columns].copy()
        if 1 in self.columns:
            j = self.columns.index(1)
            R[:, j] = np.abs(R[:, j])
        return R

    def bounded(self, R: np.ndarray) -> np.ndarray:
        """``R`` with |load| and temperature held to the training range (``mean_bounds``),
        as the mean's basis sees them; |v| as it is."""
        if self.bounds is None:
            return R
        out = R.copy()
        out[:, 1:] = np.clip(R[:, 1:], self.bounds[1:, 0], self.bounds[1:, 1])
        return out

    def kernel(self, R: np.ndarray) -> np.ndarray:
        """``k(z(x), p_j)`` ``(n, m)`` at raw inputs ``R``; ``||a - b||^2`` computed as
        ``max(||a||^2 + ||b||^2 - 2 a.b, 0)`` on length-scaled coordinates (the C export
        does the same)."""
        W = R.copy()
        W[:, 0] = np.arcsinh(W[:, 0] / self.vscale)
        Z = (W - self.shift) / self.scale / self.lengths
        P = self.points / self.lengths
        d2 = np.einsum("nd,nd->n", Z, Z)[:, None] + np.einsum("md,md->m", P, P)[None, :]
        d2 = np.maximum(d2 - 2.0 * (Z @ P.T), 0.0)
        return self.s2 * np.exp(-0.5 * d2)

    def mean(self, R: np.ndarray) -> np.ndarray:
        """The prior mean ``m(x)``: linear in |v|, |load| and T, the last two held to their
        training range (module notes)."""
        R = self.bounded(R)
        out = self.mean_coef[0] + R @ self.mean_coef[1 : len(self.columns) + 1]
        if self.vt:
            out = out + self.mean_coef[-1] * (R[:, 0] * R[:, self.columns.index(2)])
        return out

    def basis(self, R: np.ndarray) -> np.ndarray:
        """The mean's basis ``h(x)`` ``(n, q)``: 1, the inputs (|load| and T held to their
        training range), and |v| T when used."""
        R = self.bounded(R)
        extra = [R[:, 0] * R[:, self.columns.index(2)]] if self.vt else []
        return np.column_stack([np.ones(len(R)), R, *extra])

    def predict(self, Xa: np.ndarray, return_std: bool) -> tuple[np.ndarray, np.ndarray | None]:
        R = self.raw(Xa)
        g = np.empty(len(R))
        sd = np.empty(len(R)) if return_std else None
        for i in range(0, len(R), _CHUNK):
            rows = slice(i, i + _CHUNK)
            K = self.kernel(R[rows])
            g[rows] = self.mean(R[rows]) + self.y_scale * (K @ self.alpha)
            if sd is not None:
                var = self.s2 - np.einsum("nm,nm->n", K @ self.B, K)
                if self.gain is not None and self.cov is not None:
                    Rb = self.basis(R[rows]) - K @ self.gain.T
                    var = var + np.einsum("nq,nq->n", Rb @ self.cov, Rb)
                sd[rows] = self.y_scale * np.sqrt(np.maximum(var, 0.0))
        return g, sd


def left_out(state: Mapping[str, Any] | None) -> list[Mapping[str, Any]]:
    """The record of the samples each process's training left out as gross errors
    (``state["left_out"]``: count, velocity, friction, reason; written by
    :mod:`fricid.identify.learned.gp`), one per process that has one."""
    return [
        st["left_out"] for st in gp_sides(state).values() if isinstance(st.get("left_out"), Mapping)
    ]


def predict_gp(
    state: Mapping[str, Any] | None, X, return_std: bool = False
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Friction [N m] of a stored GP at ``X (n, 3)`` (velocity [rad/s], load [N m],
    temperature [degC]), and with ``return_std`` the posterior standard deviation [N m] of
    the latent friction (module notes; 0 at v = 0, where ``sign(0) = 0``).

    Raises
    ------
    DataError
        A malformed state, or ``X`` without three columns.
    """
    sides = {
        k: _Side(v, "state" if k == "all" else f"state.{k}") for k, v in gp_sides(state).items()
    }
    X = np.asarray(X, dtype=float)
    if X.ndim != 2 or X.shape[1] != len(INPUTS):
        raise DataError(
            f"inputs must have shape (n, 3): velocity, load, temperature; got {X.shape}"
        )
    v = X[:, 0]
    Xa = X.copy()
    Xa[:, 0] = np.abs(v)
    s = np.sign(v)
    if "all" in sides:
        g, sd = sides["all"].predict(Xa, return_std)
        F = s * g
        std = None if sd is None else np.where(v == 0, 0.0, sd)
    else:
        gp, sp = sides["pos"].predict(Xa, return_std)
        gn, sn = sides["neg"].predict(Xa, return_std)
        F = np.where(v > 0, gp, np.where(v < 0, -gn, 0.0))
        std = None if sp is None else np.where(v > 0, sp, np.where(v < 0, sn, 0.0))
    return (F, std) if return_std else F


class GaussianProcess:
    """The Gaussian process as a registered model (:func:`fricid.models.get_predictor`).

    Like the RBF network it predicts with ``predict(state, X)`` from a stored state
    (``stateful``), and gives its posterior standard deviation with ``return_std=True``.
    """

    name: ClassVar[str] = "gp"
    title: ClassVar[str] = "Gaussian process"
    equation: ClassVar[str] = "sign(v) g(|v|, load, T), g a GP (ARD squared exponential)"
    stateful: ClassVar[bool] = True

    def predict(self, state: Mapping[str, Any] | None, X, return_std: bool = False):
        """Friction [N m] at ``X (n, 3)``, and its standard deviation; see :func:`predict_gp`."""
        return predict_gp(state, X, return_std)

    def describe(self, state: Mapping[str, Any] | None) -> str:
        """One line on a stored process, for fit reports."""
        st = dict(state or {})
        sides = [st.get("pos"), st.get("neg")] if st.get("symmetry") == "per_direction" else [st]
        parts = []
        for sub in sides:
            sub = sub if isinstance(sub, Mapping) else {}
            lengths = ", ".join(f"{x:.3g}" for x in sub.get("length_scales") or [])
            parts.append(
                f"{len(sub.get('points') or [])} points ({sub.get('inducing', '?')}) on "
                f"{', '.join(sub.get('inputs') or [])}; length scales {lengths}; noise std "
                f"{sub.get('noise_std', float('nan')):.3g} N m"
            )
        return (
            f"Gaussian process, F = sign(v) g(|v|, load, T), symmetry {st.get('symmetry')}: "
            + "; ".join(parts)
        )


#: The one instance the model registry hands out.
GP = GaussianProcess()
