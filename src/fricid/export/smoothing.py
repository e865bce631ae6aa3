"""Smoothing of the friction model near zero velocity, for controllers.

Every analytic model has a ``sign(v)`` term, so the friction jumps at ``v = 0`` (and
``sign(0) = 0``). Fed forward in a controller this jump chatters around velocity reversals.
Two smoothings are offered, each with a zone half-width ``zone`` [rad/s]; the C export and
``fricid predict --smooth`` compute the same function as :func:`smooth_predict`.

``none``
    The model exactly as identified (``FittedModel.predict``).
``tanh``
    ``sign(v)`` is replaced by ``tanh(v / zone)`` in the model's Coulomb and Stribeck terms; the
    viscous term ``c v`` is kept as is. Every analytic model has the form
    ``F = sign(v) G(|v|, load, T) + c v`` (``c`` is ``beta`` in coulomb_viscous and msk,
    ``tau_v`` in stribeck, 0 in vlt), so the smoothed model is
    ``F_s = tanh(v / zone) G(|v|, load, T) + c v``; a per-direction model uses the ``_pos``
    parameters for ``v >= 0`` and the ``_neg`` ones below (continuous at 0, where both sides
    give 0). Outside about 3 zones the difference from the model is below 0.5 % of ``G``.
    Not for the RBF network, which has no sign term (it is continuous already).
``linear``
    Inside ``|v| < zone`` the friction follows the straight line between the model's values at
    ``-zone`` and ``+zone`` (at the same load and temperature); outside, the model is exact.
    Works for every model, the RBF network included.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..fitted import FittedModel
from ..models import Asymmetric
from ._common import ExportError

__all__ = ["SMOOTHINGS", "VISCOUS_TERM", "Smoothing", "sign_split", "smooth_predict"]

#: The smoothing kinds, with a line on each.
SMOOTHINGS: dict[str, str] = {
    "none": "the model as identified (sign(0) = 0)",
    "tanh": "sign(v) replaced by tanh(v / zone); viscous term unchanged (analytic models)",
    "linear": "straight line between the model's values at -zone and +zone (every model)",
}

#: For each analytic model family, the name of its linear viscous coefficient ``c`` in
#: ``F = sign(v) G(|v|, load, T) + c v`` (None: no such term).
VISCOUS_TERM: dict[str, str | None] = {
    "coulomb_viscous": "beta",
    "stribeck": "tau_v",
    "msk": "beta",
    "vlt": None,
}


@dataclass(frozen=True)
class Smoothing:
    """How to smooth a model near zero velocity: ``kind`` in :data:`SMOOTHINGS`, ``zone``
    the half-width [rad/s] (ignored for ``none``)."""

    kind: str = "none"
    zone: float = 0.0

    def __post_init__(self) -> None:
        kind = str(self.kind).strip().lower()
        if kind not in SMOOTHINGS:
            raise ExportError(
                f"unknown smoothing '{self.kind}'; choose one of: {', '.join(SMOOTHINGS)}"
            )
        object.__setattr__(self, "kind", kind)
        zone = float(self.zone)
        if kind != "none" and not (math.isfinite(zone) and zone > 0):
            raise ExportError(
                f"smoothing '{kind}' needs a zone half-width > 0 [rad/s], got {self.zone!r}"
            )
        object.__setattr__(self, "zone", zone if kind != "none" else 0.0)

    def describe(self) -> str:
        """One line for comments and reports."""
        if self.kind == "none":
            return "none: the model as identified, sign(0) = 0"
        if self.kind == "tanh":
            return f"tanh: sign(v) -> tanh(v / {self.zone:g} rad/s), viscous term unchanged"
        return (
            f"linear: |v| < {self.zone:g} rad/s follows the line between the model's values "
            f"at -{self.zone:g} and +{self.zone:g} rad/s"
        )


def _family(fitted: FittedModel) -> tuple[str, bool]:
    """The base family name and whether the model has parameters per direction."""
    if fitted.kind == "rbf":
        return "rbf", False
    model = fitted.friction_model()
    if isinstance(model, Asymmetric):
        return model.base.name, True
    return model.name, False


def sign_split(fitted: FittedModel) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """The sides of an analytic model as ``(theta, theta_without_viscous, c)``.

    One side for a symmetric model, two (``_pos`` then ``_neg``) for a per-direction one.
    ``theta_without_viscous`` has the viscous coefficient set to 0, so the base model with it
    evaluated at ``|v| > 0`` gives ``G(|v|, load, T)`` exactly.
    """
    family, asym = _family(fitted)
    if family not in VISCOUS_TERM:
        raise ExportError(
            f"model '{fitted.model}' has no known sign(v) G(|v|) + c v form (known: "
            f"{', '.join(VISCOUS_TERM)}); tanh smoothing cannot be applied to it, use "
            "'linear' or 'none'"
        )
    model = fitted.friction_model()
    base = model.base if asym else model
    theta = fitted.theta()
    d = base.n_params
    halves = [theta[:d], theta[d:]] if asym else [theta]
    viscous = VISCOUS_TERM[family]
    out = []
    for half in halves:
        if viscous is None:
            out.append((half, half, 0.0))
            continue
        j = base.param_names.index(viscous)
        g_theta = half.copy()
        g_theta[j] = 0.0
        out.append((half, g_theta, float(half[j])))
    return out


def _tanh(fitted: FittedModel, X: np.ndarray, zone: float) -> np.ndarray:
    if fitted.kind == "rbf":
        raise ExportError(
            "tanh smoothing replaces sign(v) in an analytic model; the RBF network has no sign "
            "term (it is continuous already): use --smooth linear, or none"
        )
    sides = sign_split(fitted)
    model = fitted.friction_model()
    base = model.base if isinstance(model, Asymmetric) else model
    v = X[:, 0]
    Xa = X.copy()
    Xa[:, 0] = np.abs(v)
    t = np.tanh(v / zone)
    values = []
    for _theta, g_theta, c in sides:
        g = base.predict(g_theta, Xa)
        values.append(t * g + c * v)
    if len(values) == 1:
        return values[0]
    return np.where(v >= 0, values[0], values[1])


def _linear(fitted: FittedModel, X: np.ndarray, zone: float) -> np.ndarray:
    v = X[:, 0]
    exact = fitted.predict(X)
    inside = np.abs(v) < zone
    if not inside.any():
        return exact
    Xp = X[inside].copy()
    Xm = X[inside].copy()
    Xp[:, 0] = zone
    Xm[:, 0] = -zone
    fp = fitted.predict(Xp)
    fm = fitted.predict(Xm)
    out = exact.copy()
    out[inside] = fm + (fp - fm) * (v[inside] + zone) / (2.0 * zone)
    return out


def smooth_predict(fitted: FittedModel, X, smoothing: Smoothing | None = None) -> np.ndarray:
    """Friction [N m] of ``fitted`` at inputs ``X`` (n, 3), smoothed near zero velocity.

    Parameters
    ----------
    fitted : the model.
    X : (n, 3) velocity [rad/s], load [N m], temperature [degC].
    smoothing : see the module docstring; None or ``Smoothing("none")`` gives
        ``fitted.predict(X)``.

    Raises
    ------
    ExportError
        tanh smoothing of a model without a sign term (the RBF network).
    """
    X = np.atleast_2d(np.asarray(X, dtype=float))
    smoothing = smoothing or Smoothing()
    if smoothing.kind == "tanh":
        return _tanh(fitted, X, smoothing.zone)
    if smoothing.kind == "linear":
        return _linear(fitted, X, smoothing.zone)
    return fitted.predict(X)
