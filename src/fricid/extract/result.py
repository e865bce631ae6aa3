"""What :func:`fricid.extract.extract` returns: the samples, the gravity fit, and what was
found and discarded (:class:`Diagnostics`), with a printable summary."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..samples import FrictionSamples
from .gravity import GravityFit
from .joint_gravity import JointGravityFit
from .quality import QualityTable

__all__ = ["Diagnostics", "ExtractionResult"]


@dataclass(frozen=True, eq=False)
class Diagnostics:
    """What extraction found and discarded.

    Attributes
    ----------
    rows, chunks : int
        Raw samples and log chunks read.
    runs : int
        Runs of one velocity sign examined (including the flicker of a noisy velocity at rest).
    segments : int
        Constant-velocity segments kept as set-point passes.
    dropped : dict of str to int
        Runs dropped, by reason: ``short_run`` (fewer than ``min_samples``), ``no_plateau`` (no
        sample near the plateau), ``short_steady`` (too short after removing ramps and settle
        margins), ``rest`` (standstill), ``unsteady`` (no steady plateau: return moves).
    spikes : int
        Samples the median filter changed by more than ``SPIKE_SIGMAS`` robust sigmas.
    binned, outside_bins : int
        Kept samples inside / outside every position bin.
    velocity_setpoints : numpy.ndarray
        rad/s, the speeds found (cluster medians).
    temperature_setpoints : numpy.ndarray
        degC, the temperatures found.
    passes_min, passes_max : int
        Fewest and most passes averaged into one sample.
    samples : dict of str to int
        Samples kept and dropped over the whole log, by reason (``kept``, ``dropped_rest``,
        ``dropped_transient``, ``dropped_outlier``, ``dropped_saturated``).
    """

    rows: int
    chunks: int
    runs: int
    segments: int
    dropped: dict[str, int]
    spikes: int
    binned: int
    outside_bins: int
    velocity_setpoints: np.ndarray
    temperature_setpoints: np.ndarray
    passes_min: int
    passes_max: int
    samples: dict[str, int] = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class ExtractionResult:
    """The friction samples of a log and how they were obtained.

    Attributes
    ----------
    samples : FrictionSamples
        Combined samples, direction 0 (eq. 11): one row per (temperature, velocity, position
        bin), sorted in that order; velocity and friction of the positive direction.
    by_direction : FrictionSamples
        The same operating points per direction (+1/-1, velocity and friction signed; rows
        ordered as ``samples`` with -1 before +1): ``tau_f+- = tau+- + tau_g`` with the fitted
        gravity, which keeps a drive's asymmetry.
    gravity : GravityFit, JointGravityFit or None
        The eq. 7 fit (eq. 11 pairing, or the joint fit with its per-set-point frictions), or
        None with ``gravity="none"``.
    diagnostics : Diagnostics
        What was read, kept and dropped.
    sem, direction_sem : numpy.ndarray
        N m, standard error of each row's friction from the scatter of the repetitions (the
        noise floor; use it for weighting or tolerances); also in ``samples.meta["sem"]`` and
        ``by_direction.meta["sem"]``, so it is written with the samples.
    position : numpy.ndarray
        rad, mean position of each combined row's samples.
    options : dict
        The extraction options used (also in ``samples.meta["extract"]``).
    quality : QualityTable or None
        Per set-point and direction, samples kept and dropped (rest, transient, outlier,
        saturated) and their scatter (also in ``samples.meta["quality"]``, so it is written
        with the samples).
    notes : tuple of str
        What the user should know about how the result was obtained (e.g. eq. 11 pairing
        impossible, gravity identified jointly instead).
    """

    samples: FrictionSamples
    by_direction: FrictionSamples
    gravity: GravityFit | JointGravityFit | None
    diagnostics: Diagnostics
    sem: np.ndarray
    direction_sem: np.ndarray
    position: np.ndarray
    options: dict[str, Any] = field(default_factory=dict)
    quality: QualityTable | None = None
    notes: tuple[str, ...] = ()

    def summary(self) -> str:
        """A few lines describing the result (for a report or the CLI)."""
        d = self.diagnostics
        combined = (
            "both directions combined"
            if (np.asarray(self.samples.direction) == 0).any()
            else "one direction only"
        )
        lines = [
            f"{_count(len(self.samples), 'sample')} ({combined}; "
            f"{_per_direction(self.by_direction)}) from {_count(d.segments, 'segment')} of "
            f"{_count(d.rows, 'row')}; {_count(d.spikes, 'spike')} filtered",
            f"{_count(d.velocity_setpoints.size, 'velocity set-point')} "
            f"({d.velocity_setpoints.min():.4g}-{d.velocity_setpoints.max():.4g} rad/s), "
            f"{_temperatures(d.temperature_setpoints)}, "
            f"{_passes(d.passes_min, d.passes_max)} per sample",
        ]
        if d.samples:
            n = d.samples
            rest = d.dropped.get("rest", 0) + d.dropped.get("short_run", 0)
            unsteady = sum(d.dropped.get(k, 0) for k in ("unsteady", "no_plateau", "short_steady"))
            lines.append(
                f"samples kept {n['kept']}, dropped: rest {n['dropped_rest']}, transient "
                f"{n['dropped_transient']}, outlier {n['dropped_outlier']}, saturated "
                f"{n['dropped_saturated']}; runs rejected: {rest} at rest or too short, "
                f"{unsteady} without a steady plateau (return moves, aborted moves)"
            )
        if self.gravity is not None:
            g = self.gravity
            how = ""
            if isinstance(g, JointGravityFit):
                how = f", joint fit with {g.friction.size} set-point frictions, no pairing"
            lines.append(
                f"gravity (eq. 7{how}): p_x = {g.p_x:.5g} +- {g.p_x_se:.2g}, "
                f"p_y = {g.p_y:.5g} +- {g.p_y_se:.2g} N m, residual {g.residual_rms:.2g} N m"
            )
        if isinstance(self.gravity, JointGravityFit):
            lines.append(self._joint_frictions())
        lines.extend(f"note: {n}" for n in self.notes)
        if self.quality is not None and self.quality.flagged.any():
            lines.append("set-points flagged (scatter far above their neighbours):")
            lines.append(self.quality.subset(self.quality.flagged).describe())
        return "\n".join(lines)

    def _joint_frictions(self) -> str:
        """The joint fit's friction per set-point and direction, with standard errors."""
        g, d = self.gravity, self.diagnostics
        nv = d.velocity_setpoints.size
        parts = []
        for label, f, se in zip(g.group, g.friction, g.friction_se, strict=True):
            it, rem = divmod(int(label), 2 * nv)
            iv, fwd = divmod(rem, 2)
            v = d.velocity_setpoints[iv] * (1 if fwd else -1)
            temperature = d.temperature_setpoints[it]
            at = f"{temperature:.4g} degC " if np.isfinite(temperature) else ""
            parts.append(f"{at}{v:+.4g} rad/s {f:+.4g}+-{se:.2g}")
        return "set-point friction [N m] (joint fit): " + "; ".join(parts)


