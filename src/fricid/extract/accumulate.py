"""Per-segment work of :func:`fricid.extract.extract` (steps 2-3 of the BAS-RBFNN paper's
section 2), with the trust checks of :mod:`.steady`.

For each candidate segment: median-filter the motor torque ``tau = K I`` (eq. 13), flag samples
pinned at a rail, trim what has not settled, screen outliers, bin the rest by position and keep
the bins' statistics (:class:`~.bins.Cells`). Whether a segment is a set-point, standstill or
an unsteady move is decided in :meth:`Accumulator.classify`, once the log's velocity scale
is known.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ._stats import median, median_filter
from .bins import Cells, CellTable, PositionBins
from .gravity_check import block_stats_of
from .joint_gravity import moments_of, regressors
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
    blocks: np.ndarray | None = None  # :func:`.gravity_check.block_stats` of the kept samples
    source: str | None = None  # the file the segment was read from
    extra: np.ndarray | None = None  # the ``extra`` statistics of the kept samples


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
    extra : callable, optional
        ``extra(segment, keep, tau)`` -> statistics of the segment's kept samples (``keep`` a
        boolean mask over the segment's rows, ``tau`` its filtered motor torque), kept in
        :attr:`Record.extra` (the whole-configuration gravity of :mod:`.arm_gravity`).
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
        extra: Callable[[Segment, np.ndarray, np.ndarray], np.ndarray] | None = None,
    ) -> None:
        self.moments = moments
        self.extra = extra
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
        cos, sin = np.cos(log.position), np.sin(log.position)  # once, for cells and moments
        cells = Cells.of(
            idx, tau, log.position, log.velocity, log.temperature, self.bins.n_bins, cos, sin
        )
        stats = blocks = None
        if self.moments:
            theta = log.position[keep]
            x = regressors(cos[keep], sin[keep], tau[keep])
            stats, blocks = moments_of(x), block_stats_of(theta, x)
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
                moments=stats,
                blocks=blocks,
                source=log.source,
                extra=None if self.extra is None else self.extra(seg, keep, tau),
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
        self.rest_limit = rest_threshold(speed.max(), quantum=quantum, duration=duration)
        rest = speed < self.rest_limit
        band = np.array([r.band_fraction for r in self.records])
        kept = np.array([r.kept for r in self.records])
        self.no_plateau = band < MIN_BAND_FRACTION
        kinds[self.no_plateau | (kept < self.min_samples)] = "unsteady"
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
                for name in (
                    "count",
                    "torque",
                    "m2",
                    "position",
                    "velocity",
                    "temperature",
                    "cos",
                    "sin",
                    "sem",
                )
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
        direction 0. Every row has a label (the files of its runs when they came from several
        files, else its set-point) and a note saying what was merged or why it was dropped."""
        nb = self.bins.n_bins
        nv = v_set.size
        keep = kinds == "setpoint"
        kept = [r for r, k in zip(self.records, keep, strict=True) if k]
        files = {r.source for r in self.records} - {None}
        forward = np.array([r.direction > 0 for r in kept], dtype=np.intp)
        group = (t_label * nv + v_label) * 2 + forward
        scatter, run_scatter = _scatters(cells, nb, int(np.prod((t_set.size, nv, 2))))
        rows = []
        for g in np.unique(group):
            members = [r for r, gi in zip(kept, group, strict=True) if gi == g]
            it, rem = divmod(int(g), 2 * nv)
            iv, fwd = divmod(rem, 2)
            binned = int(sum(r.cells.count.sum() for r in members))
            velocity = float(v_set[iv]) * (1 if fwd else -1)
            rows.append(
                {
                    "kind": "setpoint",
                    "label": _label(members, files, velocity, float(t_set[it])),
                    "temperature": float(t_set[it]),
                    "velocity": velocity,
                    "direction": 1 if fwd else -1,
                    "runs": len(members),
                    "kept": binned,
                    "outside_bins": sum(r.kept for r in members) - binned,
                    "dropped_rest": 0,
                    "dropped_transient": sum(r.transient for r in members),
                    "dropped_outlier": sum(r.outlier for r in members),
                    "dropped_saturated": sum(r.saturated for r in members),
                    "scatter": float(scatter[g]),
                    "run_scatter": float(run_scatter[g]),
                    "note": _merged(members),
                }
            )
        for kind, column in (("rest", "dropped_rest"), ("unsteady", "dropped_transient")):
            for direction in (-1, 1):
                chosen = np.flatnonzero(
                    (kinds == kind) & np.array([r.direction == direction for r in self.records])
                )
                if not chosen.size:
                    continue
                members = [self.records[i] for i in chosen]
                row = dict.fromkeys(QUALITY_COLUMNS, 0)
                row.update(
                    kind=kind,
                    label=_label(members, files, None, None),
                    temperature=float(np.mean([r.temperature for r in members])),
                    velocity=direction * float(np.median([r.speed for r in members])),
                    direction=direction,
                    runs=len(members),
                    scatter=np.nan,
                    run_scatter=np.nan,
                    gravity_residual=np.nan,
                    flagged=False,
                    note=self._dropped_note(kind, chosen),
                )
                row[column] = sum(r.samples for r in members)
                rows.append(row)
        for kind, column, n, why in (
            ("unsteady", "dropped_transient", between[1], _NO_PLATEAU),
            ("between", "dropped_rest", between[0], _BETWEEN),
        ):
            if n:
                row = dict.fromkeys(QUALITY_COLUMNS, 0)
                row.update(kind=kind, label="between runs", temperature=np.nan, velocity=0.0)
                row.update(scatter=np.nan, run_scatter=np.nan, gravity_residual=np.nan)
                row.update(flagged=False, note=why)
                row[column] = int(n)
                rows.append(row)
        return QualityTable.from_rows(rows)

    def _dropped_note(self, kind: str, chosen: np.ndarray) -> str:
        """Why the records ``chosen`` (all rest, or all unsteady) were dropped, with speeds."""
        speeds = _speeds([self.records[i].speed for i in chosen])
        if kind == "rest":
            limit = float(np.max(self.rest_limit[chosen]))
            return (
                f"dropped as standstill: {len(chosen)} run(s) at {speeds} rad/s, below the rest "
                f"threshold {limit:.2g} rad/s (1e-3 of the fastest run, or under one encoder "
                "step over the run)"
            )
        flat = int(self.no_plateau[chosen].sum())
        parts = []
        if flat:
            parts.append(f"{flat} without a steady plateau (return or aborted moves)")
        if len(chosen) - flat:
            parts.append(
                f"{len(chosen) - flat} with fewer than min_samples={self.min_samples} samples "
                "left after trimming ramps, settling, outliers and rail samples"
            )
        return f"dropped as transient: {len(chosen)} run(s) at {speeds} rad/s: " + ", ".join(parts)


