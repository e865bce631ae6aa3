"""Per-segment work of :func:`fricid.extract.extract` (steps 2-3 of the BAS-RBFNN paper's
section 2), with the trust checks of :mod:`.steady`.

For each candidate segment: median-filter the motor torque ``tau = K I`` (eq. 13), flag samples
pinned at a rail, trim what has not settled, screen outliers, bin the rest by position and keep
the bins' statistics (:class:`~.bins.Cells`). Whether a segment is a set-point, standstill or
an unsteady move is decided in :meth:`Accumulator.classify`, once the log's velocity scale
is known.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._stats import median, median_filter
from .bins import Cells, CellTable, PositionBins
from .joint_gravity import moments
from .quality import QUALITY_COLUMNS, QualityTable
from .segment import Segment
from .steady import OUTLIER_SIGMAS, SETTLE_SIGMAS, outliers, rest_threshold, saturated, settled

__all__ = ["SPIKE_SIGMAS", "Accumulator", "Record"]

#: A filtered sample differing from the raw one by more than this many robust standard
#: deviations (1.4826 MAD of the differences) is counted as a spike in the diagnostics.
SPIKE_SIGMAS = 8.0

#: A segment with fewer of its steady part's samples inside the velocity band than this share
#: is not at constant velocity (a move without a plateau, such as a return move).
MIN_BAND_FRACTION = 0.5


def count_spikes(raw: np.ndarray, filtered: np.ndarray) -> int:
    """Samples the filter moved by more than SPIKE_SIGMAS robust sigmas (1.4826 MAD of the
    changes; for quantised or noiseless data with MAD 0, the median nonzero change)."""
    r = np.abs(raw - filtered)
    scale = 1.4826 * median(r)
    if scale == 0.0:
        nonzero = r[r > 0]
        if nonzero.size == 0:
            return 0
        scale = median(nonzero)
    return int(np.count_nonzero(r > SPIKE_SIGMAS * scale))


@dataclass(frozen=True, eq=False)
class Record:
    """One candidate segment's bookkeeping (samples by fate, scatter, its cells)."""

    speed: float
    direction: int
    temperature: float
    duration: float
    band_fraction: float
    samples: int  # samples of the whole run
    transient: int  # trimmed: ramps, settle margins, unsettled blocks
    outlier: int
    saturated: int
    kept: int  # kept samples (inside or outside the position bins)
    cells: Cells
    spikes: int
    moments: np.ndarray | None = None  # :func:`.joint_gravity.moments` of the kept samples


