"""The virtual joint: its dynamics (BAS-RBFNN paper eq. 6-8), its sensors' noise, and scenarios.

A :class:`Scenario` is everything :func:`fricid.sim.simulate` needs: an experiment
:class:`~fricid.sim.design.Design`, a :class:`Joint` (true friction law, gravity, inertia,
torque constant) and a :class:`Noise` model of the sensors.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np

from ..errors import ConfigError
from .design import Design
from .faults import Faults
from .laws import FrictionLaw

__all__ = ["Joint", "Noise", "Scenario", "gravity_torque"]


def gravity_torque(theta, p_x: float, p_y: float) -> np.ndarray:
    """Gravitational torque [N m] at position ``theta`` [rad]: ``p_x cos - p_y sin`` (eq. 7)."""
    theta = np.asarray(theta, dtype=float)
    return p_x * np.cos(theta) - p_y * np.sin(theta)


@dataclass(frozen=True, eq=False)
class Joint:
    """A single joint's physics.

    Attributes
    ----------
    law : the true friction law, ``law(velocity, load, temperature)`` [N m].
    p_x, p_y : N m, gravity coefficients of eq. 7 (0 and 0 for a horizontal joint).
    inertia : kg m^2, the J of eq. 6 (joint side, motor included); default 0.01, so the
        200 deg/s^2 ramps of the default design add J a = 0.035 N m while accelerating.
    torque_constant : N m/A, the K of eq. 13 (default 0.5): the log carries I = tau_m / K.
    """

    law: FrictionLaw
    p_x: float = 0.0
    p_y: float = 0.0
    inertia: float = 0.01
    torque_constant: float = 0.5

    def __post_init__(self) -> None:
        if not callable(self.law):
            raise ConfigError("Joint: 'law' must be callable as law(velocity, load, temperature)")
        if not (math.isfinite(self.torque_constant) and self.torque_constant > 0):
            raise ConfigError(f"Joint: 'torque_constant' must be > 0, got {self.torque_constant!r}")
        if not (math.isfinite(self.inertia) and self.inertia >= 0):
            raise ConfigError(f"Joint: 'inertia' must be >= 0, got {self.inertia!r}")

    def gravity(self, theta) -> np.ndarray:
        """Gravitational torque tau_g(theta) [N m], eq. 7; it is also the load (eq. 12)."""
        return gravity_torque(theta, self.p_x, self.p_y)

    def motor_torque(self, theta, velocity, acceleration, temperature, offset=0.0) -> np.ndarray:
        """Motor torque [N m]: ``tau_f - tau_g + J acc`` (eq. 6; eq. 8 at constant velocity).

        ``offset`` [N m] is added to the friction magnitude (a per-traverse repeatability
        offset, signed with the velocity).
        """
        load = self.gravity(theta)
        velocity = np.asarray(velocity, dtype=float)
        friction = self.law(velocity, load, temperature) + np.sign(velocity) * offset
        return friction - load + self.inertia * np.asarray(acceleration, dtype=float)


@dataclass(frozen=True)
class Noise:
    """The virtual joint's measurement model; :meth:`none` gives an ideal joint.

    Attributes
    ----------
    current_std : A, Gaussian noise of the current sensor (per sample).
    current_lsb : A, ADC resolution of the current (0: not quantised).
    spike_rate : fraction of samples hit by a current spike (0.2 % by default).
    spike_min, spike_max : A, spike magnitude, uniform in this range with a random sign; the
        median filter of the extractor must remove them.
    velocity_rel_std, velocity_abs_std : measured velocity noise, ``rel |v| + abs`` [rad/s].
    position_lsb : rad, encoder resolution (default 20 bits per turn).
    temperature_std : degC, noise of the temperature channel.
    pass_offset_std : N m, standard deviation of a random friction offset drawn once per
        traverse (repeatability between passes); it sets the noise floor of averaged samples.
    """

    current_std: float = 0.01
    current_lsb: float = 0.001
    spike_rate: float = 0.002
    spike_min: float = 0.5
    spike_max: float = 2.0
    velocity_rel_std: float = 0.005
    velocity_abs_std: float = 2e-5
    position_lsb: float = 2.0 * math.pi / 2**20
    temperature_std: float = 0.05
    pass_offset_std: float = 0.002

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not (math.isfinite(value) and value >= 0):
                raise ConfigError(f"Noise: '{f.name}' must be a number >= 0, got {value!r}")
        if self.spike_rate > 1:
            raise ConfigError(f"Noise: 'spike_rate' must be in [0, 1], got {self.spike_rate!r}")
        if self.spike_max < self.spike_min:
            raise ConfigError("Noise: 'spike_max' must be >= 'spike_min'")

    @classmethod
    def none(cls) -> Noise:
        """No noise at all: exact current, velocity, position and temperature."""
        return cls(**{f.name: 0.0 for f in fields(cls)})

    def sample_torque_std(self, torque_constant: float) -> float:
        """Per-sample torque noise [N m] (Gaussian plus quantisation, spikes excluded)."""
        return torque_constant * math.sqrt(self.current_std**2 + self.current_lsb**2 / 12.0)


@dataclass(frozen=True, eq=False)
class Scenario:
    """A virtual experiment: design, joint and noise (what :func:`~fricid.sim.preset` returns).

    ``gravity`` is "fit" for a joint with gravity (the extractor separates it by eq. 11 and
    fits eq. 7) and "none" for a horizontal joint. :meth:`extract_options` gives the matching
    keyword arguments of :func:`fricid.extract.extract`. ``faults`` (None: a clean campaign)
    injects the faults of a real campaign (:class:`~fricid.sim.faults.Faults`).
    """

    name: str
    size: str
    design: Design
    joint: Joint
    noise: Noise
    gravity: str = "fit"
    description: str = ""
    faults: Faults | None = None

    def __post_init__(self) -> None:
        if self.gravity not in ("fit", "none"):
            raise ConfigError(f"Scenario: 'gravity' must be 'fit' or 'none', got {self.gravity!r}")
        if self.faults is not None and not isinstance(self.faults, Faults):
            raise ConfigError("Scenario: 'faults' must be a fricid.sim.Faults or None")

    def extract_options(self) -> dict[str, Any]:
        """Keyword arguments for :func:`fricid.extract.extract` matching this design: the
        position bins for a joint with gravity, the whole steady traverse for a horizontal one."""
        if self.gravity == "none":
            return {"positions": None, "gravity": "none"}
        return {
            "positions": self.design.positions,
            "bin_halfwidth": self.design.bin_halfwidth,
            "gravity": "fit",
        }

    def with_faults(self, faults: Faults | None) -> Scenario:
        """The same scenario with faults injected (None: a clean campaign)."""
        return replace(self, faults=faults)

    def period_length(self, iv: int) -> int:
        """Samples in one period of velocity set-point ``iv`` (faults included)."""
        traverse = self.design.traverse(self.design.velocities[iv])
        if self.faults is not None and self.faults.active:
            return self.faults.period_length(traverse)
        return traverse.n_period

    def with_noise(self, noise: Noise) -> Scenario:
        """The same scenario with another noise model (``Noise.none()`` for exact data)."""
        return replace(self, noise=noise)