def _temperatures(setpoints: np.ndarray) -> str:
    """``2 temperatures``, or ``no temperature logged`` (a log without one)."""
    if setpoints.size and not np.isfinite(setpoints).any():
        return "no temperature logged"
    return _count(setpoints.size, "temperature")


def _count(n: int, noun: str, plural: str | None = None) -> str:
    """``1 temperature``, ``5 temperatures``, ``1,211,640 rows`` (the summary's counts)."""
    n = int(n)
    return f"{n:,} " + (noun if n == 1 else plural or f"{noun}s")


def _per_direction(by_direction: FrictionSamples) -> str:
    """``330 + 330 per-direction samples`` (positive + negative), or the total when one-sided."""
    d = np.asarray(by_direction.direction)
    pos, neg = int((d > 0).sum()), int((d < 0).sum())
    if pos and neg and pos + neg == len(d):
        return f"{pos:,} + {neg:,} per-direction samples"
    return f"{_count(len(d), 'per-direction sample')}"


def _passes(lo: int, hi: int) -> str:
    """``3 passes``, ``1 pass``, ``2-4 passes`` (repetitions averaged into each sample)."""
    lo, hi = int(lo), int(hi)
    if lo == hi:
        return _count(lo, "pass", "passes")
    return f"{lo}-{hi} passes"
