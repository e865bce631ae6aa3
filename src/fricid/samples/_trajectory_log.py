"""Checks of a trajectory log before identification allocates anything: time holes and
steps out of order, the size of the uniform grid, a torque or current channel stuck
while the joint moves (each a :class:`~fricid.errors.DataError` naming the row), and a logged
velocity that is not the position's derivative (:mod:`._agreement`).
"""

from __future__ import annotations

import numpy as np

from ..errors import DataError
from ._agreement import velocity_mismatch, wrapped_rows
from ._columns import RAWLOG_COLUMNS
from ._encoder_steps import position_unit_problem
from .rawlog import RawLog


def own_position(log: RawLog) -> bool:
    """The position is the log's own channel (not integrated from the velocity by a reader:
    ``meta["position_source"]``)."""
    meta = log.meta if isinstance(log.meta, dict) else {}
    return meta.get("position_source", "channel") == "channel"


#: A time step over this many times the median step is a hole in a trajectory log.
HOLE_FACTOR = 5.0

#: Most samples a trajectory log may have on its uniform grid (40 MB per column).
MAX_TRAJECTORY_SAMPLES = 5_000_000

#: A torque or current channel that holds one value for at least this many rows of a
#: trajectory log while the velocity sweeps :data:`STUCK_SWEEP` of its range is stuck: inertia
#: and friction change the torque whenever the velocity changes. Judged on a channel whose
#: finest step is at most :data:`STUCK_QUANTUM` of its range (a coarser one holds its levels
#: for a while by itself). Measured on the virtual joint (``fricid simulate --trajectory``):
#: on the 2 s multi-sine 30 stuck rows moved the inertia by up to 60 %, 10 rows by at most
#: 6 % (on the 20 s one, 100 rows by 27 %); on the six 20 s trajectories, a live current in
#: steps of 0.5 % of its range or finer never held 20 rows while the velocity swept 5 %.
STUCK_MIN_SAMPLES = 20
STUCK_SWEEP = 0.05
STUCK_QUANTUM = 0.005


def check_trajectory_log(log: RawLog) -> None:
    """Refuse a log that a trajectory identification would turn into a wrong answer.

    A trajectory is differentiated and resampled on one uniform grid, so its log must be one
    continuous recording with a live torque (or current) channel:

    - no hole: a time step over :data:`HOLE_FACTOR` times the median step (a pause, a lost
      stretch, a moved stamp) would be bridged by interpolation, inventing a motion; the log
      is refused with the row after the hole named (cut it there and fit each part: the log
      is not split into runs here, each run would need its own filter edges);
    - at most :data:`MAX_TRAJECTORY_SAMPLES` samples on the uniform grid, checked before
      anything is allocated;
    - a torque or current channel that varies: one value in every row, or (a channel in
      steps of at most :data:`STUCK_QUANTUM` of its range) one value over
      :data:`STUCK_MIN_SAMPLES` rows or more while the velocity sweeps :data:`STUCK_SWEEP` of
      its range, is a stuck sensor (or a saturated drive), refused with the rows named;
    - a logged velocity (not one a reader computed from the position, ``meta["velocity_from"]``)
      that is not the position's derivative: a unit, a sign or a gear ratio between the two
      (:func:`._agreement.velocity_mismatch`), refused with the factor and its likely cause,
      since the fit reads both and would be off by the factor; a position that jumps by
      more than pi where the velocity does not (an angle wrapped to one turn:
      :func:`._agreement.wrapped_rows`), refused with the row; a position whose steps are
      a binary encoder's counts in degrees or revolutions labelled radians
      (:func:`._encoder_steps.position_unit_problem`: its velocity, in the same unit,
      agrees with it), refused naming the unit.

    Parameters
    ----------
    log : RawLog
        The log (time strictly increasing: :class:`RawLog` checks that).

    Raises
    ------
    DataError
        Naming the log's source, the row (0-based sample index) and the column.
    """
    _check_time_grid(log)
    _check_stuck_effort(log)
    wraps = wrapped_rows(log.time, log.position, log.velocity)
    if wraps.size:
        row = int(wraps[0])
        raise DataError(
            f"the position jumps by {float(log.position[row] - log.position[row - 1]):.4g} rad "
            f"while the velocity says {float(log.velocity[row]):.4g} rad/s ({wraps.size} such "
            "jumps): an angle wrapped to one turn; unwrap it (numpy.unwrap) before the fit, "
            "which differentiates the position",
            file=log.source,
            row=row,
            column="position",
        )
    if "velocity_from" not in log.meta:
        wrong = velocity_mismatch(log.time, log.position, log.velocity)
        if wrong:
            raise DataError(
                f"{wrong}; correct the unit or sign in the column's header (a motor-side "
                "velocity: divide it by the gear ratio)",
                file=log.source,
                column="velocity",
            )
    unit = position_unit_problem(log.position) if own_position(log) else None
    if unit:
        raise DataError(
            f"{unit}; give the column's unit in its header ('position [deg]', and the "
            "velocity's if it is in the same unit), or the reader's unit option",
            file=log.source,
            column="position",
        )


