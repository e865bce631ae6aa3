"""The measurement scatter of friction samples, estimated from the data themselves.

A fit is good when its error is as small as the noise of the data it is compared with: the
standard error of each set-point's mean friction. :func:`measurement_scatter` estimates it, in
this order of preference (issue 11, "Validation built in"):

1. standard errors given by the caller (``sem=``, e.g. the scatter of repeated passes that
   :func:`fricid.extract.extract` computes as ``ExtractionResult.direction_sem``), or carried
   by the samples as ``meta["sem"]`` (method ``meta["sem_method"]`` where the extraction or
   reader recorded it, else "given");
2. the raw steady samples of each set-point (``raw=``): within-run, with the autocorrelation
   taken into account (an effective sample size from the lag-1 autocorrelation, and batch
   means; the larger standard error of the two);
3. repeated runs at one operating point among the samples: the pooled between-run standard
   deviation. Repeats are rows the samples label as one set-point (``meta["setpoint"]``,
   one label per row: a file, run or segment of one commanded speed), else rows of one
   direction, load and temperature whose speeds lie within :data:`LEVEL_RTOL` of their
   common centre (:func:`speed_levels`: a level's span is bounded, so closely spaced speeds
   never chain into one "point" whose rise would be counted as scatter);
4. the samples' own ``std / sqrt(count)``, with the caveat that it ignores autocorrelation
   and is a lower bound;
5. nothing repeats and nothing was given: an estimate from the second differences along the
   speed axis (:func:`second_difference_scatter`, method :data:`SECOND_DIFFERENCES`), said
   to be an estimate (``Scatter.estimated``); with too few speeds for it, unknown.

It lives apart from :mod:`fricid.identify.validate` (which re-exports it) because ``fit``
uses it too (the scale of the robust losses, the weights), and validation calls ``fit``.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..metrics import sem_autocorrelated
from ..samples import FrictionSamples

__all__ = [
    "LEVEL_RTOL",
    "SECOND_DIFFERENCES",
    "WEIGHTS",
    "Scatter",
    "exact_copies",
    "level_labels",
    "measurement_scatter",
    "sample_weights",
    "second_difference_scatter",
    "sem_autocorrelated",
    "speed_levels",
]

#: A velocity level's speeds lie within this fraction of its centre (the level's span is at
#: most twice it): speeds that differ by more are distinct set-points, however many lie
#: between them, so closely spaced speeds never chain into one level.
LEVEL_RTOL = 0.01

#: The levels of the two directions of one set-point are paired when their centres lie within
#: this fraction of each other (:func:`level_labels`).
PAIR_RTOL = 0.05

#: Fewest second-difference residuals for :func:`second_difference_scatter` (fewer: unknown).
MIN_DIFFERENCES = 10

#: Largest median ratio of neighbouring speeds for :func:`second_difference_scatter`: speeds
#: further apart leave the law's curvature in the differences (measured: speeds a factor of 2.1
#: apart, 8 per direction, read 1.5-1.8x the noise on a curved law), so the scatter is unknown.
MAX_SPEED_STEP = 1.5

#: The median of ``|z|`` for a standard normal ``z``: a median absolute residual over it
#: estimates the standard deviation.
_MEDIAN_ABS_NORMAL = 0.6744897501960817

#: ``Scatter.method`` of :func:`second_difference_scatter`.
SECOND_DIFFERENCES = "estimated from second differences, no repeats"
#: ... the samples' own std / sqrt(count), which ignores the raw samples' autocorrelation: a
#: lower bound of the scatter.
STD_OVER_ROOT_COUNT = "within-run, std/sqrt(count)"


@dataclass(frozen=True)
class Scatter:
    """The measurement scatter of samples and how it was estimated.

    Attributes
    ----------
    value : float
        N m, root mean square of ``per_sample``: the scatter an RMSE is compared with. NaN
        when it cannot be estimated.
    per_sample : numpy.ndarray
        N m, the standard error of each sample's friction.
    method : str
        ``"given"``, ``"within-run, autocorrelation-corrected"``, ``"between repeated runs"``,
        ``"within-run, std/sqrt(count)"``, :data:`SECOND_DIFFERENCES` or ``"none"``.
    caveat : str
        What the estimate leaves out ("" when nothing known).
    """

    value: float
    per_sample: np.ndarray = field(repr=False)
    method: str
    caveat: str = ""

    @property
    def estimated(self) -> bool:
        """Nothing repeats and nothing was given: the value is inferred from the spread of
        the samples about a smooth curve (:func:`second_difference_scatter`), not measured."""
        return self.method == SECOND_DIFFERENCES

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: value, method and caveat (not the per-sample array)."""
        v = float(self.value)
        value = v if np.isfinite(v) else None
        return {"value": value, "method": self.method, "caveat": self.caveat}

    def describe(self) -> str:
        """``"1.4e-05 N m (within-run, std/sqrt(count); ...)"``."""
        if not np.isfinite(self.value):
            return f"unknown ({self.caveat})"
        note = f"; {self.caveat}" if self.caveat else ""
        return f"{self.value:.3g} N m ({self.method}{note})"


