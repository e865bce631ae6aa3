"""The local spread of a fit's held-out errors: how far a new measured sample falls from the
model near an operating point, where the model follows the law and where it does not
(:func:`local_variance`; the record ``prediction_interval["local"]`` of an analytic fit,
built by :func:`fricid.identify._intervals.local_record`).

A model whose family misses the law is off by a bias that varies along the speed axis: near
zero where the family follows the data, several noise standard deviations where it does not
(the Stribeck dip under a Coulomb-viscous line). One width for every speed, scaled by the
root mean square of all the residuals, is then too wide where the model is right and too
narrow where it is wrong. The spread here is local: the mean squared leave-one-out error of
the samples near ``x`` (a Nadaraya-Watson kernel average, Gaussian kernel; Fan & Yao 1998 for
variance functions, and the locally weighted scores of Lei et al. 2018, section 5.2), per
direction of motion, in ``log10 |v|`` (:data:`BANDWIDTH_DECADES` decades) and, where the
samples vary them, in load and temperature (:data:`BANDWIDTH_SPAN` of their measured span).
It is never below the measured scatter: a new sample carries at least the noise. An
analytic fit's record also holds the signed errors; their kernel average is the local bias
``m(x)`` (:func:`local_bias_std`), and the interval holds a new sample ``N(m, s^2)``
(:func:`biased_half_width`) rather than ``1.96 sqrt(v)``, about twice a dominant bias.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

__all__ = [
    "BANDWIDTH_DECADES",
    "BANDWIDTH_SPAN",
    "MAX_POINTS",
    "biased_half_width",
    "input_spans",
    "local_bias_std",
    "local_mean",
    "local_variance",
    "spread_points",
]

#: Kernel standard deviation along the speed axis [decades of |v|].
BANDWIDTH_DECADES = 0.1

#: Kernel standard deviation along load and temperature [share of their measured span].
BANDWIDTH_SPAN = 0.3

#: More samples than this are pooled into cells before they are stored (the model file
#: stays small on long logs; cells of 0.02 decades and a tenth of each span).
MAX_POINTS = 2000

#: Safeguarded Newton steps of :func:`biased_half_width` (quadratic from the bracket).
_ROOT_STEPS = 12
_ROOT_TOL = 1e-12
_SQRT_2PI = 2.5066282746310002

#: Rows of ``X`` per kernel block (memory: rows x points x inputs doubles).
_CHUNK = 1024


def _coordinates(X: np.ndarray, spans: list[list[float] | None]) -> np.ndarray:
    """``(n, 1 + k)``: ``log10 |v|``, then each input with a span, scaled to it (NaN: 0)."""
    cols = [np.log10(np.maximum(np.abs(X[:, 0]), 1e-300))]
    for j, span in zip((1, 2), spans, strict=True):
        if span is None:
            continue
        lo, hi = span
        col = (X[:, j] - lo) / (hi - lo)
        cols.append(np.where(np.isfinite(col), col, 0.0))
    return np.column_stack(cols)


def input_spans(X: np.ndarray) -> list[list[float] | None]:
    """The measured ``[min, max]`` of load and temperature, None for one that does not vary
    (or is not measured)."""
    out: list[list[float] | None] = []
    for j in (1, 2):
        col = X[:, j][np.isfinite(X[:, j])]
        lo, hi = (float(col.min()), float(col.max())) if col.size else (0.0, 0.0)
        out.append([lo, hi] if hi > lo else None)
    return out


def spread_points(
    X: np.ndarray, e2: np.ndarray, spans: list[list[float] | None]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The stored points ``(X, e2, weight)`` and each sample's point: every sample, or,
    past :data:`MAX_POINTS`, the means of cells of 0.02 decades in speed and a tenth of
    each span (coarser where that leaves more), weighted by their counts (the kernel
    average is then the same to well under the bandwidth)."""
    n = len(e2)
    if n <= MAX_POINTS:
        return X, e2, np.ones(n), np.arange(n)
    c = _coordinates(X, spans)
    cell = 1.0
    while True:  # cells twice as coarse until they fit
        key = np.column_stack(
            [np.sign(X[:, 0]), np.floor(c[:, 0] / (0.02 * cell)), np.floor(c[:, 1:] * 10 / cell)]
        )
        _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
        if counts.size <= MAX_POINTS:
            break
        cell *= 2
    inverse = inverse.ravel()
    Xm = np.column_stack(
        [np.bincount(inverse, np.nan_to_num(X[:, j])) / counts for j in range(X.shape[1])]
    )
    e2m = np.bincount(inverse, e2) / counts
    return Xm, e2m, counts.astype(float), inverse


def local_variance(
    record: Mapping[str, Any], X: np.ndarray, *, leave_out_self: bool = False
) -> np.ndarray:
    """The local mean squared held-out error [N^2 m^2] at each row of ``X`` (module notes),
    from ``record`` (``velocity``, ``load``, ``temperature``, ``e2``, ``weight``, ``spans``,
    ``bandwidth``); NaN where the record holds no sample of that direction.

    ``leave_out_self``: ``X`` are the record's own points, each averaged without itself
    (the leave-one-out spread, for the calibration of :func:`fricid.identify._intervals`).
    """
    return local_mean(record, X, "e2", leave_out_self=leave_out_self)


