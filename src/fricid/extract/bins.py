"""Position bins and the statistics accumulated in them (vectorised, no loop over samples).

Each segment (one pass at one velocity) contributes one *cell* per position bin: sample count,
mean and sum of squared deviations (M2) of the torque, and means of position, velocity,
temperature and of ``cos`` and ``sin`` of the position (the gravity torque of eq. 7 is linear in
those two, so its mean over a cell's samples is exact however wide the cell). Cells are then
pooled over repetitions into set-point groups with Chan's parallel formulas, which are exact
and independent of the order or chunking of the data.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError
from ..metrics import sem_autocorrelated

__all__ = [
    "SEM_MIN_SAMPLES",
    "CellTable",
    "Cells",
    "Pooled",
    "PositionBins",
    "cell_sem",
    "pool_cells",
]


@dataclass(frozen=True, eq=False)
class PositionBins:
    """Position bins ``[c - halfwidth, c + halfwidth]`` around sorted ``centres`` [rad], or one
    automatic bin (``centres=None``) holding a whole steady segment (the right choice for a
    horizontal joint or a steady-state file).

    ``halfwidth`` defaults to half the smallest spacing of the centres (adjacent bins); a single
    centre needs it given. Bins may not overlap.
    """

    centres: np.ndarray | None = None
    halfwidth: float | None = None

    def __post_init__(self) -> None:
        if self.centres is None:
            return
        c = np.atleast_1d(np.asarray(self.centres, dtype=float))
        if c.ndim != 1 or c.size == 0 or not np.isfinite(c).all():
            raise ConfigError("positions must be a non-empty 1-D array of finite angles [rad]")
        c = np.sort(c)
        if np.any(np.diff(c) <= 0):
            raise ConfigError("positions must be distinct")
        spacing = float(np.diff(c).min()) if c.size > 1 else None
        hw = self.halfwidth
        if hw is None:
            if spacing is None:
                raise ConfigError("a single position needs bin_halfwidth [rad]")
            hw = spacing / 2.0
        hw = float(hw)
        if not (np.isfinite(hw) and hw > 0):
            raise ConfigError(f"bin_halfwidth must be a positive angle [rad], got {hw!r}")
        if spacing is not None and hw > spacing / 2.0 * (1 + 1e-9):
            raise ConfigError(
                f"bin_halfwidth {hw:.6g} rad makes the position bins overlap; "
                f"use at most half the smallest spacing, {spacing / 2:.6g} rad"
            )
        object.__setattr__(self, "centres", c)
        object.__setattr__(self, "halfwidth", hw)

    @property
    def auto(self) -> bool:
        return self.centres is None

    @property
    def n_bins(self) -> int:
        return 1 if self.centres is None else int(self.centres.size)

    def assign(self, position: np.ndarray) -> np.ndarray:
        """Bin index of each position, -1 outside every bin."""
        position = np.asarray(position, dtype=float)
        if self.centres is None:
            return np.zeros(position.shape, dtype=np.intp)
        c = self.centres
        mid = 0.5 * (c[1:] + c[:-1])
        idx = np.searchsorted(mid, position)
        inside = np.abs(position - c[idx]) <= self.halfwidth
        return np.where(inside, idx, -1)


@dataclass(frozen=True, eq=False)
class Cells:
    """Per-bin statistics of one segment, arrays of shape (n_bins,)."""

    count: np.ndarray
    torque: np.ndarray  # mean
    m2: np.ndarray  # sum of squared deviations from the mean
    position: np.ndarray
    velocity: np.ndarray
    temperature: np.ndarray
    cos: np.ndarray | None = None  # mean cos(position)
    sin: np.ndarray | None = None  # mean sin(position)
    sem: np.ndarray | None = None  # standard error of the mean: :func:`cell_sem`

    @classmethod
    def of(
        cls, idx, torque, position, velocity, temperature, n_bins: int, cos=None, sin=None
    ) -> Cells:
        """Accumulate samples (bin index ``idx``, -1 skipped) with ``np.bincount``; ``cos``
        and ``sin`` of the positions when already computed."""
        sem = cell_sem(idx, torque, position, n_bins)
        keep = idx >= 0
        idx = idx[keep]
        count = np.bincount(idx, minlength=n_bins).astype(float)
        safe = np.maximum(count, 1.0)

        def mean(x: np.ndarray) -> np.ndarray:
            return np.bincount(idx, weights=x[keep], minlength=n_bins) / safe

        tau = torque[keep]
        m = np.bincount(idx, weights=tau, minlength=n_bins) / safe
        m2 = np.bincount(idx, weights=(tau - m[idx]) ** 2, minlength=n_bins)
        return cls(
            count,
            m,
            m2,
            mean(position),
            mean(velocity),
            mean(temperature),
            mean(np.cos(position) if cos is None else cos),
            mean(np.sin(position) if sin is None else sin),
            sem,
        )


#: Fewest samples of a cell for :func:`cell_sem` (fewer: NaN, and ``std / sqrt(n)``).
SEM_MIN_SAMPLES = 16


def cell_sem(idx: np.ndarray, torque: np.ndarray, position: np.ndarray, n_bins: int) -> np.ndarray:
    """Standard error [N m] of each bin's mean torque over one pass, ``(n_bins,)``: of the
    torque about its trend in position within the bin (``1, q, cos q, sin q`` by least
    squares: eq. 7's gravity and a slope, which are the pass's shape, not its noise), in time
    order, by :func:`fricid.metrics.sem_autocorrelated` (the larger of the AR(1) and
    batch-means standard errors), scaled by ``sqrt(n / (n - 4))`` for the trend's columns.

    ``std / sqrt(n)`` of the torque counts every sample as independent; after the
    extraction's running median of 5 white noise leaves the mean about 2.1 times less
    certain than that says (2,000 draws of 1,800 samples), and a drive's own noise is rarely
    white. :func:`pool_cells` takes the larger of the two: ``std`` holds gravity's slope
    across a position bin, and eq. 11 pairs the two directions' means in a bin as if at one
    position, so where their mean positions differ that slope is an error of the friction
    which this standard error, about the trend, leaves out. Measured (12 seeds of a
    3-5 speed sweep with eq. 7's gravity, 0.05 N m noise at 100 Hz; the set-points' errors
    over their standard errors, a standard deviation of 1 being right): a staircase without
    gravity 2.06 -> 0.89 (``std / sqrt(n)`` -> the larger); one bin per traverse with the
    joint gravity fit 3.56 -> 1.13 (with :func:`.gravity.gravity_se`); 11 position bins 0.98
    -> 0.84, where this alone gave 1.65. NaN where a bin has fewer than
    :data:`SEM_MIN_SAMPLES` samples.
    """
    out = np.full(n_bins, np.nan)
    inside = np.flatnonzero(idx >= 0)
    order = inside[np.argsort(idx[inside], kind="stable")]  # by bin, in time order within
    counts = np.bincount(idx[inside], minlength=n_bins)
    for b, rows in enumerate(np.split(order, np.cumsum(counts)[:-1])):
        n = rows.size
        if n < SEM_MIN_SAMPLES:
            continue
        q = position[rows]
        A = np.column_stack([np.ones(n), q - q.mean(), np.cos(q), np.sin(q)])
        coef = np.linalg.lstsq(A, torque[rows], rcond=1e-10)[0]
        out[b] = sem_autocorrelated(torque[rows] - A @ coef) * np.sqrt(n / (n - A.shape[1]))
    return out


@dataclass(frozen=True, eq=False)
class CellTable:
    """Cells of many segments stacked: arrays (n_cells,) plus the group each cell belongs to."""

    group: np.ndarray
    count: np.ndarray
    torque: np.ndarray
    m2: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    temperature: np.ndarray
    cos: np.ndarray | None = None  # mean cos(position); None: cos of the mean position
    sin: np.ndarray | None = None
    sem: np.ndarray | None = None  # :func:`cell_sem`; None: std / sqrt(n) for one pass


@dataclass(frozen=True, eq=False)
class Pooled:
    """Group statistics, arrays (n_groups,); groups without samples have count 0 and NaNs."""

    count: np.ndarray  # raw samples
    passes: np.ndarray  # cells (passes) with samples
    torque: np.ndarray  # pooled mean
    std: np.ndarray  # pooled sample standard deviation of the raw samples
    sem: np.ndarray  # standard error of the mean from the scatter of the per-pass means
    position: np.ndarray
    velocity: np.ndarray
    temperature: np.ndarray
    cos: np.ndarray  # mean cos(position) of the samples
    sin: np.ndarray  # mean sin(position) of the samples


def pool_cells(cells: CellTable, n_groups: int) -> Pooled:
    """Pool cells into groups (Chan et al.'s parallel mean and variance, vectorised).

    The mean is over all raw samples of a group (the repetitions' samples averaged together).
    ``sem`` is ``sqrt(sum w_i (m_i - M)^2 / (k - 1))`` over its k passes with weights
    ``w_i = n_i / N`` (the scatter of the pass means, which captures per-pass offsets and
    correlated noise that ``std / sqrt(N)`` would miss); for a single pass, the larger of the
    cell's own :func:`cell_sem` and ``std / sqrt(N)`` (its notes say why both).
    """
    g, n = cells.group, cells.count
    has = n > 0
    g, n = g[has], n[has]

    def total(x: np.ndarray) -> np.ndarray:
        return np.bincount(g, weights=x, minlength=n_groups)

    cos = np.cos(cells.position) if cells.cos is None else cells.cos
    sin = np.sin(cells.position) if cells.sin is None else cells.sin
    count = total(n)
    passes = np.bincount(g, minlength=n_groups).astype(float)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = total(n * cells.torque[has]) / count
        dev2 = n * (cells.torque[has] - mean[g]) ** 2
        between = total(dev2)
        m2 = total(cells.m2[has]) + between
        std = np.sqrt(m2 / np.maximum(count - 1.0, 1.0))
        single = std / np.sqrt(count)
        if cells.sem is not None:
            own = cells.sem[has]
            found = total(np.isfinite(own).astype(float)) > 0
            single = np.where(found, np.fmax(total(np.nan_to_num(own)), single), single)
        sem = np.where(passes > 1, np.sqrt(between / count / np.maximum(passes - 1.0, 1.0)), single)
        pooled = Pooled(
            count=count,
            passes=passes,
            torque=mean,
            std=std,
            sem=sem,
            position=total(n * cells.position[has]) / count,
            velocity=total(n * cells.velocity[has]) / count,
            temperature=total(n * cells.temperature[has]) / count,
            cos=total(n * cos[has]) / count,
            sin=total(n * sin[has]) / count,
        )
    return pooled
