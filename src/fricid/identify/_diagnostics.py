"""What a model file and its samples say about trust before any validation: parameters the
data do not determine or bound, the operating range, and the samples' quality table.

Helpers of :mod:`fricid.identify.trust` (the verdict), kept apart so that the verdict's module
stays readable; :func:`not_determined` is also the report's parameter table status.
"""

from __future__ import annotations

import contextlib
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..fitted import FittedModel, Parameter
from ..models._range import SIDES, coverage_text, gap_pairs, gaps_note
from ..samples import FrictionSamples
from ._scatter import sample_weights

__all__ = [
    "DOWN_WEIGHT",
    "DROPS",
    "downweighted",
    "not_determined",
    "open_sides",
    "quality_rows",
    "range_text",
]

#: A sample whose weight under a robust loss is below this is reported as down-weighted and
#: left out of the error the verdict grades: soft_l1 ``1 / sqrt(1 + z^2)`` below it beyond
#: ``|z| = 2.83`` scales, huber ``min(1, 1 / |z|)`` beyond 3 (``z`` the residual over the
#: loss's scale, weighted as the fit weighs it), about 0.5 % of Gaussian noise either way.
DOWN_WEIGHT = 1.0 / 3.0

#: Down-weighted samples listed by name (the rest counted).
_LISTED = 5

_UNITS = {"velocity": "rad/s", "load": "N m", "temperature": "degC"}

#: The quality table's drop counts and what each dropped.
DROPS = {
    "dropped_rest": "at rest",
    "dropped_transient": "transient",
    "dropped_outlier": "outliers",
    "dropped_saturated": "saturated",
}


def not_determined(fitted: FittedModel) -> list[str]:
    """Free parameters the data do not determine (their record's flag: the note says so, "not
    determined", "not identified", or, from a converged fit without notes, the standard error
    is missing)."""
    if fitted.kind == "rbf":
        return []
    return [n for n, p in fitted.parameters.items() if p.not_determined and not p.fixed]


def _zero_floor(p: Parameter) -> bool:
    """Only the lower side is open, at a bound of 0: the parameter is consistent with 0."""
    return bool(p.low_open and not p.high_open and p.bounds is not None and p.bounds[0] == 0)


def open_sides(fitted: FittedModel, *, include_zero: bool = False) -> dict[str, str]:
    """Free parameters whose 95 % interval reaches a bound of the search box, with the note
    of the fit (or one made here); ``include_zero`` keeps those open only at a lower bound of
    0 ("consistent with zero")."""
    out = {}
    for name, p in fitted.parameters.items():
        sides = (p.low_open, p.high_open)
        if p.fixed or not any(sides):
            continue
        if _zero_floor(p) and not include_zero:
            continue
        which = " and ".join(s for s, o in zip(("lower", "upper"), sides, strict=True) if o)
        out[name] = p.note or f"{which} side reaches the search bound"
    return out


def gap_caveat(fitted: FittedModel) -> str:
    """``"no speed measured between 1 and 4 rad/s (v > 0): the model is untested there"``
    for each gap between measured speeds that the file records (``provenance["speeds"]``,
    :func:`fricid.models._range.speed_coverage`): held-out validation leaves out measured
    levels, so it says nothing of a gap; "" when there is none."""
    coverage = (fitted.provenance or {}).get("speeds")
    parts = [
        f"between {a:.4g} and {b:.4g} rad/s ({label})"
        for side, label in SIDES.items()
        for a, b in gap_pairs(coverage, side)
    ]
    if not parts:
        return ""
    return f"no speed measured {', '.join(parts)}: the model is untested there"


def range_text(fitted: FittedModel) -> str:
    """The extrapolation-free operating range: ``"velocity 0.0105 to 0.838 rad/s; ..."``.

    Velocity of a model of combined samples (direction 0, odd in velocity) is given as speed
    ``|v|`` for either direction; one identified on one direction names it; one identified on
    both, where the file records the measured speeds per direction (``provenance["speeds"]``),
    gives each direction's range (:func:`fricid.models._range.coverage_text`: ``"velocity
    v > 0: measured 0.217 to 20.84 rad/s (nothing between 2 and 5), v < 0: ..."``). The gaps
    between measured speeds are named in each case. Inputs the model does not use are left
    out; ``""`` when the file records no range.
    """
    used = set(fitted.inputs_used()) if fitted.operating_range else set()
    dirs = sorted({int(d) for d in (fitted.provenance or {}).get("directions") or ()})
    coverage = (fitted.provenance or {}).get("speeds")
    parts = []
    for name in ("velocity", "load", "temperature"):
        pair = fitted.operating_range.get(name)
        if not pair or name not in used:
            continue
        lo, hi = float(pair[0]), float(pair[1])
        unit = _UNITS[name]
        if name == "velocity" and dirs == [0]:
            gaps = gaps_note(coverage, "both")
            parts.append(f"speed {lo:.4g} to {hi:.4g} {unit} (either direction{gaps})")
        elif name == "velocity" and dirs in ([1], [-1]):
            side = "positive" if dirs == [1] else "negative"
            gaps = gaps_note(coverage, side[:3])
            parts.append(f"velocity {lo:.4g} to {hi:.4g} {unit} ({side} direction only{gaps})")
        elif name == "velocity" and len(coverage_text(coverage)) == 2:  # per direction
            parts.append("velocity " + ", ".join(coverage_text(coverage)))
        elif lo == hi:
            parts.append(f"{name} {lo:.4g} {unit} only")
        else:
            parts.append(f"{name} {lo:.4g} to {hi:.4g} {unit}")
    return "; ".join(parts)


