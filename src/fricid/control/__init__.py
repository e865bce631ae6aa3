"""Friction compensation, shown: a joint tracking a reference under PD control, without and
with the identified model as torque feed-forward.

>>> from fricid.control import compensation_study, plot_compensation      # doctest: +SKIP
>>> joint = fricid.sim.preset("paper2", "quick").joint                       # the caller's truth
>>> result = compensation_study(fitted, truth=Truth(joint.law, "paper2", joint.inertia))
>>> result.rms, result.max                                                  # rad
>>> plot_compensation(result, "compensation.png")
"""

from __future__ import annotations

from .plot import plot_compensation
from .tracking import (
    CompensationResult,
    TrackingConfig,
    Truth,
    compensation_study,
    default_config,
    fitted_law,
    simulate_tracking,
)

__all__ = [
    "CompensationResult",
    "TrackingConfig",
    "Truth",
    "compensation_study",
    "default_config",
    "fitted_law",
    "plot_compensation",
    "simulate_tracking",
]
