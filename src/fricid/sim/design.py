"""Experiment designs: which constant-velocity sweeps the virtual joint runs, and their timing.

A :class:`Design` is the BAS-RBFNN paper's section 2.2 as data: velocity set-points,
temperatures (one experiment each), position bins (their loads via eq. 7 and 12) and the number
of repetitions. :class:`Traverse` is the motion of one velocity set-point: one *period* is a
forward traverse then a backward one over the measured range, each with a trapezoidal velocity
profile, separated by short dwells at rest.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError
from ..units import DEG

__all__ = ["COVERAGES", "Design", "Profile", "Traverse"]

#: Values of :attr:`Design.coverage`.
COVERAGES = ("both", "split")


def _positive_array(name: str, values) -> np.ndarray:
    arr = np.atleast_1d(np.asarray(values, dtype=float))
    if arr.ndim != 1 or arr.size == 0 or not np.isfinite(arr).all():
        raise ConfigError(f"Design: '{name}' must be a non-empty 1-D array of finite numbers")
    return arr


@dataclass(frozen=True, eq=False)
class Design:
    """A constant-velocity sweep campaign (BAS-RBFNN paper, section 2.2), SI units.

    Attributes
    ----------
    velocities : (n_v,) rad/s, the positive velocity set-points; each is run in both directions.
    temperatures : (n_T,) degC; one experiment per temperature, held constant.
    positions : (n_p,) rad, centres of the position bins where samples are taken (their
        gravity torques are the loads, eq. 12).
    bin_halfwidth : rad; samples within this distance of a centre belong to its bin, so the
        measured range is ``[min(positions) - bin_halfwidth, max(positions) + bin_halfwidth]``.
    repetitions : periods (forward plus backward traverse) per velocity set-point (the paper's
        "move periodically for 10 times").
    sample_rate : Hz (the paper's 0.25 kHz).
    acceleration : rad/s^2, of the trapezoidal profile (default 200 deg/s^2).
    settle_time : s; the traverse extends beyond the measured range by the acceleration distance
        plus ``velocity * settle_time``, so an extractor that trims a settle margin up to this
        long after the acceleration still sees every bin at constant velocity.
    dwell_time : s at rest at each end of the traverse.
    experiment_gap : s between two experiments (temperatures) in the time column.
    coverage : "both" (default) records both directions over the whole measured range;
        "split" records forward traverses only below the middle of the measured range and
        backward traverses only above it (one-sided coverage: the two directions never share
        a position, so eq. 11 cannot pair them; the samples outside are not logged, leaving a
        gap in the time column).
    """

    velocities: np.ndarray
    temperatures: np.ndarray
    positions: np.ndarray
    bin_halfwidth: float
    repetitions: int = 10
    sample_rate: float = 250.0
    acceleration: float = 200.0 * DEG
    settle_time: float = 0.2
    dwell_time: float = 0.2
    experiment_gap: float = 60.0
    coverage: str = "both"

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        if self.coverage not in COVERAGES:
            raise ConfigError(
                f"Design: 'coverage' must be one of {', '.join(COVERAGES)}, got {self.coverage!r}"
            )
        velocities = _positive_array("velocities", self.velocities)
        if (velocities <= 0).any():
            raise ConfigError("Design: velocity set-points must be positive (both directions run)")
        set_(self, "velocities", velocities)
        set_(self, "temperatures", _positive_array("temperatures", self.temperatures))
        positions = np.sort(_positive_array("positions", self.positions))
        set_(self, "positions", positions)
        for name in ("bin_halfwidth", "sample_rate", "acceleration"):
            value = float(getattr(self, name))
            if not (math.isfinite(value) and value > 0):
                raise ConfigError(f"Design: '{name}' must be a positive number, got {value!r}")
            set_(self, name, value)
        for name in ("settle_time", "dwell_time", "experiment_gap"):
            value = float(getattr(self, name))
            if not (math.isfinite(value) and value >= 0):
                raise ConfigError(f"Design: '{name}' must be >= 0, got {value!r}")
            set_(self, name, value)
        if positions.size > 1 and 2 * self.bin_halfwidth > np.diff(positions).min() + 1e-12:
            raise ConfigError(
                "Design: position bins overlap; bin_halfwidth must be at most half the "
                f"smallest spacing ({np.diff(positions).min() / 2:.6g} rad)"
            )
        if int(self.repetitions) != self.repetitions or self.repetitions < 1:
            raise ConfigError(
                f"Design: 'repetitions' must be a positive integer, got {self.repetitions!r}"
            )
        set_(self, "repetitions", int(self.repetitions))

    @property
    def measured_range(self) -> tuple[float, float]:
        """(low, high) rad: the positions covered by the bins."""
        return (
            float(self.positions[0] - self.bin_halfwidth),
            float(self.positions[-1] + self.bin_halfwidth),
        )

    @property
    def shape(self) -> tuple[int, int, int]:
        """(n_temperatures, n_velocities, n_positions): the operating-point grid."""
        return (self.temperatures.size, self.velocities.size, self.positions.size)

    def traverse(self, velocity: float) -> Traverse:
        """The motion of one velocity set-point."""
        low, high = self.measured_range
        v = float(velocity)
        extension = v * v / (2.0 * self.acceleration) + v * self.settle_time
        return Traverse(
            velocity=v,
            acceleration=self.acceleration,
            start=low - extension,
            end=high + extension,
            dwell=self.dwell_time,
            sample_rate=self.sample_rate,
        )

    def recorded(self, position: np.ndarray, velocity: np.ndarray) -> np.ndarray:
        """Which samples of a profile (true ``position`` [rad] and ``velocity`` [rad/s]) are
        logged: all of them, or with ``coverage="split"`` none of a forward move above the
        middle of the measured range nor of a backward move below it."""
        if self.coverage == "both":
            return np.ones(np.shape(position), dtype=bool)
        middle = 0.5 * sum(self.measured_range)
        return ~(((velocity > 0) & (position > middle)) | ((velocity < 0) & (position < middle)))

    def samples_per_setpoint(self) -> np.ndarray:
        """(n_v,) raw samples logged per velocity set-point and temperature."""
        return np.array([self.traverse(v).n_period for v in self.velocities]) * self.repetitions

    def n_samples(self) -> int:
        """Raw samples in the whole campaign."""
        return int(self.samples_per_setpoint().sum()) * self.temperatures.size


@dataclass(frozen=True)
class Profile:
    """Positions, velocities and accelerations along one period (arrays of equal length)."""

    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    pass_index: np.ndarray  # 0 while at rest or moving forward, 1 while moving backward


@dataclass(frozen=True)
class Traverse:
    """One velocity set-point's period: dwell, forward traverse, dwell, backward traverse.

    Each traverse runs from ``start`` to ``end`` (or back) with a trapezoidal velocity profile:
    constant acceleration to ``velocity``, cruise, constant deceleration to rest.
    """

    velocity: float
    acceleration: float
    start: float
    end: float
    dwell: float
    sample_rate: float

    @property
    def distance(self) -> float:
        return self.end - self.start

    @property
    def accel_time(self) -> float:
        return self.velocity / self.acceleration

    @property
    def move_time(self) -> float:
        """Duration of one traverse: ``D / v + v / a`` (trapezoid)."""
        return self.distance / self.velocity + self.accel_time

    @property
    def n_period(self) -> int:
        """Samples in one period (forward plus backward traverse and both dwells)."""
        return math.ceil(2.0 * (self.dwell + self.move_time) * self.sample_rate)

    def _move(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Trapezoid: distance, speed and acceleration ``tau`` seconds into a traverse."""
        a, v, d, tm = self.acceleration, self.velocity, self.distance, self.move_time
        tau = np.clip(tau, 0.0, tm)
        rest = tm - tau
        ta = self.accel_time
        accelerating = tau < ta
        decelerating = rest < ta
        s = np.where(
            accelerating,
            0.5 * a * tau**2,
            np.where(decelerating, d - 0.5 * a * rest**2, v * v / (2.0 * a) + v * (tau - ta)),
        )
        speed = np.where(accelerating, a * tau, np.where(decelerating, a * rest, v))
        acc = np.where(accelerating, a, np.where(decelerating, -a, 0.0))
        return s, speed, acc

    def profile(self, t: np.ndarray) -> Profile:
        """The motion at times ``t`` [s] from the start of a period (vectorised)."""
        t = np.asarray(t, dtype=float)
        dw, tm = self.dwell, self.move_time
        forward = (t >= dw) & (t < dw + tm)
        at_end = (t >= dw + tm) & (t < 2 * dw + tm)
        backward = (t >= 2 * dw + tm) & (t < 2 * dw + 2 * tm)
        tau = np.where(backward, t - (2 * dw + tm), t - dw)
        s, speed, acc = self._move(tau)
        moving = forward | backward
        direction = np.where(backward, -1.0, 1.0)
        position = np.where(
            forward,
            self.start + s,
            np.where(backward, self.end - s, np.where(at_end, self.end, self.start)),
        )
        return Profile(
            position=position,
            velocity=np.where(moving, direction * speed, 0.0),
            acceleration=np.where(moving, direction * acc, 0.0),
            pass_index=backward.astype(np.intp),
        )
