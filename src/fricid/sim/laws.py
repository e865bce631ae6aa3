"""True friction laws of the virtual joint.

A law is any callable ``law(velocity, load, temperature) -> friction`` on numpy arrays that
broadcast together (velocity [rad/s], load [N m], temperature [degC], friction [N m]); see
:class:`FrictionLaw`. Two are provided: :class:`LoadTemperatureLaw`, a velocity-, load- and
temperature-dependent law in the style of Bittencourt and Gunnarsson (the truth of the
``paper1`` preset), and :class:`ModelLaw`, any fricid model with fixed parameters (the truth of
``paper2``).

References
----------
[B] The BAS-RBFNN paper, eq. 2-4 and Fig. 6.
[BG] A. C. Bittencourt, S. Gunnarsson, "Static friction in a robot joint: modeling and
     identification of load and temperature effects", J. Dyn. Sys., Meas., Control 134(5), 2012.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from ..models import FrictionModel
from ..units import DEG

__all__ = ["FrictionLaw", "LoadTemperatureLaw", "ModelLaw"]


@runtime_checkable
class FrictionLaw(Protocol):
    """A true friction law: ``law(velocity, load, temperature) -> friction`` [N m].

    Arguments are arrays (or scalars) that broadcast together; the result has their broadcast
    shape. Friction opposes motion: a law is odd in velocity unless it models an asymmetric
    drive on purpose, and is 0 at zero velocity (the joint is held, not sliding).
    """

    def __call__(self, velocity, load, temperature) -> np.ndarray: ...


@dataclass(frozen=True)
class LoadTemperatureLaw:
    """Stribeck friction whose levels grow with |load| and fall with temperature ([BG]).

    ``F = sign(v) [(f_c + f_cl |L|) k_c(T) + (f_s + f_sl |L|) exp(-|v / v_s|^alpha)]
    + beta k_v(T) v``, with ``k_c = exp(-(T - t_ref) / t_coulomb)`` and
    ``k_v = exp(-(T - t_ref) / t_viscous)``.

    The Coulomb level and the Stribeck (break-away) excess grow linearly with the joint load
    ([B] eq. 3, after [BG]); viscous friction and, mildly, Coulomb friction fall exponentially
    as the lubricant warms ([B] Fig. 6b). The form is deliberately none of fricid's models:
    the Stribeck exponent ``alpha`` is 1.5 (the ``vlt`` model, [B] eq. 4, has 1), viscous
    friction is linear (``vlt``'s saturates) and Coulomb friction depends on temperature
    (no model has that), so fits are tested under honest misspecification.

    Defaults (the ``paper1`` preset): Coulomb ``f_c`` 0.04 N m + 0.6 |L|, Stribeck excess
    ``f_s`` 0.08 N m + 0.3 |L|, ``v_s`` 2 deg/s, ``alpha`` 1.5, ``beta`` 0.2 N m s/rad at
    25 degC, falling with an e-folding of 80 degC (viscous) and 200 degC (Coulomb). On the
    paper's design (|L| 0.154-0.210 N m, 0.1-50 deg/s, 5-45 degC) friction spans about
    0.14-0.41 N m; least-squares fits give R^2 of about 0.80 (stribeck, velocity only),
    0.85 (msk, + load) and 0.98 (vlt, + temperature): the load effect is clearly visible and
    the temperature effect larger still, as in [B] Table 1 (0.873, 0.942, 0.978).
    """

    f_c: float = 0.04  # N m, Coulomb friction at zero load and t_ref
    f_cl: float = 0.6  # Coulomb increase per N m of |load|
    f_s: float = 0.08  # N m, Stribeck excess at zero load
    f_sl: float = 0.3  # Stribeck excess increase per N m of |load|
    v_s: float = 2.0 * DEG  # rad/s, Stribeck velocity
    alpha: float = 1.5  # Stribeck exponent
    beta: float = 0.2  # N m s/rad, viscous coefficient at t_ref
    t_ref: float = 25.0  # degC
    t_viscous: float = 80.0  # degC, e-folding temperature of the viscous coefficient
    t_coulomb: float = 200.0  # degC, e-folding temperature of the Coulomb level

    def __call__(self, velocity, load, temperature) -> np.ndarray:
        v = np.asarray(velocity, dtype=float)
        abs_load = np.abs(np.asarray(load, dtype=float))
        dt = np.asarray(temperature, dtype=float) - self.t_ref
        coulomb = (self.f_c + self.f_cl * abs_load) * np.exp(-dt / self.t_coulomb)
        stribeck = (self.f_s + self.f_sl * abs_load) * np.exp(
            -((np.abs(v) / self.v_s) ** self.alpha)
        )
        viscous = self.beta * np.exp(-dt / self.t_viscous)
        return np.sign(v) * (coulomb + stribeck) + viscous * v


@dataclass(frozen=True, eq=False)
class ModelLaw:
    """A fricid model with fixed parameters, used as a true law.

    ``ModelLaw(Stribeck(), [0.084, 0.641, 0.066, 0.0026, 1.0])`` is the ``paper2`` truth
    (RWSAVSBAS paper, eq. 7 and Table 2).
    """

    model: FrictionModel
    theta: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        theta = np.asarray(self.theta, dtype=float)
        object.__setattr__(self, "theta", theta)
        # validate the parameter count now, not at the first call
        self.model.predict(theta, np.zeros((1, 3)))

    def __call__(self, velocity, load, temperature) -> np.ndarray:
        v, load_, temp = np.broadcast_arrays(
            np.asarray(velocity, dtype=float),
            np.asarray(load, dtype=float),
            np.asarray(temperature, dtype=float),
        )
        X = np.column_stack([v.ravel(), load_.ravel(), temp.ravel()])
        return self.model.predict(self.theta, X).reshape(v.shape)

    def __repr__(self) -> str:
        values = ", ".join(
            f"{n}={x:g}" for n, x in zip(self.model.param_names, self.theta, strict=True)
        )
        return f"ModelLaw({self.model.name}: {values})"
