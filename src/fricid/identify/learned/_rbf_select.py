"""Choices made before an RBF network is trained (issue 11, "Validation built in"): the number
of centres by cross-validated error, and inputs that do not vary dropped with a note.

Used by :func:`fricid.identify.learned.rbf.fit_rbf`; the estimator itself
(:class:`~fricid.identify.learned.rbf.RBFNetRegressor`) stays a plain scikit-learn regressor.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Mapping, Sequence
from numbers import Integral
from typing import Any

import numpy as np
import scipy.linalg

from ...errors import DataError, DataQualityWarning, IdentifiabilityWarning, user_stacklevel
from ...models.rbf import tail_columns
from ._conformal import INTERVAL_LEVELS, conformal_half_widths
from ._rbf_estimator import LSQ_IGNORES, RBFNetRegressor
from ._rbf_folds import FOLDS, choose_penalty, cv_folds

__all__ = [
    "ALPHAS",
    "INTERVAL_LEVELS",
    "MAX_AUTO_CENTERS",
    "STRETCHES",
    "WIDTH_FACTORS",
    "centre_grid",
    "check_centres",
    "choose_n_centers",
    "choose_structure",
    "conformal_half_widths",
    "drop_constant_inputs",
    "structure_grid",
]

#: The largest number of centres :func:`choose_n_centers` tries.
MAX_AUTO_CENTERS = 60


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


#: Width factors (:class:`RBFNetRegressor` ``width_factor``) :func:`choose_structure` tries
#: when none is given.
WIDTH_FACTORS = (1.0, 1.5, 2.2, 3.2)

#: Ridge penalties (``alpha``, on the target scaled to [-1, 1]) it tries when none is given.
ALPHAS = (1e-11, 1e-8, 1e-5)


#: Fewest distinct levels of the first input (the speed) for the quadratic tail.
QUADRATIC_MIN_LEVELS = 6

#: Velocity stretches (:class:`RBFNetRegressor` ``velocity_stretch``) it tries.
STRETCHES = (1.0, 2.0, 4.0)


def structure_grid(n: int) -> list[int]:
    """Candidate numbers of centres of :func:`choose_structure` for ``n`` samples: eight
    values spaced geometrically from 5 to ``min(400, n / 4)``."""
    hi = max(1, min(400, n // 4))
    lo = min(5, hi)
    return sorted({int(np.rint(x)) for x in np.geomspace(lo, hi, 8)})


def _kmeans_centres(Z: np.ndarray, m: int, random_state: Any) -> np.ndarray:
    """The centres :class:`RBFNetRegressor` ``.fit`` places with ``random_state`` (the same
    draws in the same order, so the chosen candidate is the network fit trains)."""
    from sklearn.utils import check_random_state

    from ._rbf_estimator import _KMEANS_MIN, _KMEANS_PER_CENTRE, kmeans_centres

    seed = _seed(random_state)
    n = Z.shape[0]
    n_kmeans = max(_KMEANS_MIN, _KMEANS_PER_CENTRE * m)
    if n <= n_kmeans:  # no subset drawn: the first draw only, the same for every call
        return kmeans_centres(Z, m, _first_seed(seed))
    rs = check_random_state(seed)
    kmeans_seed = int(rs.randint(np.iinfo(np.int32).max))
    rs.randint(np.iinfo(np.int32).max)  # the search seed, drawn second by fit
    return kmeans_centres(Z[rs.permutation(n)[:n_kmeans]], m, kmeans_seed)


@functools.lru_cache(maxsize=64)
def _first_seed(seed: int) -> int:
    """The k-means seed :class:`RBFNetRegressor` ``.fit`` draws first from ``seed``
    (memoised: the structure search asks for it 20-40 times per network, and each new
    ``RandomState`` costs about 0.1 ms)."""
    return int(np.random.RandomState(seed).randint(np.iinfo(np.int32).max))


class _CrossValidation:
    """k-fold held-out residuals of ``lsq`` networks sharing their hidden layers (see
    :func:`choose_structure`); ``residuals(m, wf, stretch)`` -> (alpha index, score [N m],
    residuals [N m] of every fold set pooled, RMSE [N m] per fold set: random, then levels)
    of the best penalty, memoised. The score is the random folds' RMSE, or
    ``max(random, levels / LEVEL_GAP_ALLOWANCE)`` with level folds; the penalty by
    :func:`~fricid.identify.learned._rbf_folds.choose_penalty`
    (:mod:`fricid.identify.learned._rbf_folds`)."""

    def __init__(
        self,
        X: np.ndarray,
        t: np.ndarray,
        params: Mapping[str, Any],
        alphas,
        speed_input: bool = True,
    ) -> None:
        n, self.d = X.shape
        vscale = params.get("velocity_scale")
        Xw = X.copy()
        if vscale is not None:
            Xw[:, 0] = np.arcsinh(Xw[:, 0] / float(vscale))
        self.Z = (Xw - Xw.mean(axis=0)) / Xw.std(axis=0)
        self.linear = bool(params.get("linear_tail"))
        self.fit_bias = bool(params.get("fit_bias", True)) or self.linear
        self.L = {}
        for order in (1, 2):
            F = tail_columns(X, tuple(params.get("linear_magnitude") or ()), order)
            sd = F.std(axis=0)
            self.L[order] = (F - F.mean(axis=0)) / np.where(sd > 0, sd, 1.0)
        if self.fit_bias:
            mid, half = 0.5 * (t.max() + t.min()), 0.5 * (t.max() - t.min())
        else:
            mid, half = 0.0, float(np.max(np.abs(t)))
        self.half = half if half > 0 else 1.0
        self.ts = (t - mid) / self.half
        self.seed = _seed(params.get("random_state"))
        self.alphas = alphas
        speed = X[:, 0] if speed_input else None
        levels = bool(params.get("level_folds", True))
        rnd, lvl, self.note = cv_folds(speed, n, self.seed, levels=levels)
        self.splits = rnd
        self.folds = len(rnd)
        #: (splits, held-out mask) of the random folds, then of the level folds if any
        self.sets = []
        for splits in (rnd, lvl) if lvl else (rnd,):
            held = np.zeros(n, dtype=bool)
            for _, test in splits:
                held[test] = True
            self.sets.append((splits, held))
        self.held = self.sets[-1][1]
        self._centres: dict[tuple[int, float], np.ndarray] = {}
        self._memo: dict[tuple, tuple[int, float, np.ndarray]] = {}

    def residuals(
        self, m: int, wf: float, stretch: float, order: int = 1
    ) -> tuple[int, float, np.ndarray, list[float]]:
        from ...models import _rbf_core as core

        key = (m, wf, stretch, order)
        if key in self._memo:
            return self._memo[key]
        Z = self.Z.copy()
        Z[:, 0] *= stretch
        if (m, stretch) not in self._centres:
            self._centres[(m, stretch)] = _kmeans_centres(Z, m, self.seed)
        C = self._centres[(m, stretch)]
        A = core.design(Z, C, core.nn_widths(C, wf, float(np.sqrt(self.d))))
        if self.linear:
            A = np.hstack([A, self.L[order]])
        oof = np.full((len(self.sets), len(self.alphas), len(self.ts)), np.nan)
        # the training folds' normal equations from the whole set's minus the held-out
        # fold's (one Gram matrix of all samples, one of each fold: half the products of
        # forming each training fold's), centred through the column sums when fitting a bias
        S_all, s_all, r_all = A.T @ A, A.sum(axis=0), A.T @ self.ts
        folds = []
        for j, (splits, _) in enumerate(self.sets):
            for train, test in splits:
                Ae, te, nt = A[test], self.ts[test], len(train)
                mu = (s_all - Ae.sum(axis=0)) / nt if self.fit_bias else np.zeros(A.shape[1])
                tm = float((self.ts.sum() - te.sum()) / nt) if self.fit_bias else 0.0
                G = (S_all - Ae.T @ Ae - nt * np.outer(mu, mu)) / nt
                h = (r_all - Ae.T @ te - nt * tm * mu) / nt
                folds.append((j, test, mu, tm, G, h))
        W = self._solve_all([f[4] for f in folds], [f[5] for f in folds])
        for (j, test, mu, tm, _, _), w in zip(folds, W, strict=True):
            oof[j][:, test] = ((A[test] - mu) @ w.T + tm).T
        # level folds hold out no end level
        errs = [oof[j][:, held] - self.ts[held] for j, (_, held) in enumerate(self.sets)]
        err = np.concatenate(errs, axis=1)
        k, rmse, per = choose_penalty([e * self.half for e in errs], self.alphas)
        out = (k, float(rmse[k]), err[k] * self.half, [float(p[k]) for p in per])
        self._memo[key] = out
        return out

    #: Up to this many output weights, :meth:`_solve_all` solves every fold and penalty in
    #: one batched call (the per-call overhead dominates small systems); above, one Cholesky
    #: solve each (a batched LU would cost twice the arithmetic).
    BATCH_MAX = 128

    def _solve_all(self, Gs: list[np.ndarray], hs: list[np.ndarray]) -> np.ndarray:
        """Ridge solutions ``(G + alpha I) w = h`` for every fold (``Gs``, ``hs``) and penalty
        of :attr:`alphas`: ``(folds, len(alphas), p)``. Cholesky where ``G + alpha I`` is
        positive definite, else least squares (rounding can leave it indefinite)."""
        G = np.asarray(Gs)
        h = np.asarray(hs)
        nf, p = h.shape
        alphas = np.asarray(self.alphas, dtype=float)
        if p <= self.BATCH_MAX:
            GA = np.repeat(G[:, None], len(alphas), axis=1)
            GA[..., np.arange(p), np.arange(p)] += alphas[None, :, None]
            try:
                np.linalg.cholesky(GA)  # positive definite, all of them (else per system)
                hA = np.broadcast_to(h[:, None, :, None], (nf, len(alphas), p, 1))
                return np.linalg.solve(GA, hA)[..., 0]
            except np.linalg.LinAlgError:
                pass
        W = np.empty((nf, len(alphas), p))
        for f in range(nf):
            for k, alpha in enumerate(alphas):
                Gk = G[f].copy()
                Gk[np.diag_indices_from(Gk)] += alpha
                try:
                    W[f, k] = scipy.linalg.cho_solve(
                        scipy.linalg.cho_factor(Gk, check_finite=False, overwrite_a=True),
                        h[f],
                        check_finite=False,
                    )
                except (np.linalg.LinAlgError, scipy.linalg.LinAlgError):
                    W[f, k] = np.linalg.lstsq(G[f] + alpha * np.eye(p), h[f], rcond=None)[0]
        return W


def choose_structure(
    X: np.ndarray, t: np.ndarray, params: Mapping[str, Any], speed_input: bool = True
) -> tuple[dict[str, Any], dict[str, Any]]:
    """Number of centres, width factor, velocity stretch and ridge penalty of the ``lsq``
    network by cross-validation over random folds and folds of whole speed levels (issue 15,
    "defaults chosen by the held-out error that matters": the score of
    :mod:`fricid.identify.learned._rbf_folds`; random folds only when there are too few levels),
    and prediction intervals from the chosen candidate's held-out residuals.

    The search is coordinate-wise: the number of centres over :func:`structure_grid` (width
    factor 1.5, no stretch), then the width factor (:data:`WIDTH_FACTORS`), the velocity
    stretch (:data:`STRETCHES`), the linear tail's order (1 or 2, when ``linear_tail``; 2 only
    with at least :data:`QUADRATIC_MIN_LEVELS` speed levels), and the number of centres once
    more; every candidate takes its best penalty among :data:`ALPHAS`. Candidates share their
    hidden layers across folds: the k-means centres are placed once per number of centres and
    stretch on all inputs (as ``fit`` places them with the same ``random_state``; the targets
    are not used, so no held-out target leaks into them), and for each fold the output layer
    (weights, the linear tail when ``linear_tail``, bias) is solved by ridge least squares for
    every penalty. One least-squares solve per candidate, fold and penalty: fast.

    Parameters
    ----------
    X : ndarray, shape (n, d)
        The network's inputs (velocity first when it is an input).
    t : ndarray, shape (n,)
        Targets [N m].
    params : mapping
        :class:`RBFNetRegressor` parameters; those given (not None) among ``n_centers``,
        ``width_factor``, ``velocity_stretch``, ``alpha`` are held, the others chosen.
    speed_input : bool
        The first input is the speed ``|v|`` (its levels make the folds).

    Returns
    -------
    dict
        The chosen ``n_centers``, ``width_factor``, ``velocity_stretch``, ``alpha``.
    dict
        The note saved in the model file: ``grid`` (centres), ``width_factors``,
        ``stretches``, ``alphas``, ``folds`` (random), ``cv_folds``, ``cv_levels``,
        ``level_folds``, ``cv_note`` (:func:`~fricid.identify.learned._rbf_folds.cv_folds`),
        ``cv_rmse`` [N m] the score per number of centres (last pass), ``n_held`` (samples
        the level folds hold out, else all), ``chosen`` (centres), ``chosen_width_factor``,
        ``chosen_stretch``, ``chosen_alpha``, ``cv_rmse_chosen`` (random folds),
        ``cv_rmse_levels_chosen`` and ``cv_score_chosen`` (with level folds) and
        ``prediction_interval`` (levels, half-widths [N m], method).
    """
    n = X.shape[0]

    def held(key: str, default):
        return (params[key],) if params.get(key) is not None else default

    grid = [int(m) for m in held("n_centers", structure_grid(n)) if int(m) <= n] or [1]
    widths = tuple(float(w) for w in held("width_factor", WIDTH_FACTORS))
    stretches = (1.0,)
    if params.get("velocity_scale") is not None or params.get("velocity_stretch") is not None:
        stretches = tuple(float(x) for x in held("velocity_stretch", STRETCHES))
    alphas = tuple(max(float(a), 1e-12) for a in held("alpha", ALPHAS))
    cv = _CrossValidation(X, t, params, alphas, speed_input)
    note: dict[str, Any] = {
        "grid": grid,
        "width_factors": list(widths),
        "stretches": list(stretches),
        "alphas": list(alphas),
        "folds": cv.folds,
        "n_held": int(cv.held.sum()),
        **cv.note,
        "trainer": "lsq",
    }
    wf = 1.5 if 1.5 in widths else widths[0]
    stretch = stretches[0]
    if not cv.splits:  # too few samples to cross-validate: the largest candidate
        note.update(cv_rmse=None, chosen=grid[-1], cv_rmse_chosen=None)
        return {
            "n_centers": grid[-1],
            "width_factor": wf,
            "velocity_stretch": stretch,
            "alpha": alphas[0],
        }, note

    def best_of(cands):
        scores = [cv.residuals(*c)[1] for c in cands]
        return cands[int(np.argmin(scores))], scores

    orders = (1,)
    if params.get("linear_tail"):
        # the quadratic tail only with the levels to resolve it (a few levels: overfitting)
        # levels: distinct speeds to a tenth of a decade (measured speeds scatter about
        # their set-points)
        first = np.abs(X[:, 0])
        levels = np.unique(np.round(np.log10(first[first > 0]), 1)).size
        tried = (1, 2) if levels >= QUADRATIC_MIN_LEVELS else (1,)
        orders = (int(params["tail_order"]),) if params.get("tail_order") else tried
    order = orders[0]
    (m, _, _, _), _ = best_of([(g, wf, stretch, order) for g in grid])
    (_, wf, _, _), _ = best_of([(m, w, stretch, order) for w in widths])
    (_, _, stretch, _), _ = best_of([(m, wf, x, order) for x in stretches])
    (_, _, _, order), _ = best_of([(m, wf, stretch, o) for o in orders])
    (m, _, _, _), per_m = best_of([(g, wf, stretch, order) for g in grid])
    k, score, resid, per = cv.residuals(m, wf, stretch, order)
    n = len(t)
    held = (
        "random folds"
        if len(per) == 1
        else "random folds and folds of interior speed levels, pooled"
    )
    if len(per) == 2:
        note.update(cv_rmse_levels_chosen=per[1], cv_score_chosen=score)
    note.update(
        cv_rmse=[r if np.isfinite(r) else None for r in per_m],
        chosen=m,
        chosen_width_factor=wf,
        chosen_stretch=stretch,
        chosen_alpha=alphas[k],
        chosen_tail_order=order,
        cv_rmse_chosen=per[0],
        heldout_errors=np.abs(resid[:n]),  # the random folds': every sample, in order
        prediction_interval={
            "levels": list(INTERVAL_LEVELS),
            "half_width": conformal_half_widths(resid),
            "method": f"conformal: quantiles of the {cv.folds}-fold cross-validation "
            f"residuals of the chosen candidate (CV+, Barber et al. 2021; {held})",
        },
    )
    chosen = {
        "n_centers": m,
        "width_factor": wf,
        "velocity_stretch": stretch,
        "alpha": alphas[k],
        **({"tail_order": order} if params.get("linear_tail") else {}),
    }
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
            stacklevel=user_stacklevel(),
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
            stacklevel=user_stacklevel(),
        )
    return kept, dropped
