"""Folds of the RBF structure search (issue 15, "defaults chosen by the held-out error that
matters"): random folds, and folds of whole measured speed levels.

A learned model is used between the speeds it was measured at (the held-out laws of
:mod:`fricid.sim.heldout_laws` test random points in the design's box; the report judges it
by leave-one-velocity-out, :mod:`fricid.identify.validate`). Folds of samples dealt at random
keep every velocity level in training, so they reward a network that reproduces the measured
levels and say nothing of the speeds between them: on the demo's samples (6 speeds) the
random 5-fold CV of the hybrid's residual chose 82 centres and a ridge penalty of 1e-8, at
0.63x the scatter out of fold but 41x over the interior folds of leave-one-velocity-out.

:func:`cv_folds` deals both. The level folds are scikit-learn's ``GroupKFold`` idea with the
distinct speeds as groups: the :data:`END_LEVELS` slowest and fastest levels always stay in
training, and the interior levels go round-robin by speed into ``min(5, interior)`` folds
(one at least),
so each held-out level has measured neighbours in training. Holding a level out doubles the
gap the network must bridge, so the level folds' error overstates the error between two
measured levels; and next to the ends (one end level left in training) it measures
extrapolation more than interpolation: with one end level kept, the level folds alone chose
settings that doubled the ``rbf``'s held-out error on the ``grid`` kind (tuning seeds 0-49).
The structure search (:mod:`fricid.identify._rbf_select`) therefore scores a candidate by
``max(random-fold RMSE, level-fold RMSE / LEVEL_GAP_ALLOWANCE)``: the measured levels must be
followed, and the error across a doubled gap may be at most :data:`LEVEL_GAP_ALLOWANCE` times
that. With fewer than :data:`MIN_LEVELS` levels (or no speed input) only the random folds
are dealt, and the note saved in the model file says so.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._scatter import LEVEL_RTOL

__all__ = [
    "END_LEVELS",
    "FOLDS",
    "LEVEL_GAP_ALLOWANCE",
    "MIN_LEVELS",
    "cv_folds",
    "speed_levels",
]

#: Most folds of either kind.
FOLDS = 5

#: Levels at each end of the speed range that the level folds never hold out.
END_LEVELS = 2

#: Fewest distinct speed levels for level folds: one interior level, one fold (so that the
#: demo's 6 levels keep level folds when leave-one-velocity-out takes one away).
MIN_LEVELS = 2 * END_LEVELS + 1

#: How many times the random folds' error the level folds' may reach before it sets a
#: candidate's score (a held-out level doubles the gap between training speeds).
LEVEL_GAP_ALLOWANCE = 2.0

Split = tuple[np.ndarray, np.ndarray]


def speed_levels(speed: np.ndarray, rtol: float = LEVEL_RTOL) -> np.ndarray:
    """Level index of each ``|speed|`` (0 the slowest): sorted speeds within ``rtol`` of each
    other share one, as :func:`fricid.identify._scatter.level_labels` groups samples."""
    s_abs = np.abs(np.asarray(speed, dtype=float))
    order = np.argsort(s_abs, kind="stable")
    s = s_abs[order]
    new = np.r_[False, s[1:] > s[:-1] * (1.0 + rtol) + 1e-12]
    labels = np.empty(s.size, dtype=int)
    labels[order] = np.cumsum(new)
    return labels


def cv_folds(
    speed: np.ndarray | None, n: int, seed: int
) -> tuple[list[Split], list[Split], dict[str, Any]]:
    """Train/test index pairs of the structure search, and what they are.

    Parameters
    ----------
    speed : ndarray (n,) or None
        The samples' speeds (the network's first input when it is the velocity), or None when
        the network has no speed input.
    n : int
        Samples.
    seed : int
        Deals the random folds.

    Returns
    -------
    list of (train, test)
        Random folds: ``min(5, n // 2)`` (none below two).
    list of (train, test)
        Level folds (module notes), empty with too few levels; the end levels' samples are in
        no test fold.
    dict
        ``cv_folds`` (``"velocity_levels"`` when there are level folds, else ``"random"``),
        ``cv_levels`` (distinct speed levels, None without a speed input), ``level_folds``
        and ``cv_note`` (one sentence), for the model file's ``n_centers_selection``.
    """
    from sklearn.model_selection import KFold

    k = min(FOLDS, n // 2)
    rnd = list(KFold(k, shuffle=True, random_state=seed).split(np.empty(n))) if k >= 2 else []
    levels = speed_levels(speed) if speed is not None else None
    n_levels = int(levels.max()) + 1 if levels is not None and levels.size else 0
    if levels is None or n_levels < MIN_LEVELS or len(rnd) < 2:
        why = (
            "the network has no speed input"
            if levels is None
            else f"{n_levels} speed level(s), fewer than the {MIN_LEVELS} level folds need"
        )
        note = (
            f"{len(rnd)} random folds only ({why}): every speed level stays in training, so "
            "the error is at the measured levels only"
        )
        return rnd, [], {"cv_folds": "random", "cv_levels": n_levels or None, "cv_note": note}
    inner = n_levels - 2 * END_LEVELS
    kl = min(FOLDS, inner)
    fold_of_level = np.full(n_levels, -1)
    fold_of_level[END_LEVELS:-END_LEVELS] = np.arange(inner) % kl
    fold = fold_of_level[levels]
    lvl = [(np.flatnonzero(fold != f), np.flatnonzero(fold == f)) for f in range(kl)]
    note = (
        f"{len(rnd)} random folds and {kl} folds of whole speed levels (the {inner} interior "
        f"levels of {n_levels} dealt round-robin by speed, the {END_LEVELS} slowest and "
        f"fastest always in training); score max(random, levels / {LEVEL_GAP_ALLOWANCE:g})"
    )
    info = {"cv_folds": "velocity_levels", "cv_levels": n_levels, "level_folds": kl}
    return rnd, lvl, {**info, "cv_note": note}