def level_labels(samples: FrictionSamples, rtol: float = LEVEL_RTOL) -> np.ndarray:
    """Velocity level of each sample (:func:`speed_levels` of ``|v|``), the two directions of
    one set-point paired.

    Parameters
    ----------
    samples : FrictionSamples
    rtol : float
        A level's speeds lie within ``rtol`` of its centre.

    Returns
    -------
    numpy.ndarray of int (n,)
        Level index, 0 for the slowest; both directions of a speed share a level.

    Notes
    -----
    The measured speeds of the two directions of one set-point can differ by more than a
    level's span (on the EPOS lead screw 0.2172 and 0.2241 rad/s, 3 % apart). Two neighbouring
    levels, one holding only samples of one direction and the other only of the other, with
    centres within :data:`PAIR_RTOL` of each other, are one level: a one-to-one pairing, so it
    cannot chain either.
    """
    labels = speed_levels(samples.velocity, rtol)
    k = int(labels.max()) + 1 if labels.size else 0
    speed = np.abs(samples.velocity)
    centre = np.bincount(labels, weights=speed, minlength=k) / np.maximum(
        np.bincount(labels, minlength=k), 1
    )
    pos = np.bincount(labels, weights=samples.direction > 0, minlength=k) > 0
    neg = np.bincount(labels, weights=samples.direction < 0, minlength=k) > 0
    merged = np.arange(k)
    i = 0
    while i < k - 1:
        one_sided = pos[i] != neg[i] and pos[i + 1] != neg[i + 1] and pos[i] != pos[i + 1]
        if one_sided and centre[i + 1] <= centre[i] * (1.0 + PAIR_RTOL):
            merged[i + 1 :] -= 1
            i += 2
        else:
            i += 1
    return merged[labels]


def speed_levels(speed: np.ndarray, rtol: float = LEVEL_RTOL) -> np.ndarray:
    """Level index of each ``|speed|`` (0 the slowest), by clustering that cannot chain.

    Parameters
    ----------
    speed : array_like (n,)
        rad/s (the sign is ignored).
    rtol : float
        Every level's speeds lie within ``rtol`` of its centre (the mean of its slowest and
        fastest speed).

    Returns
    -------
    numpy.ndarray of int (n,)

    Notes
    -----
    Divisive: the sorted speeds are first cut wherever two neighbours are further apart than
    a level may span; a run of speeds still spanning more than ``2 rtol`` of its centre is cut
    at its largest relative gap, again until every level fits. A level's span is bounded
    relative to its centre, not neighbour to neighbour, so speeds 3 % apart stay 38 levels
    where a neighbour-to-neighbour rule of 5 % made them one.
    """
    s_abs = np.abs(np.asarray(speed, dtype=float))
    order = np.argsort(s_abs, kind="stable")
    s = s_abs[order]
    cut = np.zeros(s.size, dtype=bool)  # cut[i]: a new level starts at sorted index i
    if s.size:
        cut[0] = True
        cut[1:] = (s[1:] - s[:-1]) > 2.0 * rtol * s[1:] + 1e-12
    starts = [*np.flatnonzero(cut).tolist(), s.size]
    stack = list(itertools.pairwise(starts))
    while stack:
        a, b = stack.pop()
        if s[b - 1] - s[a] <= rtol * (s[b - 1] + s[a]) + 1e-12:
            continue
        gaps = (s[a + 1 : b] - s[a : b - 1]) / (s[a + 1 : b] + s[a : b - 1])
        k = a + 1 + int(np.argmax(gaps))
        cut[k] = True
        stack += [(a, k), (k, b)]
    labels = np.empty(s.size, dtype=int)
    labels[order] = np.cumsum(cut) - 1
    return labels


