"""The analytic friction model interface.

A model is a stateless description: named parameters with units and bounds (after lmfit's
``Parameter``) and a vectorised ``predict(theta, X)`` (DESIGN.md, "Vectorised"):

* ``theta`` is one parameter vector ``(d,)`` or a batch ``(k, d)``;
* ``X`` is ``(n, 3)`` with columns velocity [rad/s], load [N m], temperature [degC]
  (``FrictionSamples.X``); a model ignores the columns it does not use;
* the result is ``(n,)`` or ``(k, n)`` friction torque [N m].

Friction opposes motion, so every model is odd in velocity: ``f(-v) = -f(v)``. At exactly zero
velocity ``sign(0) = 0``; exports offer a smoothed sign for controllers.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ConfigError, DataError

__all__ = [
    "INPUTS",
    "KELVIN",
    "NOMINAL_ACTIVATION",
    "REGIONS",
    "FrictionModel",
    "Parameter",
    "data_scales",
]

#: Input columns of X, in order.
INPUTS: tuple[str, ...] = ("velocity", "load", "temperature")


#: How a parameter's default and bounds scale with the data (see :func:`data_scales`).
SCALE_KINDS = (
    "torque",
    "velocity",
    "viscous",
    "load_coef",
    "temp_coef",
    "velocity_temp",
    "activation",
    "one",
)

#: The scale of an ``"activation"`` parameter [K] without data, or when the data hold a single
#: temperature: ``1 / (1/293.15 - 1/333.15)``, the span 20-60 degC (:func:`data_scales`).
NOMINAL_ACTIVATION = 1.0 / (1.0 / 293.15 - 1.0 / 333.15)

#: Degrees Celsius to kelvin.
KELVIN = 273.15

#: A parameter's valid region (``Parameter.region``) and the rule it states.
REGIONS = {"any": "any real value", "nonnegative": ">= 0", "positive": "> 0"}


@dataclass(frozen=True)
class Parameter:
    """One named model parameter (after lmfit's ``Parameter``).

    ``default``, ``lower`` and ``upper`` are multiples of the data scale named by ``kind``
    (:func:`data_scales`): a torque parameter bounded by ``[0, 2]`` may range up to twice the
    largest measured friction. So default bounds fit a 0.1 N m wrist and a 100 N m shoulder alike.

    ``region`` is where the family's equation is physical whatever the data (:data:`REGIONS`):
    ``"nonnegative"`` (a friction level, a viscous coefficient), ``"positive"`` (a Stribeck
    velocity, an exponent, a stiffness) or ``"any"``. The search bounds lie inside it (checked
    here, for any positive data scale); a model file whose parameter lies outside it is refused
    at load (:meth:`FrictionModel.region_violation`).
    """

    name: str
    unit: str
    kind: str
    default: float
    lower: float
    upper: float
    description: str = ""
    region: str = "any"

    def __post_init__(self) -> None:
        if self.kind not in SCALE_KINDS:
            raise ConfigError(f"parameter '{self.name}': unknown scale kind '{self.kind}'")
        if not (self.lower <= self.default <= self.upper):
            raise ConfigError(
                f"parameter '{self.name}': default {self.default} outside bounds "
                f"[{self.lower}, {self.upper}]"
            )
        if self.region not in REGIONS:
            raise ConfigError(f"parameter '{self.name}': unknown region '{self.region}'")
        if not (self.admits(self.lower) and self.admits(self.upper)):
            raise ConfigError(
                f"parameter '{self.name}': bounds [{self.lower}, {self.upper}] leave its valid "
                f"region {self.rule}"
            )

    def admits(self, value: float) -> bool:
        """Whether ``value`` (not NaN; an infinite search bound counts) lies inside the
        parameter's valid region."""
        if np.isnan(value):
            return False
        if self.region == "positive":
            return value > 0
        return value >= 0 if self.region == "nonnegative" else True

    @property
    def rule(self) -> str:
        """The valid region as a rule, e.g. ``"w_s > 0"``."""
        return f"{self.name} {REGIONS[self.region]}"


class FrictionModel(ABC):
    """Base class of the analytic friction models.

    Subclasses set ``name`` (registry key), ``title``, ``equation`` (the paper reference),
    ``inputs`` (which columns of X they use) and ``parameters``, and implement
    :meth:`_predict` on a batch ``theta`` of shape ``(k, d)`` and inputs ``(n, 3)``.
    """

    name: str = ""
    title: str = ""
    equation: str = ""
    inputs: tuple[str, ...] = ("velocity",)
    parameters: tuple[Parameter, ...] = ()
    #: Predicts from a parameter vector (False), not a stored state (the RBF network).
    stateful: bool = False
    #: The parameters the prediction is a linear combination of, for fixed values of the
    #: others (variable projection, :mod:`fricid.identify.static.varpro`); ``()`` when none is
    # declared.
    linear_params: tuple[str, ...] = ()
    #: The viscous coefficient ``c`` of a model of the form ``sign(v) G(|v|, load, T) + c v``
    #: (None when the model has no such term), which a temperature law may scale
    #: (:class:`fricid.models.WithTemperature`).
    viscous: str | None = None

    # -- description ---------------------------------------------------------------------
    @property
    def param_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)

    @property
    def n_params(self) -> int:
        return len(self.parameters)

    def _scale(self, X, y) -> np.ndarray:
        scales = data_scales(X, y)
        return np.array([scales[p.kind] for p in self.parameters])

    def defaults(self, X=None, y=None) -> np.ndarray:
        """Default parameter vector ``(d,)``, scaled to the data when ``X, y`` are given."""
        rel = np.array([p.default for p in self.parameters], dtype=float)
        return rel * self._scale(X, y)

    def bounds(self, X=None, y=None) -> np.ndarray:
        """Default search bounds ``(d, 2)``, scaled to the data when ``X, y`` are given."""
        rel = np.array([(p.lower, p.upper) for p in self.parameters], dtype=float)
        return rel * self._scale(X, y)[:, None]

    @property
    def units(self) -> dict[str, str]:
        return {p.name: p.unit for p in self.parameters}

    @property
    def is_asymmetric(self) -> bool:
        return False

    def param_vector(self, values: dict[str, float]) -> np.ndarray:
        """A parameter vector from a name -> value mapping (all names required)."""
        missing = [n for n in self.param_names if n not in values]
        extra = [n for n in values if n not in self.param_names]
        if missing or extra:
            raise ConfigError(
                f"model '{self.name}' takes parameters {', '.join(self.param_names)}"
                + (f"; missing: {', '.join(missing)}" if missing else "")
                + (f"; unknown: {', '.join(extra)}" if extra else "")
            )
        return np.array([float(values[n]) for n in self.param_names])

    def region_violation(self, theta) -> tuple[Parameter, float] | None:
        """The first parameter of the vector ``theta`` ``(d,)`` outside its valid region
        (``Parameter.region``) with its value, or None when every one lies inside."""
        values = np.asarray(theta, dtype=float).ravel()
        for p, value in zip(self.parameters, values, strict=True):
            if not p.admits(float(value)):
                return p, float(value)
        return None

    def __repr__(self) -> str:
        return f"{type(self).__name__}({', '.join(self.param_names)})"

    # -- evaluation ----------------------------------------------------------------------
    def predict(self, theta, X) -> np.ndarray:
        """Friction [N m] for parameters ``theta`` ((d,) or (k, d)) at inputs ``X`` ((n, 3))."""
        theta = np.asarray(theta, dtype=float)
        single = theta.ndim == 1
        batch = np.atleast_2d(theta)
        if batch.ndim != 2 or batch.shape[1] != self.n_params:
            raise ConfigError(
                f"model '{self.name}' takes {self.n_params} parameters "
                f"({', '.join(self.param_names)}); got an array of shape {theta.shape}"
            )
        X = self.check_inputs(X)
        out = self._predict(batch, X)
        return out[0] if single else out

    def check_inputs(self, X) -> np.ndarray:
        """Validate and return ``X`` as a float array of shape ``(n, 3)``."""
        X = np.asarray(X, dtype=float)
        if X.ndim == 1:
            X = np.column_stack([X, np.zeros_like(X), np.zeros_like(X)])
        if X.ndim != 2 or X.shape[1] != len(INPUTS):
            raise DataError(
                f"model inputs must have shape (n, 3) with columns {', '.join(INPUTS)}; "
                f"got shape {X.shape}"
            )
        return X

    @abstractmethod
    def _predict(self, theta: np.ndarray, X: np.ndarray) -> np.ndarray:
        """Batch evaluation: ``theta`` (k, d), ``X`` (n, 3) -> (k, n)."""