_NO_PLATEAU = "dropped as transient: runs without a velocity plateau (found at segmentation)"
_BETWEEN = "samples between runs: zero velocity, or runs shorter than min_samples"


def _scatters(cells: CellTable, nb: int, size: int) -> tuple[np.ndarray, np.ndarray]:
    """Per set-point: the samples' scatter about their cell means, and the scatter of the
    runs' (passes') means about their cell means (NaN for a single run), pooled over cells."""
    cell_group = cells.group // nb
    has = cells.count > 0
    m2 = np.bincount(cell_group, weights=cells.m2, minlength=size)
    n = np.bincount(cell_group, weights=cells.count, minlength=size)
    k = np.bincount(cell_group[has], minlength=size)
    g, cg, c, t = cells.group[has], cell_group[has], cells.count[has], cells.torque[has]
    cell_n = np.bincount(g, weights=c, minlength=g.max(initial=0) + 1)
    cell_mean = np.bincount(g, weights=c * t, minlength=cell_n.size) / np.maximum(cell_n, 1)
    cell_k = np.bincount(g, minlength=cell_n.size)
    dev2 = np.bincount(cg, weights=(t - cell_mean[g]) ** 2, minlength=size)
    dof = np.bincount(cg, weights=(cell_k[g] - 1.0) / np.maximum(cell_k[g], 1), minlength=size)
    with np.errstate(invalid="ignore", divide="ignore"):
        scatter = np.where(n - k > 0, np.sqrt(m2 / np.maximum(n - k, 1)), np.nan)
        runs = np.where(dof > 0.5, np.sqrt(dev2 / np.maximum(dof, 1e-300)), np.nan)
    return scatter, runs


def _speeds(speeds: list[float], limit: int = 6) -> str:
    """``0.1, 0.2, 0.4`` (sorted, at most ``limit``, then how many more)."""
    s = sorted(speeds)
    text = ", ".join(f"{v:.3g}" for v in s[:limit])
    return text + (f" and {len(s) - limit} more" if len(s) > limit else "")


def _label(members: list[Record], files: set, velocity: float | None, temperature) -> str:
    """A row's label: the files of its runs when the log came from several files, else its
    set-point (``+0.2 rad/s, 25 degC``; ``+0.2 rad/s`` without a temperature) or, for dropped
    runs, their speeds."""
    if len(files) > 1:
        names = sorted({str(r.source).replace("\\", "/").rsplit("/", 1)[-1] for r in members})
        return ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
    if velocity is None:
        return f"runs at {_speeds([r.speed for r in members], 3)} rad/s"
    if not np.isfinite(temperature):  # the log has none
        return f"{velocity:+.4g} rad/s"
    return f"{velocity:+.4g} rad/s, {temperature:.4g} degC"


def _merged(members: list[Record]) -> str:
    """What a set-point row averaged: one run, or runs merged and their speed range."""
    if len(members) == 1:
        return "1 run"
    speeds = [r.speed for r in members]
    return f"{len(members)} runs merged ({min(speeds):.4g}-{max(speeds):.4g} rad/s)"