class Accumulator:
    """Collects :class:`Record` s of segments; :meth:`classify` sorts them once all are in.

    Parameters
    ----------
    bins : PositionBins
        The position bins.
    window : int
        Running-median window on the torque (1: none).
    outlier_sigmas : float or None
        Threshold of :func:`~.steady.outliers` (None: no outlier screening).
    settle_sigmas : float or None
        Threshold of :func:`~.steady.settled` (None: no settling detection).
    min_samples : int
        Fewest samples a segment must keep after the checks.
    moments : bool
        Also keep each segment's :func:`~.joint_gravity.moments` (for ``gravity="joint"``).
    """

    def __init__(
        self,
        bins: PositionBins,
        window: int,
        *,
        outlier_sigmas: float | None = OUTLIER_SIGMAS,
        settle_sigmas: float | None = SETTLE_SIGMAS,
        min_samples: int = 20,
        moments: bool = False,
    ) -> None:
        self.moments = moments
        self.bins = bins
        self.window = window
        self.outlier_sigmas = outlier_sigmas
        self.settle_sigmas = settle_sigmas
        self.min_samples = min_samples
        self.records: list[Record] = []
        self.quantum = np.inf  # smallest nonzero position step seen [rad]

    def add(self, seg: Segment) -> None:
        """Check and bin one segment."""
        log = seg.log
        raw = log.motor_torque  # eq. 13
        if self.window > 1:
            tau = median_filter(raw, self.window)
            spikes = count_spikes(raw, tau)
        else:
            tau, spikes = raw, 0
        n = len(log)
        keep = np.ones(n, dtype=bool)
        a, b = 0, n
        if self.settle_sigmas is not None:
            a, b = settled(
                log.time, log.position, log.velocity, tau, raw, sigmas=self.settle_sigmas
            )
        keep[:a] = keep[b:] = False
        sat = saturated(raw) & keep
        keep &= ~sat
        out = np.zeros(n, dtype=bool)
        if self.outlier_sigmas is not None and b > a:
            out[a:b] = outliers(tau[a:b], raw[a:b], sigmas=self.outlier_sigmas)
            out &= keep
        keep &= ~out
        step = np.abs(np.diff(log.position))
        step = step[step > 1e-12]
        if step.size:
            self.quantum = min(self.quantum, float(step.min()))
        idx = self.bins.assign(log.position)
        idx = np.where(keep, idx, -1)
        cells = Cells.of(idx, tau, log.position, log.velocity, log.temperature, self.bins.n_bins)
        self.records.append(
            Record(
                speed=seg.speed,
                direction=seg.direction,
                temperature=float(np.mean(log.temperature)),
                duration=seg.run_duration,
                band_fraction=seg.band_fraction,
                samples=max(seg.run_samples, n),
                transient=seg.trimmed + n - (b - a),
                outlier=int(out.sum()),
                saturated=int(sat.sum()),
                kept=int(keep.sum()),
                cells=cells,
                spikes=spikes,
                moments=moments(log.position[keep], tau[keep]) if self.moments else None,
            )
        )

    def classify(self) -> np.ndarray:
        """Kind of each record (object array): ``rest`` when its speed is below
        :func:`~.steady.rest_threshold` (relative to the fastest candidate and the encoder's
        smallest step), ``unsteady`` when fewer than :data:`MIN_BAND_FRACTION` of its steady
        part is inside the velocity band or fewer than ``min_samples`` samples survive the
        checks, else ``setpoint``."""
        kinds = np.array(["setpoint"] * len(self.records), dtype=object)
        if not self.records:
            return kinds
        speed = np.array([r.speed for r in self.records])
        duration = np.array([r.duration for r in self.records])
        quantum = max(self.quantum if np.isfinite(self.quantum) else 0.0, 1e-12)
        rest = speed < rest_threshold(speed.max(), quantum=quantum, duration=duration)
        band = np.array([r.band_fraction for r in self.records])
        kept = np.array([r.kept for r in self.records])
        kinds[(band < MIN_BAND_FRACTION) | (kept < self.min_samples)] = "unsteady"
        kinds[rest] = "rest"
        return kinds

    def table(self, keep: np.ndarray, t_label, v_label, shape) -> CellTable:
        """The kept records' cells, each labelled with its group (temperature, velocity,
        direction, bin)."""
        _, nv, nb = shape
        chosen = [r for r, k in zip(self.records, keep, strict=True) if k]
        forward = (np.array([r.direction for r in chosen]) > 0).astype(np.intp)
        first = ((t_label * nv + v_label) * 2 + forward) * nb
        return CellTable(
            group=(first[:, None] + np.arange(nb)[None, :]).ravel(),
            **{
                name: np.concatenate([getattr(r.cells, name) for r in chosen])
                for name in ("count", "torque", "m2", "position", "velocity", "temperature")
            },
        )

    def quality(
        self,
        kinds: np.ndarray,
        t_label: np.ndarray,
        v_label: np.ndarray,
        t_set: np.ndarray,
        v_set: np.ndarray,
        cells: CellTable,
        between: tuple[int, int],
    ) -> QualityTable:
        """The per-set-point quality table: one row per (temperature, velocity, direction) of
        the kept records, in the samples' order, then one per direction of rest and unsteady
        records, then the samples ``between`` = (at rest between runs, in runs dropped at
        segmentation for want of a plateau), as an ``unsteady`` and a ``between`` row of
        direction 0."""
        nb = self.bins.n_bins
        nv = v_set.size
        keep = kinds == "setpoint"
        kept = [r for r, k in zip(self.records, keep, strict=True) if k]
        forward = np.array([r.direction > 0 for r in kept], dtype=np.intp)
        group = (t_label * nv + v_label) * 2 + forward
        # scatter about the cell means, pooled over each set-point's cells
        cell_group = cells.group // nb
        size = int(np.prod((t_set.size, nv, 2)))
        has = cells.count > 0
        m2 = np.bincount(cell_group, weights=cells.m2, minlength=size)
        n = np.bincount(cell_group, weights=cells.count, minlength=size)
        k = np.bincount(cell_group[has], minlength=size)
        with np.errstate(invalid="ignore", divide="ignore"):
            scatter = np.where(n - k > 0, np.sqrt(m2 / np.maximum(n - k, 1)), np.nan)
        rows = []
        for g in np.unique(group):
            members = [r for r, gi in zip(kept, group, strict=True) if gi == g]
            it, rem = divmod(int(g), 2 * nv)
            iv, fwd = divmod(rem, 2)
            binned = int(sum(r.cells.count.sum() for r in members))
            rows.append(
                {
                    "kind": "setpoint",
                    "temperature": float(t_set[it]),
                    "velocity": float(v_set[iv]) * (1 if fwd else -1),
                    "direction": 1 if fwd else -1,
                    "runs": len(members),
                    "kept": binned,
                    "outside_bins": sum(r.kept for r in members) - binned,
                    "dropped_rest": 0,
                    "dropped_transient": sum(r.transient for r in members),
                    "dropped_outlier": sum(r.outlier for r in members),
                    "dropped_saturated": sum(r.saturated for r in members),
                    "scatter": float(scatter[g]),
                }
            )
        for kind, column in (("rest", "dropped_rest"), ("unsteady", "dropped_transient")):
            for direction in (-1, 1):
                members = [
                    r
                    for r, kd in zip(self.records, kinds, strict=True)
                    if kd == kind and r.direction == direction
                ]
                if not members:
                    continue
                row = dict.fromkeys(QUALITY_COLUMNS, 0)
                row.update(
                    kind=kind,
                    label="",
                    temperature=float(np.mean([r.temperature for r in members])),
                    velocity=direction * float(np.median([r.speed for r in members])),
                    direction=direction,
                    runs=len(members),
                    scatter=np.nan,
                    flagged=False,
                )
                row[column] = sum(r.samples for r in members)
                rows.append(row)
        for kind, column, n in (
            ("unsteady", "dropped_transient", between[1]),
            ("between", "dropped_rest", between[0]),
        ):
            if n:
                row = dict.fromkeys(QUALITY_COLUMNS, 0)
                row.update(kind=kind, label="", temperature=np.nan, velocity=0.0)
                row.update(scatter=np.nan, flagged=False)
                row[column] = int(n)
                rows.append(row)
        return QualityTable.from_rows(rows)
