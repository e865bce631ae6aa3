"""Constant-velocity sweeps of one joint of an arm (BAS-RBFNN paper section 2) within its
limits, as a trajectory a robot can play (:class:`~fricid.robot.trajectories.SweepTrajectory`)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..errors import ConfigError
from .limits import resolve_limits
from .model import RigidBodyModel
from .trajectories import SweepTrajectory

__all__ = ["sweep_design"]


def sweep_design(
    model: RigidBodyModel,
    joint: str,
    speeds,
    *,
    hold: Mapping[str, float] | None = None,
    workspace: Mapping[str, tuple[float, float]] | None = None,
    acceleration_limit: float | None = None,
    margin: float = 0.05,
    dwell: float = 0.5,
) -> SweepTrajectory:
    """Constant-velocity sweeps of ``joint`` forward and back at each speed (BAS-RBFNN paper
    section 2), the other joints held still, as a :class:`~.trajectories.SweepTrajectory`.

    The joint starts at rest at the low end of its range (the URDF's limits narrowed by
    ``workspace``, less ``margin`` of the width at each end); at each speed ``v`` it speeds up
    to ``v`` by a half-cosine whose peak acceleration is the acceleration limit, crosses the
    range at ``v``, stops at the high end, rests ``dwell`` s, and returns at ``-v`` the same
    way, resting ``dwell`` s again.

    Parameters
    ----------
    model : RigidBodyModel
    joint : str
    speeds : sequence of float
        [rad/s or m/s], each > 0 and within the velocity limit less the margin.
    hold : mapping, optional
        Positions of the other joints (default the middle of their ranges).
    workspace, margin : as :func:`design_excitation`.
    acceleration_limit : float, optional
        Default the joint's velocity limit (one second from rest to the top speed, about).
    dwell : float
        Rest [s] at each end.
    """
    if joint not in model.joints:
        raise ConfigError(f"joint '{joint}' is not one of {model.joints}")
    i = model.joints.index(joint)
    speeds = np.atleast_1d(np.asarray(speeds, dtype=float))
    limits = resolve_limits(model, workspace, acceleration_limit, 1.0, 1, margin)
    vmax = limits["velocity"][i]
    if speeds.size == 0 or not np.isfinite(speeds).all() or (speeds <= 0).any():
        raise ConfigError(f"the sweep speeds must be > 0; got {speeds.tolist()}")
    if (speeds > vmax).any():
        raise ConfigError(
            f"speeds {speeds[speeds > vmax].tolist()} exceed {joint}'s velocity limit "
            f"less the margin, {vmax:.4g}"
        )
    if not (np.isfinite(dwell) and dwell >= 0):
        raise ConfigError(f"dwell must be >= 0 s; got {dwell}")
    amax = limits["acceleration"][i] if acceleration_limit is not None else vmax
    lo, hi = limits["lower"][i], limits["upper"][i]
    mid = 0.5 * (limits["lower"] + limits["upper"])
    for name, value in (hold or {}).items():
        if name not in model.joints:
            raise ConfigError(f"hold names joint '{name}', not one of {model.joints}")
        mid[model.joints.index(name)] = float(value)
    mid[i] = lo
    segments = []
    for v in speeds:
        ramp = v * np.pi / (2.0 * amax)  # the half-cosine's peak acceleration is amax
        cruise = (hi - lo - v * ramp) / v
        if cruise <= 0:
            raise ConfigError(
                f"{joint} cannot reach {v:g} rad/s within its range {hi - lo:.4g} at an "
                f"acceleration of {amax:.4g}: lower the speed or raise the acceleration limit"
            )
        for sign, start in ((1.0, lo), (-1.0, hi)):
            w = sign * v
            segments += [
                (ramp, start, 0.0, w),
                (cruise, start + w * ramp / 2, w, w),
                (ramp, start + w * (ramp / 2 + cruise), w, 0.0),
            ]
            if dwell > 0:
                segments.append((dwell, hi if sign > 0 else lo, 0.0, 0.0))
    return SweepTrajectory(model.joints, i, mid, np.array(segments, dtype=float))