def quality_rows(
    samples: FrictionSamples | None,
) -> tuple[list[dict[str, Any]] | None, str, str]:
    """(rows, summary, caveat) of the samples' quality table (``meta["quality"]``,
    :class:`fricid.extract.QualityTable`): rows None when not recorded."""
    rows = None if samples is None else samples.meta.get("quality")
    if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) for r in rows):
        return None, "not recorded with these samples (no meta quality table)", ""
    points = [r for r in rows if r.get("kind", "setpoint") == "setpoint"]
    total = {k: sum(int(r.get(k) or 0) for r in rows) for k in DROPS}
    kept = sum(int(r.get("kept") or 0) for r in points)
    flagged = [r for r in points if r.get("flagged")]
    dropped = ", ".join(f"{v} {DROPS[k]}" for k, v in total.items() if v) or "none"
    summary = f"{len(points)} set-points, {kept} samples averaged; dropped: {dropped}"
    caveats = []
    if flagged:
        names = ", ".join(_point_name(r) for r in flagged[:4])
        caveats.append(
            f"{len(flagged)} set-point(s) with scatter far above their neighbours' ({names})"
        )
    if total["dropped_outlier"]:
        caveats.append(f"{total['dropped_outlier']} outlier sample(s) dropped")
    if flagged:
        summary += f"; {len(flagged)} flagged for high scatter"
    return rows, summary, "; ".join(caveats)


def _point_name(row: dict[str, Any]) -> str:
    v = row.get("velocity")
    where = f"{v:.4g} rad/s" if isinstance(v, int | float) else "?"
    return f"{row['label']} ({where})" if row.get("label") else where


def downweighted(
    fitted: FittedModel, samples: FrictionSamples | None
) -> tuple[np.ndarray | None, list[str]]:
    """The samples a robust fit (``--loss soft_l1`` or ``huber``) down-weighted.

    Parameters
    ----------
    fitted : FittedModel
    samples : FrictionSamples, optional
        The samples it was fitted to.

    Returns
    -------
    numpy.ndarray of bool (n,) or None
        True where the sample's robust weight is below :data:`DOWN_WEIGHT`; None for a fit by
        least squares, without samples, or when none (or half or more) is down-weighted.
    list of str
        The down-weighted samples by velocity, load and temperature with their residual in
        scales (the first few; then how many more).
    """
    loss = (fitted.loss or {}).get("loss")
    scale = (fitted.loss or {}).get("f_scale")
    if samples is None or loss not in ("soft_l1", "huber") or not scale or scale <= 0:
        return None, []
    r = samples.y - fitted.predict(samples.X, warn=False)
    if (fitted.loss or {}).get("weights") == "std":
        with contextlib.suppress(ConfigError):  # else the fit could not have weighed them
            r = r * np.sqrt(sample_weights(samples, "std"))
    z = np.abs(r) / float(scale)
    huber = np.minimum(1.0, 1.0 / np.maximum(z, 1e-300))
    weight = 1.0 / np.sqrt(1.0 + z**2) if loss == "soft_l1" else huber
    low = weight < DOWN_WEIGHT
    if not low.any() or 2 * low.sum() >= low.size:
        return None, []
    rows = np.flatnonzero(low)[np.argsort(-z[low])]
    names = [_sample_name(samples, int(i), float(z[i])) for i in rows[:_LISTED]]
    if rows.size > _LISTED:
        names.append(f"and {rows.size - _LISTED} more")
    return low, names


def _sample_name(samples: FrictionSamples, i: int, z: float) -> str:
    """``"row 3: v = -0.0979 rad/s, load 0 N m, 25 degC (residual 12x the loss's scale)"``."""
    parts = [f"v = {samples.velocity[i]:+.4g} rad/s"]
    if np.isfinite(samples.load[i]):
        parts.append(f"load {samples.load[i]:.4g} N m")
    if np.isfinite(samples.temperature[i]):
        parts.append(f"{samples.temperature[i]:.4g} degC")
    return f"row {i}: {', '.join(parts)} (residual {z:.3g}x the loss's scale)"
