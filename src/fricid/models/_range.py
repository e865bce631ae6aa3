"""Inputs against the operating range a model was identified on (issue 11, defect 8):
:func:`range_violations`, behind :meth:`fricid.fitted.FittedModel.range_check`.

Mathematics on the inputs and the recorded ranges only (numbers in, :class:`RangeViolation`
out); the model file, its warnings and the command line use it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._base import INPUTS

__all__ = [
    "GAP_FACTOR",
    "GAP_MIN_RATIO",
    "RANGE_TOLERANCE",
    "SIDES",
    "RangeViolation",
    "coverage_text",
    "gap_pairs",
    "gaps_note",
    "in_gap",
    "range_violations",
    "speed_coverage",
]

#: Relative tolerance of :meth:`FittedModel.range_check`: inputs within this fraction of the
#: identified span (or of the value, for a single value) beyond an edge are inside.
RANGE_TOLERANCE = 0.01

_UNITS = {"velocity": "rad/s", "load": "N m", "temperature": "degC"}

#: A gap in the measured speeds: consecutive measured speeds more than this ratio apart ...
GAP_MIN_RATIO = 2.0
#: ... and more than this many times the design's median step (on log speed) apart.
GAP_FACTOR = 1.5

#: The sides of a :func:`speed_coverage` record and how messages name them.
SIDES = {"pos": "v > 0", "neg": "v < 0", "both": "|v|"}


def speed_coverage(velocity, directions: Sequence[int] = ()) -> dict[str, dict[str, list]]:
    """The measured speeds of each direction: their range and the gaps inside it.

    Parameters
    ----------
    velocity : array_like
        The samples' velocities [rad/s] (zero ignored).
    directions : sequence of int
        The samples' directions; ``[0]`` (combined samples, an odd model) gives one entry
        ``"both"`` on ``|v|``, anything else ``"pos"`` and ``"neg"`` by the sign of ``v``.

    Returns
    -------
    dict
        Side -> ``{"range": [low, high], "gaps": [[a, b], ...]}`` [rad/s]; a gap is a pair
        of consecutive measured speeds more than :data:`GAP_MIN_RATIO` apart and more than
        :data:`GAP_FACTOR` times the design's median step both on log speed and on speed (a
        geometric sweep of ratio 1.4 has gaps where two speeds are over 2x apart, one of ratio
        1.67 over 2.16x, so that 2 to 5 rad/s in it is a gap; a linear sweep has none, not
        even its first step from a slow speed, 0.2 to 1.05 rad/s in steps of 1.05).
    """
    v = np.asarray(velocity, dtype=float).ravel()
    v = v[np.isfinite(v) & (v != 0)]
    if sorted(set(int(d) for d in directions)) == [0]:
        groups = {"both": np.abs(v)}
    else:
        groups = {"pos": v[v > 0], "neg": -v[v < 0]}
    out = {}
    for side, speeds in groups.items():
        if not speeds.size:
            continue
        s = np.unique(speeds)
        steps = np.diff(np.log(s))
        limit = (
            max(np.log(GAP_MIN_RATIO), GAP_FACTOR * float(np.median(steps))) if steps.size else 0
        )
        wide = np.diff(s) > GAP_FACTOR * float(np.median(np.diff(s))) if steps.size else steps > 0
        gaps = [[float(s[i]), float(s[i + 1])] for i in np.flatnonzero((steps > limit) & wide)]
        out[side] = {"range": [float(s[0]), float(s[-1])], "gaps": gaps}
    return out


def gap_pairs(coverage: Any, side: str) -> list[tuple[float, float]]:
    """The well-formed gaps ``(a, b)`` [rad/s] of one side of a :func:`speed_coverage`
    record (a file's record may be damaged: anything else is passed over)."""
    rec = coverage.get(side) if isinstance(coverage, dict) else None
    gaps = rec.get("gaps") if isinstance(rec, dict) else None
    pairs = [_pair({"g": g}, "g") for g in gaps or []]
    return [p for p in pairs if p is not None]


def gaps_note(coverage: Any, side: str) -> str:
    """``"; nothing measured between a and b rad/s"`` for each gap of one side of a
    :func:`speed_coverage` record; "" when it has none (or no such side)."""
    return "".join(
        f"; nothing measured between {a:.4g} and {b:.4g} rad/s"
        for a, b in gap_pairs(coverage, side)
    )


def coverage_text(coverage: Any) -> list[str]:
    """One line per side of a :func:`speed_coverage` record: its range and gaps."""
    if not isinstance(coverage, dict):
        return []
    lines = []
    for side, label in SIDES.items():
        rec = coverage.get(side)
        pair = _pair(rec, "range") if isinstance(rec, dict) else None
        if pair is None:
            continue
        tail = "; ".join(
            f"nothing between {a:.4g} and {b:.4g}" for a, b in gap_pairs(coverage, side)
        )
        lines.append(
            f"{label}: measured {pair[0]:.4g} to {pair[1]:.4g} rad/s"
            + (f" ({tail})" if tail else " (no gaps)")
        )
    return lines


def in_gap(velocity, coverage: Any) -> np.ndarray:
    """Which ``velocity`` values [rad/s] lie in a gap between measured speeds of their
    side of a :func:`speed_coverage` record (by the tolerance of :func:`range_violations`);
    all False without a record."""
    v = np.asarray(velocity, dtype=float)
    out = np.zeros(v.shape, bool)
    if not isinstance(coverage, dict):
        return out
    speed = np.abs(v)
    for side in SIDES:
        mask = {"pos": v > 0, "neg": v < 0, "both": v != 0}[side]
        for a, b in gap_pairs(coverage, side):
            out |= mask & (speed > a * (1 + RANGE_TOLERANCE)) & (speed < b * (1 - RANGE_TOLERANCE))
    return out


def _coverage_violations(v: np.ndarray, coverage: dict) -> list[RangeViolation]:
    """Speeds below the slowest measured one of their direction, or in a gap between
    measured speeds (:func:`speed_coverage`)."""
    out = []
    for side, rec in coverage.items():
        pair = _pair(rec, "range") if isinstance(rec, dict) else None
        if side not in SIDES or pair is None:
            continue
        mask = {"pos": v > 0, "neg": v < 0, "both": v != 0}[side]
        speed = np.abs(v)
        lo, hi = pair
        where = f"measured {lo:.4g} to {hi:.4g} rad/s for {SIDES[side]}"
        below = mask & (speed < lo * (1 - RANGE_TOLERANCE))
        if below.any():
            w = float(v[below][np.argmin(speed[below])])
            out.append(
                RangeViolation(
                    "velocity",
                    "below",
                    int(below.sum()),
                    w,
                    lo,
                    hi,
                    f"velocity {w:.4g} rad/s is below the smallest identified speed {lo:.4g} "
                    f"rad/s ({where}): the low-speed (Stribeck) region is extrapolated",
                    rows=below,
                )
            )
        for a, b in gap_pairs(coverage, side):
            inside = (
                mask & (speed > a * (1 + RANGE_TOLERANCE)) & (speed < b * (1 - RANGE_TOLERANCE))
            )
            if inside.any():
                w = float(v[inside][0])
                out.append(
                    RangeViolation(
                        "velocity",
                        "gap",
                        int(inside.sum()),
                        w,
                        a,
                        b,
                        f"velocity {w:.4g} rad/s lies in a gap of the measured speeds (nothing "
                        f"between {a:.4g} and {b:.4g} rad/s; {where}): interpolated",
                        rows=inside,
                    )
                )
    return out


@dataclass(frozen=True)
class RangeViolation:
    """Inputs outside the operating range a model was identified on
    (:meth:`FittedModel.range_check`).

    Attributes
    ----------
    quantity : str
        ``"velocity"``, ``"load"`` or ``"temperature"``.
    kind : str
        ``"above"`` (a speed above the largest identified one), ``"below"`` (a speed between
        zero and the smallest identified one: the low-speed, Stribeck region extrapolated),
        ``"gap"`` (a speed between two measured ones far apart: :func:`speed_coverage`),
        ``"side"`` (a velocity on the side a one-direction model was not identified on) or
        ``"outside"`` (below or above the range of load, temperature, or of a velocity range
        spanning both directions).
    count : int
        How many of the inputs.
    worst : float
        The input furthest out [SI unit].
    low, high : float
        The identified range [SI unit] (speeds for ``above``/``below``; the gap's ends for
        ``gap``).
    message : str
        One line naming the input and how far out it is.
    rows : ndarray of bool, optional
        Which rows of the inputs checked (``count`` of them are True).
    """

    quantity: str
    kind: str
    count: int
    worst: float
    low: float
    high: float
    message: str
    rows: np.ndarray | None = field(default=None, repr=False, compare=False)


def _pair(ranges: Any, name: str) -> tuple[float, float] | None:
    pair = ranges.get(name) if isinstance(ranges, dict) else None
    try:
        lo, hi = (float(x) for x in pair)
    except (TypeError, ValueError):
        return None
    return (lo, hi) if np.isfinite(lo) and np.isfinite(hi) and lo <= hi else None


def _times(x: float, ref: float) -> str:
    """How far out ``x`` is against ``ref``, the largest speed identified in its direction."""
    if not ref > 0:
        return ""
    way = "forwards" if x > 0 else "backwards"
    return f" ({abs(x) / ref:.3g}x the largest speed identified {way}, {ref:.4g} rad/s)"


def _velocity_violations(
    v: np.ndarray, lo: float, hi: float, directions: list[int]
) -> list[RangeViolation]:
    """Velocity against its range: speeds for a combined (odd) model, the sign too for a
    one-direction model, signed values for a range spanning both directions."""
    out = []
    span = hi - lo
    tol = RANGE_TOLERANCE * (span if span > 0 else max(abs(lo), abs(hi)))
    if lo < 0 < hi or lo == hi == 0:
        for mask, edge in ((v > hi + tol, hi), (v < lo - tol, lo)):
            if mask.any():
                w = float(v[mask][np.argmax(np.abs(v[mask] - edge))])
                out.append(
                    RangeViolation(
                        "velocity",
                        "outside",
                        int(mask.sum()),
                        w,
                        lo,
                        hi,
                        f"velocity {w:.4g} rad/s is outside the identified range {lo:.4g} to "
                        f"{hi:.4g} rad/s{_times(w, abs(edge))}: extrapolated",
                        rows=mask,
                    )
                )
        return out
    side = 1 if hi > 0 else -1
    one_side = directions in ([1], [-1])
    if one_side:
        wrong = np.sign(v) == -side
        if wrong.any():
            w = float(v[wrong][np.argmax(np.abs(v[wrong]))])
            named = "positive" if side > 0 else "negative"
            out.append(
                RangeViolation(
                    "velocity",
                    "side",
                    int(wrong.sum()),
                    w,
                    lo,
                    hi,
                    f"velocity {w:.4g} rad/s is on the side the model was not identified on (it "
                    f"was identified for {named} velocity only, {lo:.4g} to {hi:.4g} rad/s): "
                    "its value there is the mirror image, extrapolated",
                    rows=wrong,
                )
            )
        v = np.where(wrong, 0.0, v)
    speed = np.abs(v)
    s_lo, s_hi = sorted((abs(lo), abs(hi)))
    above = speed > s_hi + tol
    if above.any():
        w = float(v[above][np.argmax(speed[above])])
        out.append(
            RangeViolation(
                "velocity",
                "above",
                int(above.sum()),
                w,
                s_lo,
                s_hi,
                f"velocity {w:.4g} rad/s is {abs(w) / s_hi:.3g}x the largest identified speed "
                f"{s_hi:.4g} rad/s: extrapolated",
                rows=above,
            )
        )
    below = (speed > 0) & (speed < s_lo - tol)
    if below.any():
        w = float(v[below][np.argmin(speed[below])])
        out.append(
            RangeViolation(
                "velocity",
                "below",
                int(below.sum()),
                w,
                s_lo,
                s_hi,
                f"velocity {w:.4g} rad/s is below the smallest identified speed {s_lo:.4g} "
                "rad/s: the low-speed (Stribeck) region is extrapolated",
                rows=below,
            )
        )
    return out


def range_violations(
    X,
    ranges: Any,
    used: Sequence[str] = INPUTS,
    directions: Sequence[int] | None = None,
    coverage: Any = None,
) -> list[RangeViolation]:
    """The inputs of ``X`` outside ``ranges``; see :meth:`fricid.fitted.FittedModel.range_check`.

    Parameters
    ----------
    X : array_like, shape (n, 3)
        Velocity [rad/s], load [N m], temperature [degC].
    ranges : dict
        ``operating_range`` of a model file: input name -> [low, high]; inputs without a
        valid pair are not checked.
    used : sequence of str
        The inputs the model uses (only these are checked).
    directions : sequence of int, optional
        ``provenance["directions"]`` of the model: ``[0]`` (or unknown) with a velocity range
        above zero compares speeds, ``[1]`` or ``[-1]`` the side too.
    coverage : dict, optional
        The measured speeds per direction (:func:`speed_coverage`, ``provenance["speeds"]``
        of a model file): speeds below the slowest measured one of their direction
        (``"below"``, also for a range spanning both directions) and speeds in a gap between
        measured speeds (``"gap"``) are reported from it.

    Returns
    -------
    list of RangeViolation
        One per quantity and kind found, empty when every input is inside.
    """
    X = np.atleast_2d(np.asarray(X, dtype=float))
    if X.ndim != 2 or X.shape[1] != len(INPUTS) or not len(X):
        return []
    out: list[RangeViolation] = []
    pair = _pair(ranges, "velocity") if "velocity" in used else None
    if pair is not None:
        try:
            dirs = sorted({int(d) for d in directions or ()})
        except (TypeError, ValueError):
            dirs = []
        found = _velocity_violations(X[:, 0], *pair, dirs)
        if isinstance(coverage, dict) and coverage:
            found = [b for b in found if b.kind != "below"] + _coverage_violations(
                X[:, 0], coverage
            )
        out += found
    for j, name in ((1, "load"), (2, "temperature")):
        pair = _pair(ranges, name) if name in used else None
        if pair is None:
            continue
        lo, hi = pair
        tol = RANGE_TOLERANCE * (hi - lo) if hi > lo else 1e-9 * max(1.0, abs(lo))
        col = X[:, j]
        bad = (col < lo - tol) | (col > hi + tol)
        if bad.any():
            far = np.maximum(lo - col, col - hi)
            w = float(col[bad][np.argmax(far[bad])])
            unit = _UNITS[name]
            out.append(
                RangeViolation(
                    name,
                    "outside",
                    int(bad.sum()),
                    w,
                    lo,
                    hi,
                    f"{name} {w:.4g} {unit} is outside the identified range {lo:.4g} to "
                    f"{hi:.4g} {unit} ({float(far[bad].max()):.3g} {unit} beyond): "
                    "extrapolated",
                    rows=bad,
                )
            )
    return out
