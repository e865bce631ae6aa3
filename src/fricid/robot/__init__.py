"""Whole robots: a fixed-base arm's rigid-body dynamics from its URDF (:mod:`.model`), its base
inertial parameters (:mod:`.base`), their physically consistent parametrisation
(:mod:`.consistency`), excitation design (:mod:`.excitation`, :mod:`.trajectories`,
:mod:`.excitation_files`) and the example robots of ``example-robot-data`` (:mod:`.examples`).
Pinocchio (PyPI ``pin``, the ``fricid[robot]`` extra) is imported on first use.
"""

from __future__ import annotations

import importlib
from typing import Any

#: Public name -> the module defining it (imported on first use).
_WHERE = {
    "PARAMETER_SYMBOLS": "model",
    "PARAMETER_UNITS": "model",
    "RigidBodyModel": "model",
    "BaseParameters": "base",
    "base_parameters": "base",
    "random_states": "base",
    "from_log_cholesky": "consistency",
    "is_consistent": "consistency",
    "pseudo_inertia": "consistency",
    "to_log_cholesky": "consistency",
    "ExcitationDesign": "excitation",
    "design_excitation": "excitation",
    "sweep_design": "sweeps",
    "FourierTrajectory": "trajectories",
    "RampedTrajectory": "trajectories",
    "SweepTrajectory": "trajectories",
    "load_design": "excitation_files",
    "save_design": "excitation_files",
    "write_joint_trajectory_yaml": "excitation_files",
    "write_trajectory_csv": "excitation_files",
    "EXAMPLE_ROBOTS": "examples",
    "example_urdf": "examples",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        value = getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *__all__])