def data_scales(X=None, y=None) -> dict[str, float]:
    """Typical magnitudes of the data, by kind: largest |friction| F, |velocity| V, |load| L,
    |temperature| T, and their ratios. Without data every scale is 1.

    ``"activation"`` [K] is the reciprocal of the span of ``1 / (T + 273.15)`` over the data,
    so that ``E * (1/T_a - 1/T_b)`` of an Arrhenius law is the log of the viscosity ratio
    across the measured temperatures; with a single temperature (or without data) it is
    :data:`NOMINAL_ACTIVATION`.
    """
    if X is None or y is None:
        return {**dict.fromkeys(SCALE_KINDS, 1.0), "activation": NOMINAL_ACTIVATION}
    X = np.asarray(X, dtype=float)
    y = np.asarray(y, dtype=float)

    def big(a: np.ndarray) -> float:
        m = float(np.max(np.abs(a))) if a.size else 0.0
        return m if m > 0 and np.isfinite(m) else 1.0

    F, V, L, T = big(y), big(X[:, 0]), big(X[:, 1]), big(X[:, 2])
    return {
        "torque": F,
        "velocity": V,
        "viscous": F / V,
        "load_coef": F / L,
        "temp_coef": F / T,
        "velocity_temp": V / T,
        "activation": _activation_scale(X[:, 2]),
        "one": 1.0,
    }


