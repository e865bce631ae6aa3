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
    ``tau_v`` in stribeck, 0 in vlt; ``c phi(T)`` in the ``*_temp`` models of
    :mod:`fricid.models._temperature`), so the smoothed model is
    ``F_s = tanh(v / zone) G(|v|, load, T) + c v``; a per-direction model uses the ``_pos``
    parameters for ``v >= 0`` and the ``_neg`` ones below (continuous at 0, where both sides
    give 0). Outside about 3 zones the difference from the model is below 0.5 % of ``G``.
    The RBF network is ``sign(v) g(|v|, load, T)`` too (per direction: ``g_pos``, ``g_neg``;
    :mod:`fricid.models.rbf`), smoothed as ``tanh(v / zone) g(|v|, load, T)``; only a network
    stored on signed velocity (symmetry ``"signed"``) has no sign term and refuses tanh.
``linear``
    Inside ``|v| < zone`` the friction follows the straight line from 0 at rest to the model's
    value at the zone's edge on the side of ``v`` (``+zone`` or ``-zone``, at the same load and
    temperature); outside, the model is exact. For a model that is odd in ``v`` this is the
    line between the values at ``-zone`` and ``+zone``; for a per-direction model, whose two
    levels differ, that one chord crossed zero off the origin and gave friction of the wrong
    sign at slow speeds, these two lines never do. Works for every model, the RBF network
    included.

This is model mathematics (DESIGN.md: ``models/`` owns "smoothing of sign(v) at zero"), so it
imports only numpy, :mod:`fricid.errors` and the models; a fitted model is used through the
:class:`FittedLike` protocol (its registry name, parameters and ``predict``). Its users: the C
export, ``fricid predict --smooth`` and the compensation study of :mod:`fricid.control`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..errors import ConfigError
from ._asymmetric import Asymmetric
from ._base import FrictionModel
from ._temperature import WithTemperature, arrhenius_factor

__all__ = [
    "SMOOTHINGS",
    "VISCOUS_TERM",
    "FittedLike",
    "Smoothing",
    "sign_split",
    "smooth_predict",
    "smooth_values",
]


class FittedLike(Protocol):
    """What :func:`smooth_predict` needs of a fitted model (``fricid.fitted.FittedModel``).

    ``model`` is the registry name (``"rbf"`` for the RBF network), ``params`` the parameter
    values by name, and ``predict(X)`` the friction [N m] at inputs ``X`` (n, 3).
    """

    model: str
    params: Mapping[str, float]

    def predict(self, X) -> np.ndarray: ...


