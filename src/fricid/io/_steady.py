"""Robust statistics of steady-state recordings (one constant velocity per file), for the
readers that average whole files (:func:`fricid.io.epos_steady_samples`): whether a recording
holds one steady operating point, outlier rows by median/MAD (in torque and in velocity),
scatter far above the neighbours', and the warning that names them (issue 11, defect 4). The
segment-level checks of a raw log live in :mod:`fricid.extract.steady`.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from ..errors import DataQualityWarning, user_stacklevel

__all__ = [
    "OUTLIER_SIGMAS",
    "SCATTER_RATIO",
    "STEADY_SPREAD",
    "high_scatter",
    "one_operating_point",
    "outlier_rows",
    "outliers",
    "quality_rows",
    "warn_steady",
]

#: A row whose torque is further than this many robust standard deviations (1.4826 MAD) from
#: its file's median is an outlier and dropped (same threshold as
#: :data:`fricid.extract.OUTLIER_SIGMAS`). The lead-screw recordings' largest deviation is
#: 5.9 sigma; one row at 12x the nominal torque sits at hundreds.
OUTLIER_SIGMAS = 8.0

#: A file whose torque scatter exceeds this multiple of the median scatter of its neighbours
#: (same direction, up to two set-points on each side) is flagged and warned about (as
#: :data:`fricid.extract.SCATTER_RATIO`).
SCATTER_RATIO = 4.0


#: A recording holds one steady operating point when each quarter of it has a mean velocity
#: within this fraction of the whole recording's (and no row moves the other way). The
#: lead-screw recordings' quarters are within 0.5 % of their file's mean, and within 10 % at
#: 2 rpm, where the recorder's 1 rpm resolution shows; a staircase, a ramp or a start from
#: rest is not one point, and is extracted as a log.
STEADY_SPREAD = 0.25


def one_operating_point(velocity: np.ndarray) -> bool:
    """Whether a recording's velocity holds one steady operating point: every row at rest or
    moving one way, each quarter's mean velocity within :data:`STEADY_SPREAD` of the whole
    recording's (rows further than :data:`OUTLIER_SIGMAS` robust sigmas from the median
    velocity, glitches, left out)."""
    v = np.asarray(velocity, dtype=float)
    v = v[~outlier_rows(v, OUTLIER_SIGMAS)] if v.size else v
    if v.size < 4 or not np.isfinite(v).all():
        return False
    mean = float(np.mean(v))
    if mean == 0.0 or (np.sign(v) == -np.sign(mean)).any():
        return False
    quarters = np.array([np.mean(q) for q in np.array_split(v, 4)])
    return bool(np.all(np.abs(quarters - mean) <= STEADY_SPREAD * abs(mean)))


def outlier_rows(torque: np.ndarray, sigmas: float) -> np.ndarray:
    """Rows further than ``sigmas`` robust standard deviations from the median (1.4826 MAD;
    the median nonzero deviation when the MAD is 0; nothing when every row is equal)."""
    dev = np.abs(torque - np.median(torque))
    scale = 1.4826 * float(np.median(dev))
    if scale == 0.0:
        nonzero = dev[dev > 0]
        if nonzero.size == 0:
            return np.zeros(torque.shape, dtype=bool)
        scale = float(np.median(nonzero))
    return dev > sigmas * scale


def outliers(
    torque: np.ndarray, velocity: np.ndarray, sigmas: float | None
) -> tuple[np.ndarray, np.ndarray]:
    """A file's rows dropped from its means: (torque outliers, velocity outliers), each
    :func:`outlier_rows` of its channel at ``sigmas`` (none when ``sigmas`` is None). The
    velocity is averaged as the torque is: a glitch row at 100x the set-point would move it."""
    if sigmas is None:
        none = np.zeros(len(torque), dtype=bool)
        return none, none
    return outlier_rows(torque, sigmas), outlier_rows(velocity, sigmas)


def high_scatter(velocity: np.ndarray, scatter: np.ndarray, ratio: float) -> np.ndarray:
    """Files whose scatter exceeds ``ratio`` times the median of their neighbours' (same sign
    of velocity, ordered by speed, up to two on each side)."""
    flagged = np.zeros(velocity.size, dtype=bool)
    for sign in (-1.0, 1.0):
        group = np.flatnonzero(np.sign(velocity) == sign)
        group = group[np.argsort(np.abs(velocity[group]))]
        s = scatter[group]
        for j, row in enumerate(group):
            others = np.concatenate([s[max(j - 2, 0) : j], s[j + 1 : j + 3]])
            if others.size and s[j] > max(ratio * float(np.median(others)), 1e-12):
                flagged[row] = True
    return flagged


def warn_steady(
    folder: str,
    quality: list[dict[str, Any]],
    lines: dict[str, list[int]],
    velocity_lines: dict[str, list[int]] | None = None,
) -> None:
    """One DataQualityWarning for the outliers dropped and the files flagged, naming them:
    ``lines`` and ``velocity_lines`` are the lines of each file's torque and velocity
    outliers."""
    parts = []
    for row in quality:
        where = f"{row['label']} ({row['velocity']:+.4g} rad/s)"
        for channel, found in (("torque", lines), ("velocity", velocity_lines or {})):
            dropped = found.get(row["label"])
            if dropped:
                shown = ", ".join(str(x) for x in dropped[:5])
                more = f" and {len(dropped) - 5} more" if len(dropped) > 5 else ""
                parts.append(
                    f"{where}: dropped {len(dropped)} outlier row(s) (line {shown}{more}), "
                    f"more than {OUTLIER_SIGMAS:g} robust sigmas from the file's median "
                    f"{channel}"
                )
        if row["flagged"]:
            parts.append(
                f"{where}: torque scatter {row['scatter']:.3g} N m is more than "
                f"{SCATTER_RATIO:g}x its neighbours'; check that recording"
            )
    if parts:
        warnings.warn(
            f"{folder}: " + "; ".join(parts), DataQualityWarning, stacklevel=user_stacklevel()
        )


def quality_rows(
    names, velocity, keep, std, flagged, temperature: float | None
) -> list[dict[str, Any]]:
    """One quality-table row per file (the columns of :data:`fricid.extract.QUALITY_COLUMNS`;
    :mod:`fricid.io` sits below :mod:`fricid.extract`, so the names are spelled here)."""
    return [
        {
            "kind": "setpoint",
            "label": name,
            "temperature": None if temperature is None else float(temperature),
            "velocity": float(v),
            "direction": int(np.sign(v)),
            "runs": 1,
            "kept": int(k.sum()),
            "outside_bins": 0,
            "dropped_rest": 0,
            "dropped_transient": 0,
            "dropped_outlier": int((~k).sum()),
            "dropped_saturated": 0,
            "scatter": float(sd),
            "run_scatter": None,
            "gravity_residual": None,
            "flagged": bool(f),
            "note": "1 file" + (f"; scatter >{SCATTER_RATIO:g}x neighbours'" if f else ""),
        }
        for name, v, k, sd, f in zip(names, velocity, keep, std, flagged, strict=True)
    ]