def input_keys(samples: FrictionSamples) -> tuple[np.ndarray, np.ndarray]:
    """Load [N m] and temperature [degC] rounded for grouping (6 and 1 decimals); a column
    not measured (NaN) becomes one key (``inf``), as ``np.unique(..., axis=0)`` never finds
    two NaN rows equal."""

    def key(x: np.ndarray, decimals: int) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        return np.where(np.isnan(x), np.inf, np.round(x, decimals))

    return key(samples.load, 6), key(samples.temperature, 1)


def _repeat_groups(samples: FrictionSamples, rtol: float) -> np.ndarray:
    """Group index of each sample's operating point: the samples' own set-point labels
    (``meta["setpoint"]``, one per row: rows of one label are repeated runs of one
    operating point, e.g. one file or segment each) where given, else (level, direction,
    load, temperature) with non-chaining velocity levels (:func:`speed_levels`); either way
    per direction."""
    own = samples.meta.get("setpoint")
    if isinstance(own, list | tuple) and len(own) == len(samples):
        keys = np.asarray([f"{d:+d} {k}" for d, k in zip(samples.direction, own, strict=True)])
        _, group = np.unique(keys, return_inverse=True)
        return group.ravel()
    keys = np.column_stack(
        [
            level_labels(samples, rtol),
            samples.direction,
            *input_keys(samples),
        ]
    )
    _, group = np.unique(keys, axis=0, return_inverse=True)
    return group.ravel()


def measurement_scatter(
    samples: FrictionSamples,
    *,
    raw: Sequence[Any] | None = None,
    sem: Any | None = None,
    rtol: float = LEVEL_RTOL,
) -> Scatter:
    """The standard error of the samples' friction, estimated from the data (module docstring).

    Parameters
    ----------
    samples : FrictionSamples
    raw : sequence of array_like, optional
        One array per sample row: the raw steady torque samples [N m] averaged into it, in
        time order.
    sem : array_like (n,), optional
        Standard errors [N m] known otherwise (e.g. ``ExtractionResult.direction_sem``).
    rtol : float
        Repeated runs of one operating point lie within ``rtol`` of their centre in speed
        (:func:`speed_levels`), unless the samples label their set-points themselves.

    Returns
    -------
    Scatter

    Raises
    ------
    ConfigError
        ``raw`` or ``sem`` of a length other than the number of samples.
    """
    n = len(samples)
    stale = ""
    if sem is None and "sem" in samples.meta:
        given = np.asarray(samples.meta["sem"], dtype=float)
        if given.shape != (n,):  # rows removed or added by hand under the file's header
            stale = (
                f"; the samples file's '# meta' header holds {given.size} per-row errors for "
                f"these {n} rows (rows removed or added under it?), so they were not used"
            )
        if given.shape == (n,):
            how = samples.meta.get("sem_method")
            if isinstance(how, str) and how:  # the reader or extraction says how
                return _scatter(given, how, str(samples.meta.get("sem_caveat") or ""))
            sem = given
    if sem is not None:
        se = np.asarray(sem, dtype=float)
        if se.shape != (n,):
            raise ConfigError(f"sem needs {n} standard errors, one per sample; got {se.shape}")
        return _scatter(se, "given", "")
    if raw is not None:
        if len(raw) != n:
            raise ConfigError(f"raw needs {n} series, one per sample; got {len(raw)}")
        se = np.array([sem_autocorrelated(x) for x in raw])
        return _scatter(
            se,
            "within-run, autocorrelation-corrected",
            "one run per set-point: offsets between runs are not in it",
        )
    copy = exact_copies(samples)
    said = (
        f"; {int(copy.sum())} row(s) exact copies of others (a copy is not a repeated run): "
        "not counted as repeats"
        if copy.any()
        else ""
    )
    group = _repeat_groups(samples, rtol)
    sizes = np.bincount(group[~copy], minlength=int(group.max()) + 1)
    if (sizes > 1).any():
        ys, gs = samples.y[~copy], group[~copy]
        means = np.bincount(gs, weights=ys, minlength=sizes.size) / np.maximum(sizes, 1)
        dof = float(np.sum(np.maximum(sizes - 1, 0)))
        s = float(np.sqrt(np.sum((ys - means[gs]) ** 2) / dof))
        k = int((sizes > 1).sum())
        return _scatter(
            np.full(n, s), "between repeated runs", f"{k} operating points repeated{said}"
        )
    if (samples.std > 0).any():
        lost = (
            "; fricid extract records autocorrelation-corrected errors in the samples file's "
            "'# meta' header, which these samples lack (a spreadsheet re-save drops it)"
            if not samples.meta
            else ""
        )
        return _scatter(
            samples.std / np.sqrt(samples.count),
            STD_OVER_ROOT_COUNT,
            f"ignores autocorrelation of the raw samples: a lower bound{said}{lost}{stale}",
        )
    out = second_difference_scatter(samples)
    return Scatter(out.value, out.per_sample, out.method, out.caveat + said) if said else out


