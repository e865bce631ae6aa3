"""Order statistics of finite data, equal bit for bit to numpy's and several times faster.

``np.median`` and ``np.percentile`` partition their input at two or three positions at once
(the middle pair and the last element, which they check for NaN); numpy's vectorised
selection handles one position at a time, so the several-position partition falls back to a
scalar introselect about ten times slower. On finite data the same values come from one
single-position partition and a minimum of the part above it, combined with numpy's own
arithmetic (the mean of the middle value or pair; :func:`numpy.percentile`'s linear
interpolation), so
the results are identical. Non-finite input goes to numpy itself, and so does a zero result
when the data hold both 0.0 and -0.0 (the sign would depend on which one a partition
selects).

Extraction takes a dozen medians per raw sample (noise scales, plateaus, robust scales); with
these they cost about as much as reading the sample.
"""

from __future__ import annotations

import numpy as np

__all__ = ["load_kernel", "median", "median_filter", "percentile"]


def _kth_pair(x: np.ndarray, k: int) -> tuple[float, float]:
    """The k-th and (k+1)-th smallest values of ``x`` (0-based; ``k + 1 < x.size``)."""
    part = np.partition(x, k)
    return part[k], part[k + 1 :].min()


def median(x: np.ndarray) -> float:
    """``float(np.median(x))`` of a 1-D float array, exactly.

    Parameters
    ----------
    x : numpy.ndarray
        1-D, float64; any size (empty gives NaN, as numpy's does with a warning).

    Returns
    -------
    float
    """
    n = x.size
    if n < 3 or not np.isfinite(x).all():
        return float(np.median(x))
    half = n // 2
    odd = n % 2
    middle = np.partition(x, half)[half : half + 1] if odd else np.array(_kth_pair(x, half - 1))
    m = float(np.add.reduce(middle) / middle.size)  # numpy's mean of the middle value(s)
    # which of equal values (0.0 and -0.0) a partition selects is its own: a zero result's
    # sign is numpy's to decide when both zeros are present
    return m if m != 0.0 or _one_zero(x) else float(np.median(x))


def percentile(x: np.ndarray, q: float) -> float:
    """``float(np.percentile(x, q))`` (linear method) of a 1-D float array, exactly.

    Parameters
    ----------
    x : numpy.ndarray
        1-D, float64, not empty.
    q : float
        Percentile in [0, 100].

    Returns
    -------
    float
    """
    n = x.size
    if n < 3 or not np.isfinite(x).all():
        return float(np.percentile(x, q))
    virtual = float((n - 1) * np.true_divide(q, 100))
    if not 0 <= virtual <= n - 1:
        return float(np.percentile(x, q))
    if virtual == n - 1:  # numpy takes the last value twice, at gamma = n
        low = high = x.max()
        gamma = float(n)
    else:
        k = int(np.floor(virtual))
        gamma = virtual - k
        low, high = _kth_pair(x, k)
    diff = high - low
    p = float(high - diff * (1 - gamma)) if gamma >= 0.5 else float(low + diff * gamma)
    return p if p != 0.0 or _one_zero(x) else float(np.percentile(x, q))  # see median


_kernel = None  # the compiled running median, once loaded (:func:`load_kernel`)


def load_kernel() -> None:
    """Load the compiled running median (numba and its cached machine code: about 0.35 s of
    CPU, which pays back over a few million samples); from then on :func:`median_filter`
    uses it."""
    global _kernel
    if _kernel is None:
        from ._kernels import running_median

        _kernel = running_median


def median_filter(x: np.ndarray, size: int) -> np.ndarray:
    """``scipy.ndimage.median_filter(x, size=size, mode="nearest")`` of a 1-D float array,
    exactly; from the compiled :func:`~fricid.extract._kernels.running_median` once
    :func:`load_kernel` has loaded it (three times faster than scipy's, and it releases the
    GIL).

    scipy itself filters what the kernel does not cover: an even ``size``, non-finite values,
    and an ``x`` holding both 0.0 and -0.0 (which of two equal values a filter selects is its
    own, and only the sign of a zero could tell).

    Parameters
    ----------
    x : numpy.ndarray
        1-D float64.
    size : int
        Samples in the window.

    Returns
    -------
    numpy.ndarray
        A new array.
    """
    x = np.ascontiguousarray(x, dtype=float)
    size = int(size)
    kernel = _kernel
    if kernel is None or size < 3 or size % 2 == 0 or x.size == 0 or not _plain(x):
        from scipy.ndimage import median_filter as scipy_median_filter

        return scipy_median_filter(x, size=size, mode="nearest")
    out = np.empty_like(x)
    kernel(x, size, out)
    return out


def _plain(x: np.ndarray) -> bool:
    """Finite, and zeros (if any) of one sign only."""
    return bool(np.isfinite(x).all()) and _one_zero(x)


def _one_zero(x: np.ndarray) -> bool:
    """No zeros, or zeros of one sign only (0.0 or -0.0)."""
    sign = np.signbit(x[x == 0.0])
    return bool(sign.all() or not sign.any())
