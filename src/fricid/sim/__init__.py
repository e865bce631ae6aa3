"""The virtual joint: raw logs of constant-velocity sweeps from a known friction law.

It is fricid's embedded default data and the test oracle:

>>> from fricid.sim import preset, simulate, true_samples
>>> scenario = preset("paper1", "quick")
>>> logs = simulate(scenario, seed=1)            # one RawLog per velocity set-point
>>> truth = true_samples(scenario)                # what extraction should recover

Modules: :mod:`.laws` (true friction laws), :mod:`.design` (experiment designs, trapezoidal
traverses), :mod:`.joint` (dynamics, noise, scenarios), :mod:`.simulate`, :mod:`.presets`,
:mod:`.oracle`, :mod:`.faults` (rest, settling, ramps, return moves, spike bursts, saturation;
off by default, ``preset("paper1+faults")`` switches them on), :mod:`.trajectory` (any motion:
sines, chirps, multi-sines, stick-slip, pre-sliding; static or LuGre truth).

Whole arms (imported from their modules, so that ``fricid`` starts without Pinocchio):
:mod:`.robot` (``simulate_robot``/``run_robot``: a :class:`~fricid.robot.RigidBodyModel`
tracking a reference with each joint's friction, quantised encoders and torque noise),
:mod:`.robot_friction` (``ArmFriction``, per-joint, per-direction Stribeck laws),
:mod:`.robot_lugre` (LuGre friction on chosen joints), :mod:`.robot_reference`
(``FourierTrajectory``, ``random_fourier``, ``sweep_reference``).
"""

from __future__ import annotations

from .design import Design, Profile, Traverse
from .faults import FAULT_KINDS, Faults
from .joint import Joint, Noise, Scenario, gravity_torque
from .laws import FrictionLaw, LoadTemperatureLaw, ModelLaw
from .oracle import (
    MEDIAN_EFFICIENCY,
    expected_noise_std,
    operating_grid,
    true_gravity,
    true_samples,
)
from .presets import PRESETS, SIZES, preset
from .simulate import CHUNKS, SeedLike, root_entropy, simulate, simulate_log

__all__ = [
    "CHUNKS",
    "FAULT_KINDS",
    "MEDIAN_EFFICIENCY",
    "PRESETS",
    "SIZES",
    "Design",
    "Faults",
    "FrictionLaw",
    "Joint",
    "LoadTemperatureLaw",
    "ModelLaw",
    "Noise",
    "Profile",
    "Scenario",
    "SeedLike",
    "Traverse",
    "expected_noise_std",
    "gravity_torque",
    "operating_grid",
    "preset",
    "root_entropy",
    "simulate",
    "simulate_log",
    "true_gravity",
    "true_samples",
]
