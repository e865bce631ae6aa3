"""Goodness-of-fit metrics, as the BAS-RBFNN paper reports them (Table 1, Table 3).

``fitness`` is the coefficient of determination R^2 (the paper's Table 1 "Fitness");
``rmspe`` is the root mean square of the relative error, as a fraction (Table 1 "RMSPE");
mean and max absolute error are Table 3's "Mean" and "Maximum". Values are in the units of
the data (N m for friction).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "fit_statistics",
    "fitness",
    "mae",
    "max_abs_error",
    "metrics",
    "rmse",
    "rmspe",
    "sse",
]


def _pair(y, y_hat) -> tuple[np.ndarray, np.ndarray]:
    y = np.asarray(y, dtype=float)
    y_hat = np.asarray(y_hat, dtype=float)
    if y.shape != y_hat.shape:
        raise ValueError(f"shapes differ: {y.shape} against {y_hat.shape}")
    return y, y_hat


def sse(y, y_hat) -> float:
    """Sum of squared errors (the RWSAVSBAS paper's fitness, eq. 11 there)."""
    y, y_hat = _pair(y, y_hat)
    r = y - y_hat
    return float(r @ r)


def rmse(y, y_hat) -> float:
    """Root mean squared error."""
    y, _ = _pair(y, y_hat)
    return float(np.sqrt(sse(y, y_hat) / y.size))


def fitness(y, y_hat) -> float:
    """Coefficient of determination R^2 = 1 - SSE / SST (BAS-RBFNN paper, Table 1 "Fitness")."""
    y, y_hat = _pair(y, y_hat)
    sst = float(np.sum((y - y.mean()) ** 2))
    if sst == 0.0:
        return 1.0 if sse(y, y_hat) == 0.0 else float("-inf")
    return 1.0 - sse(y, y_hat) / sst


def rmspe(y, y_hat) -> float:
    """Root mean squared relative error, a fraction; points with y == 0 are left out."""
    y, y_hat = _pair(y, y_hat)
    keep = y != 0
    if not keep.any():
        return float("nan")
    rel = (y[keep] - y_hat[keep]) / y[keep]
    return float(np.sqrt(np.mean(rel**2)))


def mae(y, y_hat) -> float:
    """Mean absolute error (Table 3 "Mean")."""
    y, y_hat = _pair(y, y_hat)
    return float(np.mean(np.abs(y - y_hat)))


def max_abs_error(y, y_hat) -> float:
    """Largest absolute error (Table 3 "Maximum")."""
    y, y_hat = _pair(y, y_hat)
    return float(np.max(np.abs(y - y_hat)))


def metrics(y, y_hat) -> dict[str, float]:
    """All of the above, by name."""
    return {
        "fitness": fitness(y, y_hat),
        "sse": sse(y, y_hat),
        "rmse": rmse(y, y_hat),
        "rmspe": rmspe(y, y_hat),
        "mae": mae(y, y_hat),
        "max_abs_error": max_abs_error(y, y_hat),
        "n": float(np.asarray(y).size),
    }


def fit_statistics(y, y_hat, nvarys: int, weights=None) -> dict[str, float]:
    """Fit statistics of a least-squares fit, as lmfit's ``fit_report`` prints them.

    Parameters
    ----------
    y, y_hat : array_like (n,)
        Measured and fitted values.
    nvarys : int
        Number of fitted (free) parameters.
    weights : array_like (n,), optional
        Weights of the squared errors (chi-square is their weighted sum).

    Returns
    -------
    dict
        ``ndata``; ``nvarys``; ``nfree = ndata - nvarys``; ``chisqr``, the (weighted) sum of
        squared errors; ``redchi = chisqr / nfree`` (NaN without spare data);
        ``aic = ndata ln(chisqr / ndata) + 2 nvarys`` and
        ``bic = ndata ln(chisqr / ndata) + ln(ndata) nvarys`` (lmfit's definitions, up to
        the constant they share; chisqr is floored at the smallest positive float so a
        perfect fit gives a finite value); ``rsquared`` (:func:`fitness`).
    """
    y, y_hat = _pair(y, y_hat)
    r = y - y_hat
    w = np.ones_like(r) if weights is None else np.asarray(weights, dtype=float)
    chisqr = float(np.sum(w * r * r))
    n = int(y.size)
    nfree = n - int(nvarys)
    neg2loglik = n * np.log(max(chisqr, np.finfo(float).tiny) / n) if n else float("nan")
    return {
        "ndata": float(n),
        "nvarys": float(nvarys),
        "nfree": float(nfree),
        "chisqr": chisqr,
        "redchi": chisqr / nfree if nfree > 0 else float("nan"),
        "aic": float(neg2loglik + 2 * nvarys),
        "bic": float(neg2loglik + np.log(n) * nvarys) if n else float("nan"),
        "rsquared": fitness(y, y_hat),
    }