def exact_copies(samples: FrictionSamples) -> np.ndarray:
    """Rows equal in every column (velocity, load, temperature, friction, count, std) to an
    earlier row: a copy (a pasted row, a file joined twice), never a repeated run, whose
    friction would differ by its noise. (n,) bool."""
    cols = np.column_stack(
        [samples.velocity, samples.load, samples.temperature, samples.y, samples.count, samples.std]
    )
    _, first = np.unique(cols, axis=0, return_index=True)
    copy = np.ones(len(samples), dtype=bool)
    copy[first] = False
    return copy


def _lines(samples: FrictionSamples) -> list[np.ndarray]:
    """Row indices of each line along the speed axis (one direction, load and temperature),
    sorted by speed."""
    keys = np.column_stack([samples.direction, *input_keys(samples)])
    _, line = np.unique(keys, axis=0, return_inverse=True)
    line = line.ravel()
    speed = np.abs(samples.velocity)
    return [
        np.flatnonzero(line == k)[np.argsort(speed[line == k], kind="stable")]
        for k in range(int(line.max()) + 1)
    ]


def second_difference_scatter(samples: FrictionSamples) -> Scatter:
    """The scatter of samples that repeat nothing, from their second differences in speed.

    Parameters
    ----------
    samples : FrictionSamples

    Returns
    -------
    Scatter
        Method :data:`SECOND_DIFFERENCES`, or ``"none"`` (value NaN) with fewer than
        :data:`MIN_DIFFERENCES` differences or neighbouring speeds more than
        :data:`MAX_SPEED_STEP` times apart (median over the lines).

    Notes
    -----
    Along each line of the speed axis (one direction, load and temperature; samples sorted
    by ``|v|``), every interior sample is compared with the straight line through its two
    neighbours: ``r_i = y_i - (w_- y_{i-1} + w_+ y_{i+1})`` with the interpolation weights
    ``w_- = (s_{i+1} - s_i) / (s_{i+1} - s_{i-1})`` and ``w_+ = 1 - w_-``. A law that is
    locally straight cancels, and noise of standard deviation ``sigma`` leaves
    ``var r_i = sigma^2 (1 + w_-^2 + w_+^2)``; the estimate is the median of
    ``|r_i| / sqrt(1 + w_-^2 + w_+^2)`` over every line, divided by the median of ``|z|``
    for a standard normal ``z`` (0.674), so a few points of strong curvature (the Stribeck
    drop) or outliers do not carry it. It is an estimate, not a measurement: the curvature
    the law keeps between neighbours adds to it (widely spaced speeds, few levels), and it is
    one number for every sample.
    """
    n = len(samples)
    y, speed = samples.y, np.abs(samples.velocity)
    z, steps = [], []
    for idx in _lines(samples):
        if idx.size < 3:
            continue
        s, f = speed[idx], y[idx]
        steps.append(s[1:][s[:-1] > 0] / s[:-1][s[:-1] > 0])
        span = s[2:] - s[:-2]
        ok = span > 0
        w_lo = np.where(ok, (s[2:] - s[1:-1]) / np.where(ok, span, 1.0), 0.5)
        w_hi = 1.0 - w_lo
        r = f[1:-1] - (w_lo * f[:-2] + w_hi * f[2:])
        z.append(r / np.sqrt(1.0 + w_lo**2 + w_hi**2))
    found = np.concatenate(z) if z else np.zeros(0)
    if found.size < MIN_DIFFERENCES:
        return Scatter(
            float("nan"),
            np.full(n, np.nan),
            "none",
            "the samples have no std, no repeated runs, no raw data, and too few speeds for "
            f"second differences ({found.size} of the {MIN_DIFFERENCES} needed)",
        )
    step = float(np.median(np.concatenate(steps))) if found.size else float("nan")
    if step > MAX_SPEED_STEP:
        return Scatter(
            float("nan"),
            np.full(n, np.nan),
            "none",
            "the samples have no std, no repeated runs and no raw data, and their speeds are "
            f"too far apart for second differences (a median factor of {step:.3g} between "
            f"neighbours, over the {MAX_SPEED_STEP:g} that keeps the law's curvature out)",
        )
    sigma = float(np.median(np.abs(found)) / _MEDIAN_ABS_NORMAL)
    return _scatter(
        np.full(n, sigma),
        SECOND_DIFFERENCES,
        f"no repeated runs: inferred from {found.size} second differences along the speed "
        "axis (per direction), not measured; the law's curvature between neighbouring speeds "
        "adds to it",
    )