def _activation_scale(temperature: np.ndarray) -> float:
    """``1 / (1/T_min - 1/T_max)`` [K] of the temperatures (degC) given, or the nominal one."""
    t = temperature[np.isfinite(temperature)] + KELVIN
    if t.size == 0 or float(t.min()) <= 0.0:
        return NOMINAL_ACTIVATION
    span = 1.0 / float(t.min()) - 1.0 / float(t.max())
    return 1.0 / span if span > 1e-9 else NOMINAL_ACTIVATION


def columns(theta: np.ndarray) -> list[np.ndarray]:
    """Split a (k, d) batch into d column vectors of shape (k, 1), ready to broadcast."""
    return [theta[:, j : j + 1] for j in range(theta.shape[1])]


def parameter_batch(theta, names: tuple[str, ...], title: str) -> tuple[np.ndarray, bool]:
    """``theta`` as a C-contiguous batch ``(k, d)`` and whether it was one vector ``(d,)``,
    for the dynamic models' functions (``d = len(names)``); a wrong shape is a ConfigError
    naming the model ``title`` and its parameters."""
    theta = np.asarray(theta, dtype=float)
    single = theta.ndim == 1
    batch = np.ascontiguousarray(np.atleast_2d(theta))
    if batch.ndim != 2 or batch.shape[1] != len(names):
        raise ConfigError(
            f"{title} takes {len(names)} parameters ({', '.join(names)}); "
            f"got an array of shape {theta.shape}"
        )
    return batch, single


def simulation_inputs(
    v, dt, state0, k: int, title: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The dynamic models' simulation inputs as C-contiguous arrays: velocities ``(n,)``,
    sample periods broadcast to ``(n,)`` (finite and >= 0, else a ConfigError naming the model
    ``title``) and the initial state broadcast to the ``k`` parameter rows (default 0)."""
    v = np.ascontiguousarray(np.asarray(v, dtype=float).ravel())
    dt = np.ascontiguousarray(np.broadcast_to(np.asarray(dt, dtype=float), (v.size,)))
    if v.size and (not np.all(np.isfinite(dt)) or np.any(dt < 0)):
        raise ConfigError(f"{title} simulation: sample periods must be finite and >= 0")
    s0 = np.asarray(0.0 if state0 is None else state0, float)
    return v, dt, np.ascontiguousarray(np.broadcast_to(s0, (k,)))


def state_array(
    state: Mapping[str, Any], key: str, shape: tuple[int | None, ...], title: str, where: str
) -> np.ndarray:
    """``state[key]`` of a stored-state model (``title``: "RBF model", "GP model") as a finite
    float array of ``shape`` (None: any length); anything else is a DataError naming the
    column ``where.key``."""
    column = f"{where}.{key}"
    if key not in state:
        raise DataError(f"{title} state lacks '{key}'", column=column)
    try:
        arr = np.asarray(state[key], dtype=float)
    except (TypeError, ValueError):
        raise DataError(f"{title} state '{key}' is not numeric", column=column) from None
    if arr.ndim != len(shape) or any(
        want is not None and got != want for got, want in zip(arr.shape, shape, strict=True)
    ):
        raise DataError(
            f"{title} state '{key}' has shape {arr.shape}, expected "
            f"{tuple('*' if s is None else s for s in shape)}",
            column=column,
        )
    if not np.isfinite(arr).all():
        raise DataError(f"{title} state '{key}' has non-finite values", column=column)
    return arr
