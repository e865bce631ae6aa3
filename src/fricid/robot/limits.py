"""The limits an excitation keeps: the URDF's position, velocity and effort limits, a user's
workspace and acceleration limit, less a margin (:func:`resolve_limits`), and how close a
trajectory comes to each (:func:`peak_fractions`)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..errors import ConfigError
from .model import RigidBodyModel

__all__ = [
    "DEFAULT_POSITION",
    "DEFAULT_VELOCITY",
    "assumed_limits",
    "peak_fractions",
    "ramped_within_limits",
    "resolve_limits",
]

#: How many times the ramps are lengthened (by :data:`RAMP_GROWTH` each) to keep the limits.
RAMP_TRIES = 10
RAMP_GROWTH = 1.5

#: Where the URDF gives no position limit [rad]; no velocity limit [rad/s].
DEFAULT_POSITION = np.pi
DEFAULT_VELOCITY = 2.0


def resolve_limits(
    model: RigidBodyModel,
    workspace: Mapping[str, tuple[float, float]] | None,
    acceleration: float | np.ndarray | None,
    w_f: float,
    harmonics: int,
    margin: float,
) -> dict:
    """The limits a design obeys (module notes). The acceleration limit defaults to each
    joint's velocity limit times ``w_f H`` (the acceleration of the highest harmonic at the
    full speed)."""
    if not 0.0 <= margin < 0.5:
        raise ConfigError(f"margin must be in [0, 0.5); got {margin}")
    lo = np.where(np.isfinite(model.lower), model.lower, -DEFAULT_POSITION)
    hi = np.where(np.isfinite(model.upper), model.upper, DEFAULT_POSITION)
    for name, pair in (workspace or {}).items():
        if name not in model.joints:
            raise ConfigError(f"workspace names joint '{name}', not one of {model.joints}")
        a, b = (float(x) for x in pair)
        i = model.joints.index(name)
        if not (np.isfinite(a) and np.isfinite(b)) or b < a:
            raise ConfigError(f"workspace of '{name}' must be lo <= hi; got {a}:{b}")
        lo[i], hi[i] = max(lo[i], a), min(hi[i], b)
        if hi[i] <= lo[i]:
            raise ConfigError(
                f"the workspace of '{name}' [{a:g}, {b:g}] leaves no room within its limits "
                f"[{model.lower[i]:g}, {model.upper[i]:g}]: it cannot move"
            )
    width = hi - lo
    lo, hi = lo + margin * width, hi - margin * width
    vel = np.where(np.isfinite(model.velocity_limit), model.velocity_limit, DEFAULT_VELOCITY)
    if acceleration is None:
        acc = vel * w_f * harmonics
    else:
        acc = np.broadcast_to(np.asarray(acceleration, dtype=float), (model.n,)).copy()
    if not (np.isfinite(acc).all() and (acc > 0).all()):
        raise ConfigError(f"the acceleration limit must be > 0; got {acceleration}")
    return {
        "lower": lo,
        "upper": hi,
        "velocity": vel * (1.0 - margin),
        "acceleration": acc * (1.0 - margin),
        "effort": model.effort_limit * (1.0 - margin),
        "margin": float(margin),
    }


def assumed_limits(model: RigidBodyModel) -> list[str]:
    """What :func:`resolve_limits` assumes where the URDF gives no limit (none, or 0, which
    the URDF reader reads as none), one line per quantity, for the user to check."""
    out = []
    for quantity, values, assumed in (
        ("position", model.upper - model.lower, f"+-{DEFAULT_POSITION:.4g} rad"),
        ("velocity", model.velocity_limit, f"{DEFAULT_VELOCITY:g} rad/s"),
        ("effort", model.effort_limit, "not checked"),
    ):
        joints = [j for j, v in zip(model.joints, values, strict=True) if not np.isfinite(v)]
        if joints:
            out.append(f"{quantity} {assumed} for {', '.join(joints)}")
    return out


def peak_fractions(model: RigidBodyModel, traj, limits: dict, rate: float) -> dict:
    """Each joint's peak position (about the middle, of the half-width), speed, acceleration
    and effort as fractions of the limits, at ``rate`` over the trajectory; the effort NaN
    where there is no effort limit."""
    _t, (q, dq, ddq) = traj.sample(rate)
    mid = 0.5 * (limits["upper"] + limits["lower"])
    half = 0.5 * (limits["upper"] - limits["lower"])
    tau = model.inverse_dynamics(q, dq, ddq)
    eff = limits["effort"]
    return {
        "position": np.max(np.abs(q - mid), axis=0) / half,
        "velocity": np.max(np.abs(dq), axis=0) / limits["velocity"],
        "acceleration": np.max(np.abs(ddq), axis=0) / limits["acceleration"],
        "effort": np.where(np.isfinite(eff), np.max(np.abs(tau), axis=0) / eff, np.nan),
    }


def ramped_within_limits(
    model: RigidBodyModel, trajectory, periods: int, ramp: float, limits: dict, rate: float
):
    """``periods`` of ``trajectory`` blended from and to rest, the ramps lengthened (by
    :data:`RAMP_GROWTH`, at most :data:`RAMP_TRIES` times) until no peak exceeds the limits
    more than the periodic part's own peaks do: a quintic from rest to full speed in a short
    ramp can ask for more acceleration or effort than the design (116.9 % of the acceleration
    limit with 1 s ramps on the double pendulum, where the periods reached 80 %).

    Returns
    -------
    played, ramp, peaks, first_peaks
        The trajectory played, its ramp [s], its peak fractions (:func:`peak_fractions`) and
        those with the ramp asked for.
    """
    bound = max(
        float(np.nanmax(np.r_[v, 0.0]))
        for v in peak_fractions(model, trajectory, limits, rate).values()
    )
    bound = max(bound, 1.0) + 1e-6
    first = None
    for _ in range(RAMP_TRIES + 1):
        played = trajectory.repeated(periods, ramp=ramp, limits=limits)
        peaks = peak_fractions(model, played, limits, rate)
        first = peaks if first is None else first
        if max(float(np.nanmax(np.r_[v, 0.0])) for v in peaks.values()) <= bound:
            break
        ramp *= RAMP_GROWTH
    return played, ramp, peaks, first
