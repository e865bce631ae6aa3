"""The analytic friction models of both papers.

Each parameter declares, beside its search bounds, the region where the equation is physical
(``Parameter.region``): friction levels and viscous coefficients ``>= 0``, Stribeck velocities
and exponents ``> 0``, the temperature slopes of ``vlt`` any value. A model file outside it is
refused at load (:mod:`fricid.fitted`), and a fit cannot be bounded or fixed outside it.

References
----------
[B] "An Optimized RBF Neural Network Based on Beetle Antennae Search Algorithm for Modeling
    the Static Friction in a Robotic Manipulator Joint" (the BAS-RBFNN paper), eq. 1-4.
[R] Kou et al., "A New Parameter Identification Method for Industrial Robots with Friction",
    Machines 10(5) 349, 2022 (the RWSAVSBAS paper), eq. 7.
"""

from __future__ import annotations

import numpy as np

from ._base import FrictionModel, Parameter, columns

__all__ = ["CoulombViscous", "LoadDependent", "Stribeck", "VelocityLoadTemperature"]

_TINY = 1e-12


def _vlt(X: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Input columns as (1, n) rows, ready to broadcast against (k, 1) parameters."""
    return X[None, :, 0], X[None, :, 1], X[None, :, 2]


class CoulombViscous(FrictionModel):
    """Coulomb plus viscous friction, [B] eq. 1: ``F = F_c sign(v) + beta v``."""

    name = "coulomb_viscous"
    linear_params = ("f_c", "beta")
    title = "Coulomb-viscous"
    equation = "BAS-RBFNN paper, eq. 1"
    inputs = ("velocity",)
    viscous = "beta"
    parameters = (
        Parameter("f_c", "N m", "torque", 0.5, 0.0, 2.0, "Coulomb friction", "nonnegative"),
        Parameter(
            "beta", "N m s/rad", "viscous", 0.5, 0.0, 2.0, "viscous coefficient", "nonnegative"
        ),
    )

    def _predict(self, theta, X):
        f_c, beta = columns(theta)
        v, _, _ = _vlt(X)
        return f_c * np.sign(v) + beta * v


class Stribeck(FrictionModel):
    """Stribeck friction with exponent: [B] eq. 2, identical to [R] eq. 7.

    ``F = sign(v) [tau_c + (tau_s - tau_c) exp(-|v / w_s|^delta)] + tau_v v``

    Parameters are named as in [R] (Table 2 there): Coulomb ``tau_c``, static ``tau_s``,
    Stribeck velocity ``w_s``, viscous ``tau_v`` and exponent ``delta`` ([B] calls it xi;
    [R] fixes it to 1 after Tustin, which ``identify.fit(..., fixed={"delta": 1})`` does).
    [R] writes eq. 7 for positive velocity only; the sign makes it odd in velocity, as [B] eq. 2
    and the physics require.
    """

    name = "stribeck"
    linear_params = ("tau_c", "tau_s", "tau_v")
    title = "Stribeck (velocity)"
    equation = "BAS-RBFNN paper eq. 2; RWSAVSBAS paper eq. 7"
    inputs = ("velocity",)
    viscous = "tau_v"
    parameters = (
        Parameter("tau_c", "N m", "torque", 0.5, 0.0, 2.0, "Coulomb friction", "nonnegative"),
        Parameter(
            "tau_s", "N m", "torque", 0.8, 0.0, 2.0, "static (break-away) friction", "nonnegative"
        ),
        Parameter("w_s", "rad/s", "velocity", 0.1, 1e-4, 1.0, "Stribeck velocity", "positive"),
        Parameter(
            "tau_v", "N m s/rad", "viscous", 0.2, 0.0, 2.0, "viscous coefficient", "nonnegative"
        ),
        Parameter(
            "delta", "1", "one", 1.0, 0.2, 4.0, "Stribeck exponent (xi in eq. 2)", "positive"
        ),
    )

    def _predict(self, theta, X):
        tau_c, tau_s, w_s, tau_v, delta = columns(theta)
        v, _, _ = _vlt(X)
        a = np.abs(v) / np.maximum(np.abs(w_s), _TINY)
        return np.sign(v) * (tau_c + (tau_s - tau_c) * np.exp(-(a**delta))) + tau_v * v


class LoadDependent(FrictionModel):
    """The joint-load extended model M_sk, [B] eq. 3, with h(v) = beta v (viscous).

    ``F = g_k(v, tau_l) sign(v) + beta v`` with
    ``g_k = F_c + F_ck |tau_l| + (F_s - F_c + (F_sk - F_ck) |tau_l|) exp(-|v / v_s|^xi)``.
    """

    name = "msk"
    linear_params = ("f_c", "f_s", "f_ck", "f_sk", "beta")
    title = "Load-dependent (Msk)"
    equation = "BAS-RBFNN paper, eq. 3"
    inputs = ("velocity", "load")
    viscous = "beta"
    parameters = (
        Parameter(
            "f_c", "N m", "torque", 0.4, 0.0, 2.0, "Coulomb friction at zero load", "nonnegative"
        ),
        Parameter(
            "f_s", "N m", "torque", 0.6, 0.0, 2.0, "static friction at zero load", "nonnegative"
        ),
        Parameter(
            "f_ck", "1", "load_coef", 0.1, 0.0, 2.0, "Coulomb increase per |load|", "nonnegative"
        ),
        Parameter(
            "f_sk", "1", "load_coef", 0.1, 0.0, 2.0, "static increase per |load|", "nonnegative"
        ),
        Parameter("v_s", "rad/s", "velocity", 0.1, 1e-4, 1.0, "Stribeck velocity", "positive"),
        Parameter("xi", "1", "one", 1.0, 0.2, 4.0, "Stribeck exponent", "positive"),
        Parameter(
            "beta", "N m s/rad", "viscous", 0.2, 0.0, 2.0, "viscous coefficient", "nonnegative"
        ),
    )

    def _predict(self, theta, X):
        f_c, f_s, f_ck, f_sk, v_s, xi, beta = columns(theta)
        v, load, _ = _vlt(X)
        al = np.abs(load)
        a = np.abs(v) / np.maximum(np.abs(v_s), _TINY)
        g = f_c + f_ck * al + (f_s - f_c + (f_sk - f_ck) * al) * np.exp(-(a**xi))
        return g * np.sign(v) + beta * v


class VelocityLoadTemperature(FrictionModel):
    """Velocity-load-temperature model, [B] eq. 4, read with the eight parameters of [B] Table 2.

    Eq. 4 is garbled in print (no sign, an ambiguous viscous denominator). We read it as

    ``F = sign(v) ([f_c + (f_ctl + f_stl exp(-|v / v_tl0|)) |tau_l|]
                 + (f_v0 + f_vT T)(1 - exp(-|v / (v_v0 + v_vT T)|)))``

    with T in degC: a load-proportional Coulomb and Stribeck part, and a temperature-dependent
    viscous part that saturates at high speed. The denominator ``v_v0 + v_vT T`` is guarded
    away from zero.
    """

    name = "vlt"
    linear_params = ("f_c", "f_ctl", "f_stl", "f_v0", "f_vT")
    title = "Velocity-load-temperature"
    equation = "BAS-RBFNN paper, eq. 4 (Table 2 parameters)"
    inputs = ("velocity", "load", "temperature")
    parameters = (
        Parameter("f_c", "N m", "torque", 0.3, 0.0, 2.0, "Coulomb friction", "nonnegative"),
        Parameter(
            "f_ctl", "1", "load_coef", 0.2, 0.0, 4.0, "Coulomb increase per |load|", "nonnegative"
        ),
        Parameter(
            "f_stl", "1", "load_coef", 0.2, 0.0, 4.0, "Stribeck increase per |load|", "nonnegative"
        ),
        Parameter(
            "f_v0", "N m", "torque", 0.5, 0.0, 10.0, "viscous level at 0 degC", "nonnegative"
        ),
        Parameter("f_vT", "N m/degC", "temp_coef", 0.0, -4.0, 4.0, "viscous level per degC", "any"),
        Parameter("v_tl0", "rad/s", "velocity", 0.1, 1e-4, 1.0, "Stribeck velocity", "positive"),
        Parameter(
            "v_v0", "rad/s", "velocity", 1.0, 1e-3, 20.0, "viscous saturation velocity", "positive"
        ),
        Parameter(
            "v_vT", "rad/s/degC", "velocity_temp", 0.0, -1.0, 10.0, "its change per degC", "any"
        ),
    )

    def _predict(self, theta, X):
        f_c, f_ctl, f_stl, f_v0, f_vt, v_tl0, v_v0, v_vt = columns(theta)
        v, load, temp = _vlt(X)
        av = np.abs(v)
        coulomb = f_c + (f_ctl + f_stl * np.exp(-av / np.maximum(np.abs(v_tl0), _TINY))) * np.abs(
            load
        )
        denom = np.maximum(np.abs(v_v0 + v_vt * temp), _TINY)
        viscous = (f_v0 + f_vt * temp) * (1.0 - np.exp(-av / denom))
        return np.sign(v) * (coulomb + viscous)