def _scatter(se: np.ndarray, method: str, caveat: str) -> Scatter:
    ok = np.isfinite(se)
    value = float(np.sqrt(np.mean(se[ok] ** 2))) if ok.any() else float("nan")
    return Scatter(value, se, method, caveat)


#: Choices of ``fit(..., weights=...)`` by name.
WEIGHTS = ("none", "std")


def sample_weights(samples: FrictionSamples, kind: str, scatter: Scatter | None = None):
    """Weights of weighted least squares from the samples' own standard errors.

    Parameters
    ----------
    samples : FrictionSamples
    kind : {"none", "std"}
        ``"std"``: ``w_i = (s / se_i)^2``, ``se_i`` each sample's standard error
        (:func:`measurement_scatter`) and ``s`` their root mean square, so the weights
        average about 1 and weighted residuals stay in N m; ``"none"``: no weights.
    scatter : Scatter, optional
        The scatter to use (default: :func:`measurement_scatter` of ``samples``).

    Returns
    -------
    numpy.ndarray (n,) or None
        None for ``"none"``.

    Raises
    ------
    ConfigError
        An unknown ``kind``, or a sample without a positive standard error (its row named;
        a scatter only estimated from second differences gives none).
    """
    key = str(kind).strip().lower()
    if key not in WEIGHTS:
        raise ConfigError(f"unknown weights '{kind}'; choose one of: {', '.join(WEIGHTS)}")
    if key == "none":
        return None
    sc = scatter if scatter is not None else measurement_scatter(samples)
    if sc.estimated:
        raise ConfigError(
            "weights 'std' need a standard error for every sample; row 0 has none (the std "
            f"column is 0 or missing, and the scatter is only {sc.method}): use weights 'none'"
        )
    se = np.asarray(sc.per_sample, dtype=float)
    bad = np.flatnonzero(~(np.isfinite(se) & (se > 0)))
    if bad.size:
        raise ConfigError(
            f"weights 'std' need a positive standard error for every sample; row {int(bad[0])} "
            f"has {se[bad[0]]!r} (the std column is 0 or missing: use weights 'none')"
        )
    return (sc.value / se) ** 2
