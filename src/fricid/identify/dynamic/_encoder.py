"""The measurement model of a trajectory log: the encoder's resolution and how the velocity
was formed from its counts.

A drive logs the position quantised to its encoder, ``q_k = c_k Delta`` with ``c_k`` an
integer count and ``Delta = 2 pi / N`` for ``N`` counts per revolution, and usually the
velocity by differences of those counts. The rounding error of one reading is uniform on
``[-Delta/2, Delta/2]`` (variance ``Delta^2 / 12``; Widrow and Kollar 2008, ch. 4); a
backward difference ``(q_k - q_{k-1}) / dt`` carries ``2 Delta^2 / (12 dt^2)``, and any
linear derivative filter with taps ``h`` carries ``Delta^2 / 12 sum h_j^2``.

:func:`encoder_quantum` finds ``Delta`` from the log's own position steps (every step a
whole multiple of the smallest); :func:`measurement` records it (or the ``encoder_counts``
given) with the velocity's form and the propagated quantisation errors: of the logged
velocity, of the parallel filter's acceleration regressor, and of the bristle state driven
by the measured motion (an error of ``Delta / sqrt(12)`` in the bristles' deflection is
``sigma_0 Delta / sqrt(12)`` of torque: at 2^17 counts/rev and sigma_0 = 2e4 N m/rad, 0.28 N m,
of the order of the Coulomb level, which is why a coarse encoder can leave sigma_0 and sigma_1
undetermined by an equation error however long the log). :func:`quantise` reproduces the
measurement on a simulated motion, for the bias check by simulation at the estimate
(:mod:`._rate`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...errors import ConfigError
from ...samples import encoder_quantum

__all__ = ["VELOCITY_FORMS", "encoder_quantum", "measurement", "quantise", "velocity_form"]

#: Relative distance of the counts read from a power of two within which they are taken as
#: that power (a log written with 7 decimals read 2^20 as 1048597: 2e-5 off).
POWER_SNAP = 1e-4

#: Relative amount by which the position's steps may be finer than the counts given before
#: the counts are refused (a 4096-count log taken for 1024 had been accepted without a word).
FINER = 0.01

#: How the logged velocity can be formed from the positions.
VELOCITY_FORMS = ("backward", "central", "logged")


def velocity_form(position: np.ndarray, velocity: np.ndarray, dt: float) -> str:
    """How the logged velocity relates to the positions: ``backward`` (``(q_k - q_{k-1}) /
    dt``), ``central`` (:func:`numpy.gradient`) or ``logged`` (neither: the drive's own)."""
    scale = max(float(np.max(np.abs(velocity))), 1e-12)
    back = np.diff(position) / dt
    tol = 1e-3 * scale  # the columns' rounding in a written log
    if np.max(np.abs(velocity[1:] - back)) <= tol:
        return "backward"
    if np.max(np.abs(velocity - np.gradient(position, dt))) <= tol:
        return "central"
    return "logged"


def quantise(position: np.ndarray, quantum: float, offset: float = 0.0) -> np.ndarray:
    """``position`` read by an encoder of ``quantum`` [rad] whose counts sit at ``offset +
    k quantum`` (rounding to the nearest count)."""
    return offset + np.round((np.asarray(position) - offset) / quantum) * quantum


def measurement(
    position: np.ndarray, velocity: np.ndarray, dt: float, encoder_counts: float | None
) -> dict[str, Any]:
    """The log's measurement model (module notes), as recorded in the provenance.

    Parameters
    ----------
    position, velocity : ndarray (n,)
        The logged position [rad] and velocity [rad/s] on a uniform grid.
    dt : float
        Sample period [s].
    encoder_counts : float, optional
        Counts per revolution given by the user; None reads them from the position steps.

    Returns
    -------
    dict
        ``counts_per_rev`` (None: no quantisation found), ``quantum`` [rad], ``source``
        (``option``, ``position steps`` or ``none found``), ``offset`` [rad] (where the
        counts sit), ``velocity_form``, ``velocity_std`` [rad/s] (the logged velocity's
        quantisation error).

    Raises
    ------
    ConfigError
        ``encoder_counts`` not a positive finite number, or coarser than the position's own
        steps.
    """
    form = velocity_form(position, velocity, dt)
    if encoder_counts is not None:
        if not (math.isfinite(encoder_counts) and encoder_counts > 0):
            raise ConfigError(f"encoder_counts must be a positive number, got {encoder_counts}")
        quantum, source = 2.0 * math.pi / float(encoder_counts), "option"
        seen = encoder_quantum(position)
        if seen is not None and seen < quantum * (1.0 - FINER):
            own = 2.0 * math.pi / seen
            raise ConfigError(
                f"{encoder_counts:g} encoder counts per revolution give steps of {quantum:.4g} "
                f"rad, but the position moves in steps of {seen:.4g} rad ({own:.6g} counts per "
                "revolution): leave the counts out to read them from the position, or give the "
                "encoder's own"
            )
    else:
        quantum, source = encoder_quantum(position), "position steps"
    if quantum is None:
        return {
            "counts_per_rev": None,
            "quantum": None,
            "source": "none found",
            "velocity_form": form,
        }
    counts = 2.0 * math.pi / quantum
    power = 2.0 ** round(math.log2(counts))
    if source != "option" and abs(counts / power - 1.0) <= POWER_SNAP:
        counts, quantum = power, 2.0 * math.pi / power  # a binary encoder, read to rounding
    elif abs(counts - round(counts)) <= 1e-3 * counts:
        counts = float(round(counts))
    offset = float(position[0] - np.round(position[0] / quantum) * quantum)
    std = quantum / math.sqrt(12.0)
    v_std = {"backward": math.sqrt(2.0) * std / dt, "central": std / (math.sqrt(2.0) * dt)}
    return {
        "counts_per_rev": counts,
        "quantum": quantum,
        "source": source,
        "offset": offset,
        "velocity_form": form,
        "velocity_std": v_std.get(form),
    }


def measured_velocity(position: np.ndarray, velocity: np.ndarray, dt: float, form: str):
    """The velocity a drive of velocity form ``form`` logs for ``position`` (``logged``: the
    given ``velocity``, unchanged)."""
    if form == "backward":
        return np.concatenate([velocity[:1], np.diff(position) / dt])
    if form == "central":
        return np.gradient(position, dt)
    return velocity
