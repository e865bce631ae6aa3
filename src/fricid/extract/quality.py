"""The per-set-point quality table of an extraction: what was kept, what was dropped and why.

Every extraction path (:func:`fricid.extract.extract` and the steady-state EPOS folder reader
:func:`fricid.io.epos_steady_samples`) reports, per set-point, how many samples were averaged
and how many were dropped as rest, transient, outlier or saturated, with the scatter of the
kept samples; :func:`flag_scatter` marks set-points whose scatter is far above their
neighbours' (:data:`SCATTER_RATIO`), and :func:`warn_quality` turns findings into one
:class:`~fricid.errors.DataQualityWarning` naming the file and the set-points.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field, fields, replace
from typing import Any

import numpy as np

from ..errors import DataQualityWarning, user_stacklevel

__all__ = ["QUALITY_COLUMNS", "SCATTER_RATIO", "QualityTable", "flag_scatter", "warn_quality"]

#: A set-point whose scatter exceeds this multiple of the median scatter of its neighbours
#: (same temperature and direction, up to two set-points on each side) is flagged. The real
#: lead-screw recordings stay below 2.5 (their noisiest file, 2 rpm, against 10 rpm); a single
#: spike of 12x the nominal torque left in a 500-row file raises it about 30-fold.
SCATTER_RATIO = 4.0

#: N m; scatter below this is numerical noise (a noiseless simulation) and never flagged.
SCATTER_FLOOR = 1e-9

#: Columns of :meth:`QualityTable.rows`, in order, with their units.
QUALITY_COLUMNS: dict[str, str] = {
    "kind": "",
    "label": "",
    "temperature": "degC",
    "velocity": "rad/s",
    "direction": "",
    "runs": "",
    "kept": "",
    "outside_bins": "",
    "dropped_rest": "",
    "dropped_transient": "",
    "dropped_outlier": "",
    "dropped_saturated": "",
    "scatter": "N m",
    "run_scatter": "N m",
    "gravity_residual": "N m",
    "flagged": "",
    "note": "",
}

_TEXT = ("kind", "label", "note")
_FLOATS = ("temperature", "velocity", "scatter", "run_scatter", "gravity_residual")

#: Kinds of rows: a set-point whose samples were averaged, standstill rejected as rest,
#: runs without a steady plateau (return moves, aborted moves), and samples between runs.
KINDS = ("setpoint", "rest", "unsteady", "between")


@dataclass(frozen=True, eq=False)
class QualityTable:
    """Per-set-point bookkeeping of an extraction, one row per set-point and direction.

    Attributes
    ----------
    kind : numpy.ndarray
        str, ``setpoint`` (its kept samples were averaged), ``rest`` (standstill: runs slower
        than the rest threshold, all samples dropped), ``unsteady`` (runs without a steady
        plateau, e.g. return moves), ``between`` (samples outside every run: zero velocity,
        runs too short to have a plateau).
    label : numpy.ndarray
        str, what the row is (a file name for one-file-per-set-point data, else empty).
    temperature : numpy.ndarray
        degC, mean temperature of the row's runs.
    velocity : numpy.ndarray
        rad/s, signed set-point velocity (median plateau of its runs; 0 for ``between``).
    direction : numpy.ndarray
        +1, -1 (0 for ``between``).
    runs : numpy.ndarray
        runs (passes, files) of the row.
    kept : numpy.ndarray
        samples averaged into the friction.
    outside_bins : numpy.ndarray
        good samples outside every position bin (not averaged; by design, the traverse
        extends beyond the bins).
    dropped_rest, dropped_transient, dropped_outlier, dropped_saturated : numpy.ndarray
        samples dropped: standstill (and samples between runs); ramps, settling and return
        moves (and a rest or drift merged into a move's run by its sign, trimmed with the
        ramp); outliers (:func:`fricid.extract.steady.outliers`); pinned at a rail
        (:func:`fricid.extract.steady.saturated`).
    scatter : numpy.ndarray
        N m, standard deviation of the kept samples' torque about their cell means (NaN
        without kept samples).
    run_scatter : numpy.ndarray
        N m, standard deviation of the merged runs' means about their cell means (NaN for a
        single run): what merging runs into one set-point averaged away.
    gravity_residual : numpy.ndarray
        N m, RMS of what the gravity fit (eq. 7) left along the position in this set-point's
        samples (:mod:`fricid.extract.gravity_check`; NaN without a gravity fit).
    flagged : numpy.ndarray
        bool, scatter (or, for merged runs, the scatter between them) above
        :data:`SCATTER_RATIO` times the neighbours'.
    note : numpy.ndarray
        str, why the row is what it is: the runs merged (and their speeds), the reason runs
        were dropped (standstill below the rest threshold, no steady plateau, too short after
        trimming), and why it is flagged.
    """

    kind: np.ndarray
    label: np.ndarray
    temperature: np.ndarray
    velocity: np.ndarray
    direction: np.ndarray
    runs: np.ndarray
    kept: np.ndarray
    outside_bins: np.ndarray
    dropped_rest: np.ndarray
    dropped_transient: np.ndarray
    dropped_outlier: np.ndarray
    dropped_saturated: np.ndarray
    scatter: np.ndarray
    run_scatter: np.ndarray = field(default_factory=lambda: np.zeros(0))
    gravity_residual: np.ndarray = field(default_factory=lambda: np.zeros(0))
    flagged: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    note: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=object))

    @classmethod
    def from_rows(cls, rows: Sequence[dict[str, Any]]) -> QualityTable:
        """Build from dicts keyed by :data:`QUALITY_COLUMNS` (``label``, ``flagged``, ``note``,
        ``run_scatter`` and ``gravity_residual`` optional)."""
        cols: dict[str, Any] = {}
        for f in fields(cls):
            default = {"label": "", "flagged": False, "note": ""}.get(f.name, np.nan)
            values = [r.get(f.name, default) for r in rows]
            values = [np.nan if v is None and f.name not in _TEXT else v for v in values]
            if f.name in _TEXT:
                cols[f.name] = np.array(values, dtype=object)
            elif f.name == "flagged":
                cols[f.name] = np.array(values, dtype=bool)
            else:
                cols[f.name] = np.array(values, dtype=float)
        return cls(**cols)

    def __len__(self) -> int:
        return int(self.kind.size)

    @property
    def setpoints(self) -> np.ndarray:
        """bool mask of the ``setpoint`` rows."""
        return self.kind == "setpoint"

    def subset(self, mask: np.ndarray) -> QualityTable:
        """The rows where ``mask`` is true."""
        return QualityTable(**{f.name: getattr(self, f.name)[mask] for f in fields(self)})

    def with_gravity_residual(self, values) -> QualityTable:
        """The table with ``gravity_residual`` [N m] set on the set-point rows, in order."""
        column = np.full(len(self), np.nan)
        column[np.flatnonzero(self.setpoints)] = np.asarray(values, dtype=float)
        return replace(self, gravity_residual=column)

    def totals(self) -> dict[str, int]:
        """Samples kept and dropped (by reason) over the whole table."""
        names = ("kept", "dropped_rest", "dropped_transient", "dropped_outlier")
        return {n: int(getattr(self, n).sum()) for n in (*names, "dropped_saturated")}

    def rows(self) -> list[dict[str, Any]]:
        """The table as JSON-ready dicts (for the samples' metadata and the CSV)."""
        out = []
        for i in range(len(self)):
            row: dict[str, Any] = {}
            for name in QUALITY_COLUMNS:
                value = getattr(self, name)[i]
                if name in _TEXT:
                    row[name] = str(value)
                elif name == "flagged":
                    row[name] = bool(value)
                elif name in _FLOATS:
                    row[name] = None if not np.isfinite(value) else float(value)
                else:
                    row[name] = int(value)
            out.append(row)
        return out

    def to_csv(self) -> str:
        """The table as CSV text, units in the header (``velocity [rad/s]``)."""
        head = ",".join(f"{n} [{u}]" if u else n for n, u in QUALITY_COLUMNS.items())
        lines = [head]
        for row in self.rows():
            cells = []
            for name in QUALITY_COLUMNS:
                v = row[name]
                if v is None:
                    cells.append("")
                elif isinstance(v, float):
                    cells.append(repr(v))
                elif isinstance(v, str):
                    cells.append('"' + v.replace('"', '""') + '"' if "," in v or '"' in v else v)
                else:
                    cells.append(str(v))
            lines.append(",".join(cells))
        return "\n".join(lines) + "\n"

    def accounting(self, limit: int = 12) -> list[str]:
        """Every set-point accounted for, one line each: the set-points kept and how many merge
        several runs, then each flagged set-point and each dropped group with its reason (at
        most ``limit`` lines of those)."""
        sp = self.setpoints
        merged = sp & (self.runs > 1)
        head = f"set-points: {int(sp.sum())} kept"
        if merged.any():
            lo, hi = int(self.runs[merged].min()), int(self.runs[merged].max())
            runs = f"{lo}" if lo == hi else f"{lo}-{hi}"
            head += f", {int(merged.sum())} of them merge {runs} runs each"
        lines = [head]
        for i in np.flatnonzero((sp & self.flagged) | ~sp):
            dropped = int(self.dropped_rest[i] + self.dropped_transient[i])
            what = f"flagged {self.label[i]}" if sp[i] else f"{self.kind[i]} ({self.label[i]})"
            count = f" [{dropped} samples]" if not sp[i] else ""
            lines.append(f"  {what}: {self.note[i]}{count}")
        if len(lines) > limit + 1:
            lines = [*lines[: limit + 1], f"  ... {len(lines) - limit - 1} more (quality table)"]
        return lines

    def describe(self, limit: int = 40) -> str:
        """A fixed-width text table (at most ``limit`` rows; flagged rows first)."""
        head = (
            f"{'kind':<9}{'T degC':>8}{'v rad/s':>12}{'dir':>4}{'runs':>5}{'kept':>8}"
            f"{'rest':>7}{'trans':>7}{'outl':>6}{'sat':>6}{'scatter':>11}  flag"
        )
        order = np.argsort(~self.flagged, kind="stable")[:limit]
        lines = [head]
        for i in order:
            scatter = f"{self.scatter[i]:.3g}" if np.isfinite(self.scatter[i]) else "-"
            t = f"{self.temperature[i]:.4g}" if np.isfinite(self.temperature[i]) else "-"
            lines.append(
                f"{self.kind[i]:<9}{t:>8}{self.velocity[i]:>12.4g}"
                f"{int(self.direction[i]):>4}{int(self.runs[i]):>5}{int(self.kept[i]):>8}"
                f"{int(self.dropped_rest[i]):>7}{int(self.dropped_transient[i]):>7}"
                f"{int(self.dropped_outlier[i]):>6}{int(self.dropped_saturated[i]):>6}"
                f"{scatter:>11}  {'HIGH' if self.flagged[i] else ''}"
                + (f" {self.label[i]}" if self.label[i] else "")
                + (f": {self.note[i]}" if self.note[i] else "")
            )
        if len(self) > limit:
            lines.append(f"... {len(self) - limit} more rows")
        return "\n".join(lines)


def flag_scatter(table: QualityTable, ratio: float = SCATTER_RATIO) -> QualityTable:
    """The table with ``flagged`` set where a set-point's scatter exceeds ``ratio`` times the
    median scatter of its neighbours: the set-points of the same temperature and direction,
    ordered by speed, up to two on each side (a set-point without neighbours, or with a scatter
    below :data:`SCATTER_FLOOR`, is never flagged).

    Merged runs are also flagged when the scatter *between* them (``run_scatter``, the spread
    of the runs' means) exceeds ``ratio`` times the typical spread, the larger of their
    sample scatter and their own ``run_scatter``, both of the neighbours and of all the log's
    set-points (the median): a ``run_scatter`` from two or three runs is rough (the virtual
    joint's per-run offsets give 0.002-0.03 N m between neighbours), the log's median is not.
    Each flag's reason is appended to ``note``."""
    flagged = np.zeros(len(table), dtype=bool)
    note = table.note.copy()
    sp = np.flatnonzero(table.setpoints & np.isfinite(table.scatter))
    temps = np.round(np.nan_to_num(table.temperature[sp], nan=np.inf), 6)  # none: one group
    spread = np.fmax(table.scatter, table.run_scatter)
    typical = float(np.median(spread[sp])) if sp.size else np.nan
    for key in set(zip(temps.tolist(), table.direction[sp].tolist(), strict=True)):
        group = sp[(temps == key[0]) & (table.direction[sp] == key[1])]
        group = group[np.argsort(np.abs(table.velocity[group]))]
        s, between, ref = table.scatter[group], table.run_scatter[group], spread[group]
        for j, row in enumerate(group):
            near = np.r_[max(j - 2, 0) : j, j + 1 : min(j + 3, group.size)]
            if not near.size:
                continue
            limit = ratio * float(np.median(s[near]))
            if s[j] > max(limit, SCATTER_FLOOR):
                flagged[row] = True
                note[row] = _append(note[row], f"scatter {s[j]:.3g} N m, >{ratio:g}x neighbours'")
            limit = ratio * max(float(np.median(ref[near])), typical)
            if np.isfinite(between[j]) and between[j] > max(limit, SCATTER_FLOOR):
                flagged[row] = True
                note[row] = _append(
                    note[row],
                    f"the merged runs' means scatter {between[j]:.3g} N m, "
                    f">{ratio:g}x neighbours' (runs at different conditions merged?)",
                )
    columns = {f.name: getattr(table, f.name) for f in fields(table)}
    return QualityTable(**{**columns, "flagged": flagged, "note": note})


def _append(text: str, more: str) -> str:
    return f"{text}; {more}" if text else more


def _name(table: QualityTable, i: int) -> str:
    v = float(table.velocity[i])
    t = float(table.temperature[i])
    where = f"{v:+.4g} rad/s" + (f" at {t:.4g} degC" if np.isfinite(t) else "")
    return f"{table.label[i]} ({where})" if table.label[i] else where


def warn_quality(
    table: QualityTable, source: str | None, *, stacklevel: int = 2, gravity=None
) -> None:
    """Warn once (:class:`~fricid.errors.DataQualityWarning`) when a set-point's scatter is far
    above its neighbours', samples were dropped as outliers or saturated, or the gravity fit
    left a pattern along the position (``gravity``, a
    :class:`~fricid.extract.gravity_check.GravityResidual`); the message names the file and
    the set-points (at most five) and says what to do. It points at the first caller outside
    fricid (:func:`fricid.errors.user_stacklevel`; ``stacklevel`` is kept for callers that
    pass it)."""
    parts = []
    if gravity is not None and gravity.message():
        parts.append(gravity.message())
    where = f"{source}: " if source else ""
    high = np.flatnonzero(table.flagged)
    if high.size:
        names = "; ".join(_name(table, i) for i in high[:5])
        more = f" and {high.size - 5} more" if high.size > 5 else ""
        parts.append(
            f"{high.size} set-point(s) (or the runs merged into them) scatter more than "
            f"{SCATTER_RATIO:g}x their neighbours: "
            f"{names}{more} (check those runs for disturbances before trusting their friction)"
        )
    for column, what in (
        ("dropped_outlier", "outlier samples"),
        ("dropped_saturated", "samples pinned at a sensor or current limit"),
    ):
        counts = getattr(table, column)
        hit = np.flatnonzero(counts > 0)
        if hit.size:
            names = "; ".join(f"{int(counts[i])} at {_name(table, i)}" for i in hit[:5])
            more = f" and {hit.size - 5} more set-points" if hit.size > 5 else ""
            parts.append(f"dropped {int(counts.sum())} {what}: {names}{more}")
    if parts:
        message = where + ". ".join(parts) + " (see the quality table)"
        warnings.warn(message, DataQualityWarning, stacklevel=user_stacklevel())
