"""The velocity and acceleration :func:`~.arm.extract_arm` reads, estimated piece by piece.

A robot log can hold gaps: rows a recorder dropped, or several recordings joined into one
(:func:`fricid.samples.join_robot_logs`). The extraction ends a steady run at any step in time
longer than :data:`~.segment.GAP_FACTOR` median sample periods; the derivatives must not span
it either (a window across two recordings differentiates a jump in position between them),
so both are estimated on each piece between gaps.
"""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
from scipy.signal import savgol_filter

from ..samples import RawLog, RobotLog
from .pipeline import velocity_from_position
from .segment import GAP_FACTOR

__all__ = [
    "ACCELERATION_WINDOW",
    "acceleration",
    "joint_chunks",
    "named_pieces",
    "pieces",
    "velocities",
]

#: s, the span of the Savitzky-Golay derivative that estimates the joints' accelerations when
#: the log has none (long against the noise of a velocity estimate, short against a ramp).
ACCELERATION_WINDOW = 0.05


def pieces(time: np.ndarray) -> list[slice]:
    """The rows between gaps: steps longer than :data:`~.segment.GAP_FACTOR` median periods."""
    if time.size < 3:
        return [slice(0, time.size)]
    steps = np.diff(time)
    cuts = np.flatnonzero(steps > GAP_FACTOR * float(np.median(steps))) + 1
    edges = [0, *cuts.tolist(), time.size]
    return [slice(a, b) for a, b in itertools.pairwise(edges)]


def named_pieces(arm: RobotLog) -> list[tuple[slice, str]]:
    """:func:`pieces` with the name of the recording each lies in: a joined log's
    (``meta["joined"]``, :func:`fricid.samples.join_robot_logs`), else the log's source."""
    joined = arm.meta.get("joined") if isinstance(arm.meta, dict) else None
    cuts = pieces(arm.time)
    if not joined:
        return [(rows, arm.source or "the log") for rows in cuts]
    starts = np.asarray(joined["starts"], dtype=float)
    out = []
    for rows in cuts:
        k = int(np.searchsorted(starts, arm.time[rows.start], side="right")) - 1
        out.append((rows, str(joined["sources"][max(k, 0)])))
    return out


def joint_chunks(raw: RawLog, named: list[tuple[slice, str]]) -> list[RawLog]:
    """One joint's log cut at the gaps, each chunk named by its recording: what
    :func:`~.pipeline.extract` judges a velocity on (its checks are per source)."""
    if len(named) == 1:
        return [raw]
    return [replace(raw.slice(rows.start, rows.stop), source=name) for rows, name in named]


def velocities(arm: RobotLog) -> tuple[RobotLog, set[str], list[str]]:
    """``arm`` with each joint's coarse-encoder finite-difference velocity replaced by its
    position's least-squares slope (:func:`~.pipeline.velocity_from_position`), the joints
    replaced and the warnings: the arm fit's segments and levels and each joint's samples
    (:func:`~.pipeline.extract`) then read one velocity (with the finite difference, a
    2^17-count encoder at 1 kHz had put a 0.05 rad/s sweep's levels at 0.096 rad/s). Judged
    and estimated on each piece between gaps, as :func:`~.pipeline.extract` judges each
    recording (:func:`joint_chunks`): a joint held in one recording and swept in the next is
    judged on each."""
    velocity = arm.velocity.copy()
    replaced, found = set(), []
    named = named_pieces(arm)
    for j, name in enumerate(arm.joints):
        whole = arm.joint(name, temperature=0.0)
        for rows, source in named:
            part = replace(whole.slice(rows.start, rows.stop), source=f"{source}, {name}")
            part, note = velocity_from_position(part)
            if part.meta.get("velocity_from") == "position":
                velocity[rows, j] = part.velocity
                replaced.add(name)
            if note:
                found.append(note)
    return (replace(arm, velocity=velocity) if replaced else arm), replaced, found


def acceleration(arm: RobotLog) -> np.ndarray:
    """rad/s^2, the logged acceleration, else the velocity's Savitzky-Golay derivative on each
    piece (quadratic over about :data:`ACCELERATION_WINDOW` s; exactly zero where a joint is
    held at zero velocity)."""
    if arm.acceleration is not None:
        return arm.acceleration
    out = np.zeros_like(arm.velocity)
    n = len(arm)
    dt = float(np.median(np.diff(arm.time))) if n > 1 else 1.0
    window = max(5, 2 * round(ACCELERATION_WINDOW / dt / 2) + 1)
    for rows in pieces(arm.time):
        v, t = arm.velocity[rows], arm.time[rows]
        if v.shape[0] >= window:
            out[rows] = savgol_filter(v, window, 2, deriv=1, delta=dt, axis=0, mode="interp")
        elif v.shape[0] > 1:
            out[rows] = np.gradient(v, t, axis=0)
    return out
