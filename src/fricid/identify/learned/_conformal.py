"""Conformal half-widths of the learned models' prediction intervals from held-out residuals
(:func:`conformal_half_widths`), with the fall-back that still covers on a dozen samples."""

from __future__ import annotations

import numpy as np
from scipy import stats

__all__ = ["INTERVAL_LEVELS", "conformal_half_widths"]

#: Levels of the prediction intervals stored with a learned model.
INTERVAL_LEVELS = (0.9, 0.95)


def conformal_half_widths(residuals: np.ndarray, levels=INTERVAL_LEVELS) -> list[float]:
    """Half-widths of split-conformal prediction intervals from held-out residuals: the
    ``ceil((n + 1) level)``-th smallest ``|r|`` (Vovk et al. 2005; with cross-validation
    residuals, the CV+ reading of Barber et al. 2021, whose coverage is at least
    ``2 level - 1``).

    When ``n`` is too small for the level (``ceil((n + 1) level) > n``: fewer than 19
    residuals at 95 %), the largest ``|r|`` covers only about ``n / (n + 1)`` (86 % with
    six); the half-width is then the larger of it and the Student-t interval of the
    residuals, ``t(0.5 + level / 2, n - 1) sqrt(mean r^2) sqrt(1 + 1 / n)``: exact for
    Gaussian noise, the fall-back that still covers on a dozen samples."""
    r = np.sort(np.abs(np.asarray(residuals, dtype=float)))
    n = r.size
    out = []
    for level in levels:
        k = int(np.ceil((n + 1) * float(level)))
        half = float(r[min(k, n) - 1])
        if k > n and n > 1:
            q = float(stats.t.ppf(0.5 + float(level) / 2, n - 1))
            half = max(half, q * float(np.sqrt(np.mean(r**2) * (1 + 1 / n))))
        out.append(half)
    return out
