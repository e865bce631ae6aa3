"""Standstill rows in a table of friction samples: a "set-point" that is really rest.

A per-direction mean computed over a held joint has a velocity of float residue or encoder
noise (1e-5 rad/s where the slowest real set-point is 1e-2) and the sign of that noise; taken
as a +1 or -1 set-point it pins a model's behaviour at zero speed to the breakaway torque of
whatever held the joint. Extraction from a raw log drops such runs as rest
(:func:`fricid.extract.steady.rest_threshold`); a samples file read from elsewhere is screened
here, by the same relative rule and a gap: a row is standstill when its speed is below
:data:`STANDSTILL_RTOL` times the fastest speed of its direction *and* below
:data:`STANDSTILL_GAP` times the slowest speed of that direction that is not (far below every
other speed, so a logarithmic sweep down to 1e-4 of the fastest keeps its slow decades),
and below :data:`STANDSTILL_MAX` [rad/s] (a speed a joint at rest cannot show as noise is a
set-point, however far below the others).
"""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

from ..errors import DataQualityWarning

__all__ = [
    "STANDSTILL_GAP",
    "STANDSTILL_MAX",
    "STANDSTILL_RTOL",
    "drop_standstill",
    "standstill_rows",
]

#: A standstill row is slower than this share of its direction's fastest speed ...
STANDSTILL_RTOL = 1e-3

#: ... and slower than this share of the slowest other speed of its direction.
STANDSTILL_GAP = 0.05

#: ... and slower than this [rad/s]: far above the velocity noise of a held joint (1e-5).
STANDSTILL_MAX = 1e-2


def standstill_rows(velocity, direction) -> np.ndarray:
    """Boolean mask of the standstill rows (module docstring): slower than
    :data:`STANDSTILL_RTOL` of the fastest speed of their direction and than
    :data:`STANDSTILL_GAP` of the slowest speed there that is not, and than
    :data:`STANDSTILL_MAX`; each direction (+1, -1, 0)
    is judged on its own, and one whose rows would all go is left alone."""
    speed = np.abs(np.asarray(velocity, dtype=float))
    direction = np.asarray(direction, dtype=float)
    mask = np.zeros(speed.size, dtype=bool)
    for d in np.unique(direction):
        idx = np.flatnonzero(direction == d)
        s = speed[idx]
        candidate = (s < STANDSTILL_RTOL * s.max()) & (s < STANDSTILL_MAX)
        if candidate.all() or not candidate.any():
            continue
        mask[idx] = candidate & (s < STANDSTILL_GAP * s[~candidate].min())
    return mask


def drop_standstill(samples, *, stacklevel: int = 2):
    """``samples`` without their standstill rows, with one
    :class:`~fricid.errors.DataQualityWarning` naming the rows dropped (0-based data rows and
    their velocities), the file and why; the samples unchanged when there are none."""
    mask = standstill_rows(samples.velocity, samples.direction)
    if not mask.any() or mask.all():
        return samples
    rows = np.flatnonzero(mask)
    shown = ", ".join(
        f"row {int(i)} ({float(samples.velocity[i]):+.2g} rad/s, direction "
        f"{int(samples.direction[i]):+d})"
        for i in rows[:5]
    )
    more = f" and {rows.size - 5} more" if rows.size > 5 else ""
    where = f"{samples.source}: " if samples.source else ""
    warnings.warn(
        f"{where}dropped {rows.size} standstill row(s): {shown}{more}: speed below "
        f"{STANDSTILL_RTOL:g} of the fastest and {STANDSTILL_GAP:g} of the slowest other speed "
        "of its direction, so rest rather than a set-point (its sign is noise)",
        DataQualityWarning,
        stacklevel=stacklevel + 1,
    )
    kept = samples.subset(~mask)
    return replace(kept, meta={**kept.meta, "dropped_standstill": [int(i) for i in rows]})