def _check_time_grid(log: RawLog) -> None:
    t, n = log.time, len(log)
    if n < 2:
        return
    steps = np.diff(t)
    dt = float(np.median(steps))
    big = np.flatnonzero(steps > HOLE_FACTOR * dt)
    if big.size:
        i = int(big[np.argmax(steps[big])])
        raise DataError(
            f"time jumps by {steps[i]:.6g} s (from {float(t[i])!r} to {float(t[i + 1])!r} s), over "
            f"{HOLE_FACTOR:g} times the median step {dt:.3g} s: a trajectory must be one "
            "continuous recording; cut the log at this row and fit each part",
            file=log.source,
            row=i + 1,
            column="time",
        )
    grid = (float(t[-1]) - float(t[0])) / dt + 1
    if max(grid, n) > MAX_TRAJECTORY_SAMPLES:
        raise DataError(
            f"the trajectory has {max(grid, n):.4g} samples on its uniform grid (step "
            f"{dt:.3g} s), over the {MAX_TRAJECTORY_SAMPLES} identified at once: cut or "
            "decimate the log",
            file=log.source,
            column="time",
        )


def _check_stuck_effort(log: RawLog) -> None:
    name = "torque" if log.torque is not None else "current"
    x, n = getattr(log, name), len(log)
    unit = RAWLOG_COLUMNS[name]
    if n > 1 and float(np.ptp(x)) == 0.0:
        raise DataError(
            f"the {name} is {float(x[0]):.6g} {unit} in every row: a stuck sensor, or not the "
            "measured one; a trajectory needs the measured torque or current",
            file=log.source,
            column=name,
        )
    steps = np.abs(np.diff(x))
    live = steps[steps > 0]
    if not live.size or float(live.min()) > STUCK_QUANTUM * float(np.ptp(x)):
        return  # a coarse channel: its levels last by themselves
    span = float(np.ptp(log.velocity))
    change = np.flatnonzero(steps > 0) + 1
    starts, stops = np.r_[0, change], np.r_[change, n]
    v = log.velocity
    sweeps = np.maximum.reduceat(v, starts) - np.minimum.reduceat(v, starts)  # per held run
    stuck = (stops - starts >= STUCK_MIN_SAMPLES) & (sweeps >= STUCK_SWEEP * span)
    if span > 0 and stuck.any():
        k = int(np.argmax(stuck))
        a, b, sweep = int(starts[k]), int(stops[k]), float(sweeps[k])
        raise DataError(
            f"the {name} holds {float(x[a]):.6g} {unit} for rows {a} to {b - 1} "
            f"({float(log.time[b - 1] - log.time[a]):.3g} s) while the velocity changes by "
            f"{sweep:.3g} rad/s: a stuck sensor or a saturated drive; cut that stretch out",
            file=log.source,
            row=a,
            column=name,
        )