#: The smoothing kinds, with a line on each.
SMOOTHINGS: dict[str, str] = {
    "none": "the model as identified (sign(0) = 0)",
    "tanh": "sign(v) replaced by tanh(v / zone); viscous term unchanged",
    "linear": "straight lines from 0 at rest to the model's values at -zone and +zone "
    "(every model)",
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
    """How to smooth a model near zero velocity.

    Parameters
    ----------
    kind : str
        One of :data:`SMOOTHINGS` (case-insensitive).
    zone : float
        The half-width of the zone [rad/s], finite and > 0 (ignored for ``none``).

    Raises
    ------
    ConfigError
        An unknown kind, or a zone that is not finite and positive.
    """

    kind: str = "none"
    zone: float = 0.0

    def __post_init__(self) -> None:
        kind = str(self.kind).strip().lower()
        if kind not in SMOOTHINGS:
            raise ConfigError(
                f"unknown smoothing '{self.kind}'; choose one of: {', '.join(SMOOTHINGS)}"
            )
        object.__setattr__(self, "kind", kind)
        zone = float(self.zone)
        if kind != "none" and not (math.isfinite(zone) and zone > 0):
            raise ConfigError(
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
            f"linear: |v| < {self.zone:g} rad/s follows the line from 0 at rest to the "
            f"model's value at +{self.zone:g} or -{self.zone:g} rad/s, on the side of v"
        )


def _analytic(fitted: FittedLike) -> tuple[FrictionModel, np.ndarray] | None:
    """The analytic model and parameter vector of ``fitted``; None for the stateful models
    (the RBF network, the hybrid, the Gaussian process)."""
    from . import STATEFUL, get_model

    if fitted.model in STATEFUL:
        return None

    model = get_model(fitted.model)
    return model, model.param_vector(dict(fitted.params))


def sign_split(model: FrictionModel, theta) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """The sides of an analytic model as ``(theta, theta_without_viscous, c)``.

    Parameters
    ----------
    model : FrictionModel
        An analytic model of :data:`VISCOUS_TERM`'s families, symmetric or
        :class:`~fricid.models.Asymmetric`.
    theta : array_like
        Its parameter vector ``(d,)``.

    Returns
    -------
    list of tuple
        One side for a symmetric model, two (``_pos`` then ``_neg``) for a per-direction one.
        ``theta_without_viscous`` has the viscous coefficient set to 0, so the base model with
        it evaluated at ``|v| > 0`` gives ``G(|v|, load, T)`` exactly.

    Raises
    ------
    ConfigError
        A model family without a known ``sign(v) G(|v|) + c v`` form.
    """
    asym = isinstance(model, Asymmetric)
    base = model.base if asym else model
    if base.name not in VISCOUS_TERM:
        raise ConfigError(
            f"model '{model.name}' has no known sign(v) G(|v|) + c v form (known: "
            f"{', '.join(VISCOUS_TERM)}); tanh smoothing cannot be applied to it, use "
            "'linear' or 'none'"
        )
    theta = np.asarray(theta, dtype=float)
    d = base.n_params
    halves = [theta[:d], theta[d:]] if asym else [theta]
    viscous = VISCOUS_TERM[base.name]
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


def _tanh(model: FrictionModel, theta, X: np.ndarray, zone: float) -> np.ndarray:
    if isinstance(model, WithTemperature):  # its viscous term c phi(T) v, kept as is
        inner, c, e_t = model.split(np.atleast_2d(np.asarray(theta, dtype=float)))
        c_v = np.where(X[:, 0] >= 0, c[0, 0], c[0, -1])
        g = _tanh(model.inner, inner[0], X, zone)
        return g + c_v * arrhenius_factor(e_t[0, 0], X[:, 2]) * X[:, 0]
    sides = sign_split(model, theta)
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


def _linear(predict: Callable[[np.ndarray], np.ndarray], X: np.ndarray, zone: float) -> np.ndarray:
    v = X[:, 0]
    exact = predict(X)
    inside = np.abs(v) < zone
    if not inside.any():
        return exact
    edge = X[inside].copy()
    edge[:, 0] = np.where(v[inside] >= 0, zone, -zone)  # the zone's edge on v's side
    out = exact.copy()
    out[inside] = predict(edge) * np.abs(v[inside]) / zone
    return out


_RBF_TANH = (
    "tanh smoothing replaces sign(v) in a model of the form sign(v) G(|v|); this RBF network "
    "was stored on signed velocity (symmetry 'signed') and has no sign term: use --smooth "
    "linear, or none, or refit it"
)


def _sign_form(fitted: FittedLike) -> bool:
    """True for an RBF network with a sign of its own (``F = sign(v) g(|v|)``)."""
    from .rbf import SIGN_FORM

    state = getattr(fitted, "state", None)
    return isinstance(state, Mapping) and state.get("symmetry") in SIGN_FORM


def _tanh_sign_form(predict: Callable[[np.ndarray], np.ndarray], X, zone: float) -> np.ndarray:
    """``tanh(v / zone) g(|v|)`` of a model ``F = sign(v) g(|v|)``: ``sign(v) F`` is ``g``."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    v = X[:, 0]
    return np.tanh(v / zone) * np.sign(v) * np.asarray(predict(X), dtype=float)


def smooth_values(
    predict: Callable[[np.ndarray], np.ndarray],
    X,
    smoothing: Smoothing | None = None,
    *,
    model: FrictionModel | None = None,
    theta=None,
) -> np.ndarray:
    """Friction [N m] of any model at inputs ``X`` (n, 3), smoothed near zero velocity.

    Parameters
    ----------
    predict : callable
        The model as identified: ``predict(X)`` gives friction [N m] at ``X`` (n, 3).
    X : array_like
        (n, 3) velocity [rad/s], load [N m], temperature [degC].
    smoothing : Smoothing, optional
        See the module docstring; None or ``Smoothing("none")`` gives ``predict(X)``.
    model : FrictionModel, optional
        The analytic model behind ``predict`` (None: a model without a sign term, the RBF
        network); tanh smoothing needs it.
    theta : array_like, optional
        The parameter vector of ``model``.

    Returns
    -------
    numpy.ndarray
        (n,) friction [N m].

    Raises
    ------
    ConfigError
        tanh smoothing of a model without a sign term (the RBF network).
    """
    X = np.atleast_2d(np.asarray(X, dtype=float))
    smoothing = smoothing or Smoothing()
    if smoothing.kind == "tanh":
        if model is None or theta is None:
            raise ConfigError(_RBF_TANH)
        return _tanh(model, theta, X, smoothing.zone)
    if smoothing.kind == "linear":
        return _linear(predict, X, smoothing.zone)
    return np.asarray(predict(X), dtype=float)


def smooth_predict(fitted: FittedLike, X, smoothing: Smoothing | None = None) -> np.ndarray:
    """Friction [N m] of a fitted model at inputs ``X`` (n, 3), smoothed near zero velocity.

    Parameters
    ----------
    fitted : FittedLike
        The model (a :class:`fricid.fitted.FittedModel`).
    X : array_like
        (n, 3) velocity [rad/s], load [N m], temperature [degC].
    smoothing : Smoothing, optional
        See the module docstring; None or ``Smoothing("none")`` gives ``fitted.predict(X)``.

    Returns
    -------
    numpy.ndarray
        (n,) friction [N m], the function the C export computes.

    Raises
    ------
    ConfigError
        tanh smoothing of a model without a sign term (an RBF network stored on signed
        velocity).
    """
    smoothing = smoothing or Smoothing()
    model = theta = None
    if smoothing.kind == "tanh":
        analytic = _analytic(fitted)
        if analytic is not None:
            model, theta = analytic
        elif _sign_form(fitted):
            return _tanh_sign_form(fitted.predict, X, smoothing.zone)
    return smooth_values(fitted.predict, X, smoothing, model=model, theta=theta)
