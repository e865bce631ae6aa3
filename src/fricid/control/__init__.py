"""Friction compensation, shown: a joint tracking a reference under PD control, without and
with the identified model as torque feed-forward.

>>> from fricid.control import Truth, compensation_study, default_config, plot_compensation
>>> from fricid.fitted import FittedModel
>>> from fricid.sim import preset
>>> fitted = FittedModel.from_values(
...     "stribeck", {"tau_c": 0.2, "tau_s": 0.3, "w_s": 0.1, "tau_v": 0.05, "delta": 1.0}
... )
>>> joint = preset("paper2", "quick").joint  # the caller's truth
>>> config = default_config(fitted, dt=1e-3)
>>> result = compensation_study(fitted, config, truth=Truth(joint.law, "paper2", joint.inertia))
>>> result.rms["with"] < result.rms["without"]  # tracking error [rad], RMS (and .max)
True
>>> plot_compensation(result, "compensation.png")  # doctest: +SKIP

Dynamic (LuGre) friction: static feed-forward against a LuGre friction observer, the error at
zero-velocity crossings (:mod:`fricid.control.dynamic`).

>>> from fricid.control import LuGreTruth, lugre_compensation_study, lugre_parameters
>>> theta = lugre_parameters(fitted, sigma_0=1e3, sigma_1=0.2)
>>> result = lugre_compensation_study(theta, truth=LuGreTruth(theta, inertia=0.01))
>>> ", ".join(sorted(result.rms_crossing))  # RMS error [rad] at the crossings, per run
'LuGre observer, PD only, static feed-forward'
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
