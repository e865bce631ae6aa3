""":func:`join_robot_logs`: several recordings of one robot as one :class:`RobotLog`.

Sweeps of an arm are often recorded one joint per file (the first joint swept in one
session, the second in the next). The gravity parameters they share are only determined by
all of them together (one joint's sweeps leave directions of the base gravity parameters
that only the other joint's move), so the recordings are read as one log: each after the
previous, with a gap of :data:`SEAM_PERIODS` sample periods between them. The extraction ends
a steady run at any step in time longer than ten median sample periods
(``fricid.extract.segment.GAP_FACTOR``), so no run, set-point or derivative spans two
recordings: a sweep cut off at the end of one file and one begun at the start of the next
stay two runs.

What has to agree: the joints (any column order; each recording's missing or extra joints are
named), the sample rate (within :data:`RATE_RTOL`: the extraction reads gaps against the
median period), and whether a temperature was logged (all or none: ``fricid robot extract
--temperature`` fills it in for the recordings without one before they are joined). No
recording may hold rows of another (:data:`SHARED_ROWS`). A torque logged in one file and
a current with its torque constant in another are both read as motor torque (eq. 13 of the
BAS-RBFNN paper); an acceleration or load column that not every file has is left out (the
extraction then differentiates the velocity, piece by piece), and the log's ``meta`` says so.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import DataError
from .robot_log import RobotLog

__all__ = ["RATE_RTOL", "SEAM_PERIODS", "SHARED_ROWS", "join_robot_logs"]

#: Sample periods between the last sample of one recording and the first of the next: ten
#: times the extraction's gap (``GAP_FACTOR`` = 10 periods), so a rate at the edge of
#: :data:`RATE_RTOL` still reads it as a gap.
SEAM_PERIODS = 100

#: Rows in motion two recordings may share (bit for bit) before one is taken for a copy of
#: the other (all of a recording's rows in motion when it has fewer).
SHARED_ROWS = 10

#: Relative difference of the recordings' median sample periods that is still one rate.
RATE_RTOL = 0.01


def _name(log: RobotLog, k: int) -> str:
    return log.source or f"log {k + 1}"


def _period(log: RobotLog, k: int) -> float:
    if len(log) < 2:
        raise DataError(f"{len(log)} sample(s): nothing to join", file=_name(log, k))
    return float(np.median(np.diff(log.time)))


def _same_joints(first: RobotLog, log: RobotLog, k: int) -> RobotLog:
    missing = [j for j in first.joints if j not in log.joints]
    extra = [j for j in log.joints if j not in first.joints]
    if missing or extra:
        parts = [f"no column for {', '.join(missing)}"] if missing else []
        parts += [f"joints the first log has not: {', '.join(extra)}"] if extra else []
        raise DataError(
            f"its joints are not those of {_name(first, 0)} ({'; '.join(parts)}): every "
            "recording of one robot must log the same joints",
            file=_name(log, k),
        )
    return log.select(first.joints)


def _moving_rows(log: RobotLog) -> np.ndarray:
    """The distinct rows where a joint moves, each its positions and torques as one opaque
    (bytewise) item: sorted, for :func:`numpy.intersect1d`."""
    rows = np.flatnonzero(np.any(log.velocity != 0.0, axis=1))
    both = np.ascontiguousarray(np.hstack([log.position[rows], log.motor_torque[rows]]))
    return np.unique(both.view(np.dtype((np.void, both.dtype.itemsize * both.shape[1]))))


def _no_shared_samples(logs: list[RobotLog]) -> None:
    """Refuse a recording that holds samples of another: the same file twice, or a copy of
    part of one (the first half saved apart, say). Rows where a joint moves are compared
    whole (every joint's position and torque, bit for bit): two recordings share such a row
    only by copying, as a joint at rest may repeat its quantised position and torque."""
    seen = [_moving_rows(log) for log in logs]
    for k in range(1, len(logs)):
        for i in range(k):
            shared = np.intersect1d(seen[k], seen[i], assume_unique=True).size
            if shared >= min(SHARED_ROWS, max(seen[k].size, 1)):
                raise DataError(
                    f"{shared} of its {seen[k].size} rows in motion are rows of "
                    f"{_name(logs[i], i)}, bit for bit: the same recording given twice, or a "
                    "copy of part of one; every shared run would count twice (its interval "
                    "shrinking as if it had been measured twice). Give each recording once",
                    file=_name(logs[k], k),
                )


def _stacked(logs: list[RobotLog], name: str) -> np.ndarray | None:
    columns = [getattr(log, name) for log in logs]
    return None if any(c is None for c in columns) else np.concatenate(columns)


def join_robot_logs(logs: Sequence[RobotLog]) -> RobotLog:
    """The recordings one after another, as one log (module notes).

    Parameters
    ----------
    logs : sequence of RobotLog
        Recordings of one robot, in the order to join them (at least one).

    Returns
    -------
    RobotLog
        One log: the joints in the first recording's order; the first recording's time as it
        is, each other's shifted to begin :data:`SEAM_PERIODS` sample periods after the
        previous one ends; the source the
        recordings' names joined by ``" + "``; ``meta["joined"]`` the recordings' sources,
        where each begins in the joined time (``"starts"``) and any column left out. A single
        recording is returned as it is.

    Raises
    ------
    DataError
        No recording; a recording with fewer than two samples; one that holds
        :data:`SHARED_ROWS` rows in motion of another (given twice, or a partial copy);
        joints that differ (each
        missing or extra one named, with the file); sample rates that differ by more than
        :data:`RATE_RTOL` (both named); a temperature in some recordings and not in others.
    """
    logs = list(logs)
    if not logs:
        raise DataError("no robot log to join")
    if len(logs) == 1:
        return logs[0]
    first = logs[0]
    periods = [_period(log, k) for k, log in enumerate(logs)]
    aligned = [first] + [_same_joints(first, log, k) for k, log in enumerate(logs[1:], 1)]
    for k, (log, period) in enumerate(zip(aligned, periods, strict=True)):
        if abs(period - periods[0]) > RATE_RTOL * periods[0]:
            raise DataError(
                f"sampled at {1 / period:.6g} Hz, {_name(first, 0)} at {1 / periods[0]:.6g} Hz: "
                "recordings joined into one log need one rate (resample one, or extract them "
                "separately)",
                file=_name(log, k),
            )
    _no_shared_samples(aligned)
    with_temperature = [log.temperature is not None for log in aligned]
    if any(with_temperature) and not all(with_temperature):
        k = with_temperature.index(False)
        raise DataError(
            f"no temperature, and {_name(aligned[with_temperature.index(True)], 0)} has one: "
            "give every recording its temperature column, or none (then --temperature holds "
            "for all)",
            file=_name(aligned[k], k),
        )
    times, starts, t_next = [], [], float(first.time[0])  # the first keeps its clock
    for log in aligned:
        shift = t_next - float(log.time[0])
        times.append(log.time + shift)
        starts.append(t_next)
        t_next = float(times[-1][-1]) + SEAM_PERIODS * periods[0]
    torque_logged = all(log.torque is not None for log in aligned)
    left_out = [
        name
        for name in ("acceleration", "load")
        if _stacked(aligned, name) is None
        and any(getattr(log, name) is not None for log in aligned)
    ]
    joined = {
        "sources": [_name(log, k) for k, log in enumerate(aligned)],
        "starts": starts,
        "left_out": left_out,
    }
    return RobotLog(
        time=np.concatenate(times),
        joints=first.joints,
        position=np.concatenate([log.position for log in aligned]),
        velocity=np.concatenate([log.velocity for log in aligned]),
        torque=np.concatenate(
            [log.torque if torque_logged else log.motor_torque for log in aligned]
        ),
        acceleration=_stacked(aligned, "acceleration"),
        temperature=_stacked(aligned, "temperature"),
        load=_stacked(aligned, "load"),
        source=" + ".join(joined["sources"]),
        meta={**first.meta, "joined": joined},
    )
