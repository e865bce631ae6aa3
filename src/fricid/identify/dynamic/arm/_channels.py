"""A robot log's channels checked against each other and the URDF before a whole-arm fit.

Mistakes of units, sign or channel give a whole-arm fit that fits well and is wrong (the
gravity and inertia of every joint are read at the logged positions), so they are found
before it:

- a torque (or current) channel with one value in every row was not logged: refused
  (:func:`check_live_torque`), since its rows would pull every shared inertial parameter;
- a logged velocity that is not the position's derivative (:func:`fricid.samples.
  velocity_mismatch`: a unit, a sign, a gear ratio) and a position beyond the URDF's limits by
  more than :data:`LIMIT_SLACK` of their span plus :data:`LIMIT_MARGIN` (degrees labelled
  radians, an offset zero, another robot's URDF), and a position that jumps by more than pi
  where the velocity does not (an angle wrapped to one turn) make the joint's verdict ``no``
  with the reason (:func:`channel_problems`).
"""

from __future__ import annotations

import numpy as np

from ....errors import DataError
from ....robot import RigidBodyModel
from ....samples import RobotLog, position_unit_problem, velocity_mismatch, wrapped_rows
from ....samples.robot_log import joint_column

__all__ = [
    "LIMIT_MARGIN",
    "LIMIT_SLACK",
    "channel_problems",
    "check_live_torque",
    "with_channel_problems",
]

#: How far past a URDF limit a logged position may go: this share of the limits' span plus
#: :data:`LIMIT_MARGIN` [rad or m] (a joint at its hard stop, an encoder's offset of a few
#: counts); an offset zero of 0.35-0.58 rad had passed under a slack of 10 %.
LIMIT_SLACK = 0.02
LIMIT_MARGIN = 0.02


def check_live_torque(log: RobotLog, joints: tuple[str, ...]) -> None:
    """Refuse a joint whose torque (or current) has one value in every row.

    Raises
    ------
    DataError
        Naming the log and ``<joint>.torque`` (or ``.current``) and the value.
    """
    quantity = "torque" if log.torque is not None else "current"
    channel = log.torque if log.torque is not None else log.current
    for name in joints:
        values = channel[:, log.index(name)]
        if values.size and np.ptp(values) == 0:
            raise DataError(
                f"the {quantity} is {float(values[0])!r} in every one of the {values.size} rows: "
                "the channel was not logged, and its rows would pull every joint's inertial "
                "parameters; log it, or identify the arm without this joint",
                file=log.source,
                column=joint_column(name, quantity),
            )


def channel_problems(log: RobotLog, model: RigidBodyModel) -> dict[str, list[str]]:
    """Per joint of ``model``, what makes its channels disagree (module notes); empty lists
    where nothing does."""
    logged_velocity = "velocity_from" not in log.meta
    out: dict[str, list[str]] = {}
    for j, name in enumerate(model.joints):
        k = log.index(name)
        q = log.position[:, k]
        found = []
        if logged_velocity:
            found.append(velocity_mismatch(log.time, q, log.velocity[:, k], column=name))
        wraps = wrapped_rows(log.time, q, log.velocity[:, k])
        if wraps.size:
            found.append(
                f"{name}: the position jumps by more than pi at {wraps.size} rows (first at row "
                f"{int(wraps[0])}) where the velocity does not: an angle wrapped to one turn; "
                "unwrap it (numpy.unwrap)"
            )
        unit = position_unit_problem(q)
        if unit:
            found.append(f"{name}: the position: {unit}")
        lo, hi = float(model.lower[j]), float(model.upper[j])
        if np.isfinite(lo) and np.isfinite(hi) and hi > lo:
            slack = LIMIT_SLACK * (hi - lo) + LIMIT_MARGIN
            qmin, qmax = float(q.min()), float(q.max())
            if qmin < lo - slack or qmax > hi + slack:
                found.append(
                    f"{name}: the position spans [{qmin:.4g}, {qmax:.4g}], beyond the URDF's "
                    f"limits [{lo:.4g}, {hi:.4g}]: a position in degrees labelled radians, a "
                    "zero offset between the encoder and the URDF, or another robot's URDF"
                )
        out[name] = [f for f in found if f]
    return out


def with_channel_problems(err: DataError, log: RobotLog, model: RigidBodyModel) -> DataError:
    """``err`` with the channels' disagreements (:func:`channel_problems`) added, which may be its
    cause (positions in degrees labelled radians make a log look too short or still)."""
    try:
        found = [p for joint in channel_problems(log, model).values() for p in joint]
    except DataError:
        return err
    if not found:
        return err
    return DataError(
        f"{err.message}; the log's channels also disagree, which may be why: {'; '.join(found)}",
        file=err.file,
        row=err.row,
        column=err.column,
    )
