"""Choices made before an RBF network is trained (issue 11, "Validation built in"): the number
of centres by cross-validated error, and inputs that do not vary dropped with a note.

Used by :func:`fricid.identify.rbf.fit_rbf`; the estimator itself
(:class:`~fricid.identify.rbf.RBFNetRegressor`) stays a plain scikit-learn regressor.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from numbers import Integral
from typing import Any

import numpy as np

from ..errors import DataError, DataQualityWarning, IdentifiabilityWarning
from ._rbf_estimator import LSQ_IGNORES, RBFNetRegressor

__all__ = [
    "MAX_AUTO_CENTERS",
    "centre_grid",
    "check_centres",
    "choose_n_centers",
    "drop_constant_inputs",
]

#: The largest number of centres :func:`choose_n_centers` tries.
MAX_AUTO_CENTERS = 60

#: Folds of the cross-validation behind :func:`choose_n_centers`.
FOLDS = 5


def centre_grid(n: int) -> list[int]:
    """Candidate numbers of centres for ``n`` samples: about six values spaced
    geometrically from 5 to ``min(60, n / 3)`` (fewer for small ``n``)."""
    hi = max(1, min(MAX_AUTO_CENTERS, n // 3))
    lo = min(5, hi)
    return sorted({int(np.rint(x)) for x in np.geomspace(lo, hi, 6)})


def _seed(random_state: Any) -> int:
    return int(random_state) if isinstance(random_state, Integral) else 0


def choose_n_centers(
    X: np.ndarray, t: np.ndarray, params: Mapping[str, Any]
) -> tuple[int, dict[str, Any]]:
    """The number of centres with the smallest k-fold held-out RMSE of the fast ``lsq``
    trainer, over :func:`centre_grid`.

    Parameters
    ----------
    X : ndarray, shape (n, d)
        The network's inputs.
    t : ndarray, shape (n,)
        Its targets [N m].
    params : mapping
        The :class:`RBFNetRegressor` parameters of the fit (width factor, ridge penalty,
        velocity warp, ``random_state``); the optimiser's are left out, since the
        cross-validation trains with ``lsq``.

    Returns
    -------
    int
        The chosen number of centres (the smallest of equal errors).
    dict
        ``grid``, ``cv_rmse`` [N m] per candidate (None where a fold could not be trained),
        ``folds`` and ``chosen``, saved in the model file.
    """
    from sklearn.model_selection import KFold

    n = len(t)
    grid = centre_grid(n)
    folds = min(FOLDS, n // 2)
    note: dict[str, Any] = {"grid": grid, "folds": folds, "trainer": "lsq"}
    if folds < 2 or len(grid) == 1:
        note.update(cv_rmse=None, chosen=grid[-1])
        return grid[-1], note
    skip = (*LSQ_IGNORES, "trainer", "n_centers")
    lsq = {k: v for k, v in params.items() if k not in skip}
    seed = _seed(params.get("random_state"))
    lsq["random_state"] = seed
    splits = list(KFold(folds, shuffle=True, random_state=seed).split(X))
    rmse = []
    for m in grid:
        sq = 0.0
        try:
            for train, test in splits:
                if m > len(train):
                    raise DataError("more centres than training samples")
                est = RBFNetRegressor(m, trainer="lsq", **lsq).fit(X[train], t[train])
                sq += float(np.sum((est.predict(X[test]) - t[test]) ** 2))
        except DataError:
            rmse.append(np.inf)
            continue
        rmse.append(float(np.sqrt(sq / n)))
    best = int(np.argmin(rmse))
    chosen = grid[best] if np.isfinite(rmse[best]) else grid[0]
    note.update(cv_rmse=[r if np.isfinite(r) else None for r in rmse], chosen=chosen)
    return chosen, note


def check_centres(m: int, n: int, where: str = "") -> None:
    """Warn (:class:`~fricid.errors.IdentifiabilityWarning`) when a network has about as many
    centres as samples (more than one per two): it can interpolate the measurement noise, and
    its held-out error is then far above its in-sample error."""
    if m > n / 2:
        warnings.warn(
            f"the RBF network{where} has {m} centres for {n} samples: about as many "
            "centres as samples, so it interpolates the measurement noise (the held-out error "
            "is far above the in-sample error); use fewer centres, or leave the number unset "
            "(fricid chooses it by cross-validation)",
            IdentifiabilityWarning,
            stacklevel=4,
        )


def drop_constant_inputs(
    X: np.ndarray, names: Sequence[str], where: str = ""
) -> tuple[list[str], dict[str, float]]:
    """The inputs among ``names`` (columns of ``X``) that vary, and those that do not.

    A column with zero variance carries no information and cannot be standardised; it is
    dropped with a :class:`~fricid.errors.DataQualityWarning` naming it and its value (saved
    in the model file as ``state["dropped_inputs"]``). Predictions at another value of it
    are extrapolations, which the operating range (a single value) then reports.

    Returns
    -------
    list of str
        The inputs kept, in order.
    dict
        Dropped input name -> its constant value.

    Raises
    ------
    DataError
        When no input varies.
    """
    kept, dropped = [], {}
    for j, name in enumerate(names):
        col = X[:, j]
        spread = float(np.max(col) - np.min(col))
        if spread > 1e-12 * max(1.0, float(np.max(np.abs(col)))):
            kept.append(name)
        else:
            dropped[name] = float(col[0])
    if dropped:
        what = ", ".join(f"{k} (every sample at {v:.6g})" for k, v in dropped.items())
        if not kept:
            raise DataError(
                f"no input of the RBF network{where} varies: {what}; it has nothing to learn from"
            )
        warnings.warn(
            f"the RBF network{where} drops the input(s) that do not vary: {what}; the model "
            f"uses {', '.join(kept)} only (noted in the model file)",
            DataQualityWarning,
            stacklevel=4,
        )
    return kept, dropped