def local_mean(
    record: Mapping[str, Any], X: np.ndarray, key: str, *, leave_out_self: bool = False
) -> np.ndarray:
    """The kernel average of the record's column ``key`` at each row of ``X``
    (:func:`local_variance` for ``e2``; the local bias for the signed errors ``e``)."""
    return _kernel_average(record, X, (key,), leave_out_self)[:, 0]


def _kernel_average(
    record: Mapping[str, Any], X: np.ndarray, keys: tuple[str, ...], leave_out_self: bool
) -> np.ndarray:
    """``(n, len(keys))``: the kernel averages of the record's columns ``keys`` at each row of
    ``X``, one kernel for all of them; NaN on a direction without samples."""
    P = np.column_stack(
        [np.asarray(record[k], dtype=float) for k in ("velocity", "load", "temperature")]
    )
    values = np.column_stack([np.asarray(record[k], dtype=float) for k in keys])
    w = np.asarray(record["weight"], dtype=float)
    spans = list(record["spans"])
    bw = record["bandwidth"]
    cp, cx = _coordinates(P, spans), _coordinates(np.asarray(X, dtype=float), spans)
    scale = np.r_[float(bw["decades"]), [float(bw["span"])] * (cp.shape[1] - 1)]
    out = np.full((len(cx), len(keys)), np.nan)
    for sign in (1.0, -1.0):
        mp, mx = np.sign(P[:, 0]) == sign, np.sign(X[:, 0]) == sign
        if not mp.any() or not mx.any():
            continue
        cols, rows = np.flatnonzero(mp), np.flatnonzero(mx)
        for start in range(0, rows.size, _CHUNK):
            part = rows[start : start + _CHUNK]
            d = (cx[part][:, None, :] - cp[cols][None, :, :]) / scale
            d2 = np.einsum("ijk,ijk->ij", d, d)
            if leave_out_self:
                d2[part[:, None] == cols[None, :]] = np.inf
            near = d2.min(axis=1, keepdims=True)
            ok = np.isfinite(near[:, 0])
            K = np.exp(-0.5 * (d2[ok] - near[ok])) * w[cols]  # scaled: never all underflow
            out[part[ok]] = (K @ values[cols]) / K.sum(axis=1)[:, None]
    return out


def biased_half_width(bias: np.ndarray, std: np.ndarray, level: float) -> np.ndarray:
    """The half-width ``h`` that holds a share ``level`` of a new sample ``N(bias, std^2)``
    about 0: ``Phi((h - b) / s) - Phi((-h - b) / s) = level`` (the folded normal's quantile;
    the critical value of a bias-aware interval, Armstrong and Kolesar 2020, with the
    bias estimated locally). ``z s`` without bias (``z`` the normal quantile), about
    ``|b| + z' s`` (``z'`` the one-sided one) when the bias dominates, where ``z sqrt(b^2 +
    s^2)`` would be nearly twice the bias."""
    from scipy.special import ndtr, ndtri

    b = np.abs(np.asarray(bias, dtype=float))
    s = np.maximum(np.asarray(std, dtype=float), 1e-300)
    b, s = np.broadcast_arrays(b, s)
    c = 2.0 * b / s
    if not c.any():  # no bias (a learned model's record): the normal quantile
        return float(ndtri(0.5 + level / 2)) * s
    # in x = (h - |b|) / s the root lies in [max(z', -|b| / s), z]; Newton from the lower
    # end (g is concave for x >= 0, so from the left it climbs to the root and stays in the
    # bracket), bisection where a step leaves it
    lo = np.maximum(float(ndtri(level)), -0.5 * c)
    hi = np.full(c.shape, float(ndtri(0.5 + level / 2)))
    x = lo.copy()
    for _ in range(_ROOT_STEPS):
        g = ndtr(x) - ndtr(-x - c) - level
        if not (np.abs(g) > 1e-14).any():
            break
        lo, hi = np.where(g < 0, x, lo), np.where(g < 0, hi, x)
        slope = (np.exp(-0.5 * x * x) + np.exp(-0.5 * (x + c) ** 2)) / _SQRT_2PI
        step = x - g / np.where(slope > 0, slope, np.inf)
        inside = (step >= lo - _ROOT_TOL) & (step <= hi + _ROOT_TOL)  # rounding at an end
        x = np.where(inside, np.clip(step, lo, hi), 0.5 * (lo + hi))
    return b + x * s


def local_bias_std(
    record: Mapping[str, Any],
    X: np.ndarray,
    extra: np.ndarray | float = 0.0,
    *,
    leave_out_self: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """The local bias ``m(x)`` [N m] of the held-out errors and the spread about it ``s(x)``
    [N m] at each row of ``X``: ``m`` the kernel average of the signed errors ``e`` (0 in a
    record without them), ``s^2 = max(v - m^2, noise^2) + extra`` with ``v`` the local mean
    square (:func:`local_variance`, never below ``noise^2``); ``extra`` [N^2 m^2] the
    model's own zero-mean uncertainty (an analytic model's parameter term)."""
    noise2 = float(record["noise"]) ** 2
    keys = ("e2", "e") if "e" in record else ("e2",)
    avg = _kernel_average(record, X, keys, leave_out_self)  # one kernel for both
    v = np.maximum(np.where(np.isfinite(avg[:, 0]), avg[:, 0], noise2), noise2)
    m = np.nan_to_num(avg[:, 1]) if "e" in record else np.zeros_like(v)
    return m, np.sqrt(np.maximum(v - m**2, noise2) + np.maximum(extra, 0.0))
