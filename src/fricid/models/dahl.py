"""The Dahl dynamic friction model: friction as a function of the distance travelled.

References
----------
[D68] P. R. Dahl, "A solid friction model", The Aerospace Corporation, TOR-0158(3107-18)-1,
    1968.
[D76] P. R. Dahl, "Solid friction damping of mechanical vibrations", AIAA Journal 14(12)
    1675-1682, 1976, eq. 1-3.
[CW95] C. Canudas de Wit et al., "A new model for control of systems with friction", IEEE
    Trans. Automatic Control 40(3), 1995 (Dahl as the special case sigma_1 = 0, g = tau_c).

The model ([D76] eq. 1, with a viscous term added as is usual for geared joints)::

    dF_d/dx = sigma_0 |1 - sign(v) F_d / tau_c|^alpha  sign(1 - sign(v) F_d / tau_c)
    F       = F_d + sigma_2 v

with ``x`` the position: a stiffness ``sigma_0`` at the start of a motion (pre-sliding), the
Coulomb level ``tau_c`` approached as the distance grows, ``alpha`` the shape of that
approach (1: exponential, [D68]'s usual choice). For ``alpha = 1`` it is LuGre with
``sigma_1 = 0`` and ``g(v) = tau_c`` ([CW95]), i.e. ``dF_d/dt = sigma_0 (v - |v| F_d / tau_c)``.

Why Dahl rather than the generalised Maxwell-slip model (GMS): one joint's data determine
Dahl's four parameters (sigma_0 from pre-sliding, tau_c and sigma_2 from sliding, alpha from
the shape of the transition), while GMS needs N elements with a stiffness and a threshold
each, plus a Stribeck curve, and its hysteresis has non-local memory, so its parameters are
identifiable only from rich pre-sliding data; Dahl is also rate independent, the cleanest
contrast to LuGre's Stribeck-dependent transients.

Update. Along a sample the velocity is held (zero-order hold), so the distance travelled is
``|v| dt``. With ``u = 1 - sign(v) F_d / tau_c`` the model reads ``du/ds = -(sigma_0 /
tau_c) u^alpha`` along the distance ``s``, solved exactly: ``u e^{-k}`` for ``alpha = 1``,
``(u^{1-alpha} - (1 - alpha) k)^{1/(1-alpha)}`` (reaching 0 in finite distance) for
``alpha < 1`` and ``(u^{1-alpha} + (alpha - 1) k)^{-1/(alpha-1)}`` for ``alpha > 1``, with
``k = sigma_0 |v| dt / tau_c``. Unconditionally stable for any stiffness.

Consistency and passivity (:func:`passivity_margin`, :func:`is_passive`). With ``sigma_0 >
0``, ``tau_c > 0``, ``alpha > 0`` the set ``|F_d| <= tau_c`` is invariant ([D76]: ``u`` stays
in ``[0, 2]``, the friction never exceeds the Coulomb level), and on it the map ``v -> F`` is
passive with the storage ``V = F_d^2 / (2 sigma_0)`` whenever ``sigma_2 >= 0``::

    F v - dV/dt = tau_c |v| (1 - u) (1 - u^alpha) + sigma_2 v^2 >= 0,

since ``1 - u`` and ``1 - u^alpha`` have the same sign for ``alpha > 0``. A state outside the
invariant set (``|F_d| > tau_c``) is projected onto it at the first update.
"""

from __future__ import annotations

import numpy as np

from ._base import FrictionModel, Parameter, parameter_batch, simulation_inputs

__all__ = [
    "PARAMETERS",
    "PARAM_NAMES",
    "Dahl",
    "is_passive",
    "passivity_margin",
    "simulate",
    "steady_state",
]

#: Dahl's parameters, in the order of ``theta`` columns.
PARAMETERS: tuple[Parameter, ...] = (
    Parameter("sigma_0", "N m/rad", "one", 1e4, 1.0, 1e7, "rest stiffness", "positive"),
    Parameter("tau_c", "N m", "torque", 0.5, 1e-6, 2.0, "Coulomb friction", "positive"),
    Parameter("alpha", "1", "one", 1.0, 0.1, 4.0, "shape of the stress-strain curve", "positive"),
    Parameter(
        "sigma_2", "N m s/rad", "viscous", 0.2, 0.0, 2.0, "viscous coefficient", "nonnegative"
    ),
)
PARAM_NAMES: tuple[str, ...] = tuple(p.name for p in PARAMETERS)


def _batch(theta) -> tuple[np.ndarray, bool]:
    return parameter_batch(theta, PARAM_NAMES, "Dahl")


def steady_state(theta, v) -> np.ndarray:
    """Friction at constant velocity, ``sign(v) tau_c + sigma_2 v`` (Coulomb plus viscous)."""
    batch, single = _batch(theta)
    v = np.asarray(v, dtype=float)[None, :]
    out = np.sign(v) * batch[:, 1:2] + batch[:, 3:4] * v
    return out[0] if single else out


def passivity_margin(theta) -> np.ndarray:
    """The smallest of ``sigma_0``, ``tau_c``, ``alpha`` (each must be > 0) and ``sigma_2``
    (>= 0), in their own units: passive (and consistent) where > 0, or where the first three
    are > 0 and ``sigma_2`` is 0 (margin 0). See the module notes for the proof."""
    batch, single = _batch(theta)
    margin = np.min(batch, axis=1)
    return margin[0] if single else margin


def is_passive(theta) -> np.ndarray:
    """Whether ``sigma_0, tau_c, alpha > 0`` and ``sigma_2 >= 0`` (module notes)."""
    batch, single = _batch(theta)
    ok = np.all(batch[:, :3] > 0, axis=1) & (batch[:, 3] >= 0)
    return bool(ok[0]) if single else ok


def simulate(theta, v, dt, f0=None) -> tuple[np.ndarray, np.ndarray]:
    """Friction and Dahl force along a velocity signal, for one or many parameter vectors.

    Parameters
    ----------
    theta : array_like
        ``(4,)`` or ``(k, 4)`` in the order of :data:`PARAM_NAMES`.
    v : array_like
        ``(n,)`` velocity [rad/s], held constant over each sample.
    dt : float or array_like
        Sample period [s], scalar or ``(n,)`` (the step into each sample).
    f0 : float or array_like, optional
        Initial Dahl force [N m], scalar or ``(k,)``; default 0.

    Returns
    -------
    F, F_d : ndarray
        Friction (Dahl force plus viscous) and the Dahl force [N m], ``(n,)`` or ``(k, n)``;
        NaN rows for parameters outside the domain (sigma_0, tau_c or alpha not positive).
    """
    batch, single = _batch(theta)
    k = batch.shape[0]
    v, dt, f0 = simulation_inputs(v, dt, f0, k, "Dahl")
    n = v.size
    F = np.empty((k, n))
    S = np.empty((k, n))
    from ._dahl_kernel import run  # lazy: importing numba takes a while

    run(batch, v, dt, f0, F, S)
    return (F[0], S[0]) if single else (F, S)


class Dahl(FrictionModel):
    """Dahl's static projection for the model-file machinery: ``predict`` is the steady
    state, Coulomb plus viscous (:func:`steady_state`); the transients come from
    :func:`simulate`."""

    name = "dahl"
    title = "Dahl (dynamic; steady state shown)"
    equation = "Dahl 1976, eq. 1"
    inputs = ("velocity",)
    parameters = PARAMETERS

    def _predict(self, theta, X):
        return steady_state(theta, X[:, 0])
