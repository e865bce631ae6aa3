"""Inputs against the operating range a model was identified on (issue 11, defect 8):
:func:`range_violations`, behind :meth:`fricid.fitted.FittedModel.range_check`.

Mathematics on the inputs and the recorded ranges only (numbers in, :class:`RangeViolation`
out); the model file, its warnings and the command line use it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._base import INPUTS

__all__ = ["RANGE_TOLERANCE", "RangeViolation", "range_violations"]

#: Relative tolerance of :meth:`FittedModel.range_check`: inputs within this fraction of the
#: identified span (or of the value, for a single value) beyond an edge are inside.
RANGE_TOLERANCE = 0.01

_UNITS = {"velocity": "rad/s", "load": "N m", "temperature": "degC"}


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
        ``"side"`` (a velocity on the side a one-direction model was not identified on) or
        ``"outside"`` (below or above the range of load, temperature, or of a velocity range
        spanning both directions).
    count : int
        How many of the inputs.
    worst : float
        The input furthest out [SI unit].
    low, high : float
        The identified range [SI unit] (speeds for ``above``/``below``).
    message : str
        One line naming the input and how far out it is.
    """

    quantity: str
    kind: str
    count: int
    worst: float
    low: float
    high: float
    message: str


def _pair(ranges: Any, name: str) -> tuple[float, float] | None:
    pair = ranges.get(name) if isinstance(ranges, dict) else None
    try:
        lo, hi = (float(x) for x in pair)
    except (TypeError, ValueError):
        return None
    return (lo, hi) if np.isfinite(lo) and np.isfinite(hi) and lo <= hi else None


def _times(x: float, ref: float) -> str:
    return f" ({abs(x) / ref:.3g}x the largest identified speed {ref:.4g} rad/s)" if ref > 0 else ""


def _velocity_violations(
    v: np.ndarray, lo: float, hi: float, directions: list[int]
) -> list[RangeViolation]:
    """Velocity against its range: speeds for a combined (odd) model, the sign too for a
    one-direction model, signed values for a range spanning both directions."""
    out = []
    span = hi - lo
    tol = RANGE_TOLERANCE * (span if span > 0 else max(abs(lo), abs(hi)))
    top = max(abs(lo), abs(hi))
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
                        f"{hi:.4g} rad/s{_times(w, top)}: extrapolated",
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
            )
        )
    return out


def range_violations(
    X, ranges: Any, used: Sequence[str] = INPUTS, directions: Sequence[int] | None = None
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
        out += _velocity_violations(X[:, 0], *pair, dirs)
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
                )
            )
    return out
