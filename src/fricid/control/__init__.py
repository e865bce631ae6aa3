"""Friction compensation, shown: a joint tracking a reference under PD control, without and
with the identified model as torque feed-forward.

>>> from fricid.control import compensation_study, plot_compensation      # doctest: +SKIP
>>> joint = fricid.sim.preset("paper2", "quick").joint                       # the caller's truth
>>> result = compensation_study(fitted, truth=Truth(joint.law, "paper2", joint.inertia))
>>> result.rms, result.max                                                  # rad
>>> plot_compensation(result, "compensation.png")

Dynamic (LuGre) friction: static feed-forward against a LuGre friction observer, the error at
zero-velocity crossings (:mod:`fricid.control.dynamic`).

>>> theta = lugre_parameters(stribeck_fit, sigma_0=1e3, sigma_1=0.5)      # doctest: +SKIP
>>> result = lugre_compensation_study(theta, truth=LuGreTruth(true_theta, inertia=0.01))
>>> result.rms_crossing                                                     # rad, per run
"""

from __future__ import annotations

from .dynamic import (
    DynamicCompensationResult,
    LuGreTruth,
    lugre_compensation_study,
    lugre_parameters,
)
from .plot import plot_compensation, plot_lugre_compensation
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
    "DynamicCompensationResult",
    "LuGreTruth",
    "TrackingConfig",
    "Truth",
    "compensation_study",
    "default_config",
    "fitted_law",
    "lugre_compensation_study",
    "lugre_parameters",
    "plot_compensation",
    "plot_lugre_compensation",
    "simulate_tracking",
]
