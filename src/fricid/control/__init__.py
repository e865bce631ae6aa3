"""Friction compensation, shown: a joint tracking a reference under PD control, without and
with the identified model as torque feed-forward.

>>> from fricid.control import compensation_study, plot_compensation      # doctest: +SKIP
>>> result = compensation_study(fitted, truth="paper2")
>>> result.rms, result.max                                                  # rad
>>> plot_compensation(result, "compensation.png")
"""

from __future__ import annotations

from .plot import plot_compensation
from .tracking import (
    TRUTHS,
    CompensationResult,
    TrackingConfig,
    compensation_study,
    default_config,
    fitted_law,
    simulate_tracking,
)

__all__ = [
    "TRUTHS",
    "CompensationResult",
    "TrackingConfig",
    "compensation_study",
    "default_config",
    "fitted_law",
    "plot_compensation",
    "simulate_tracking",
]
