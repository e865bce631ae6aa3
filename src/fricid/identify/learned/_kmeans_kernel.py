"""The compiled greedy k-means++ seeding of the RBF network's centres (numba, cached on disk).

A module of its own so that importing :mod:`fricid.identify.learned.rbf` does not import numba, and
so
that the kernel is a module-level function numba can cache across processes. It runs the
arithmetic of scikit-learn's ``_kmeans_plusplus`` (unit sample weights) in one compiled loop,
where scikit-learn's makes about ten numpy calls per centre: a fixed cost that grows with the
number of centres and is paid 20-40 times per residual network by the cross-validated structure
search (:func:`fricid.identify.learned._rbf_estimator.kmeans_centres`). With the memoised random
streams the hybrid trained 13-15 % faster on issue 15's held-out laws (median times of the two
implementations alternated in one process, a one-off script, 2026-11-23) and gives the same
models on their tuning and reporting seeds (``benchmarks/bench_learned_tuning.py``,
``benchmarks/bench_floor.py``).

Lloyd's iterations stay scikit-learn's (its public ``KMeans`` started from these seeds). A
compiled copy of them (tried, not kept) resolved the
exact ties of lattice data (a design grid's points equidistant from two centres) otherwise than
scikit-learn's BLAS rounding does, and over the tuning seeds 0-49 of issue 15's grid kind the
networks were worse with it (hybrid 1.134 against 1.110 x the noise, rbf 1.245 against 1.196;
``python benchmarks/bench_learned_tuning.py`` with that copy, 2026-11-23).
"""

from __future__ import annotations

import numpy as np

from fricid._jit import njit  # absolute: the module may move within identify/

__all__ = ["plusplus"]


@njit(cache=True)
def _sq_dist(Xc, xx, i, out):  # pragma: no cover - compiled
    """``||x_i - x_j||^2`` for every j as scikit-learn forms it, ``-2 x_i.x_j + |x_i|^2 +
    |x_j|^2``, clipped at 0."""
    n, d = Xc.shape
    for j in range(n):
        dot = 0.0
        for k in range(d):
            dot += Xc[i, k] * Xc[j, k]
        v = -2.0 * dot + xx[i] + xx[j]
        out[j] = v if v > 0.0 else 0.0


@njit(cache=True)
def plusplus(Xc, first, U):  # pragma: no cover - compiled
    """Indices of the greedy k-means++ seeds (Arthur and Vassilvitskii 2007) of the centred
    data ``Xc``: ``first`` the first seed, ``U`` (m - 1, trials) the uniform draws of the
    local trials of each further seed, in scikit-learn's order."""
    n = Xc.shape[0]
    m = U.shape[0] + 1
    trials = U.shape[1]
    xx = np.empty(n)
    for j in range(n):
        s = 0.0
        for k in range(Xc.shape[1]):
            s += Xc[j, k] * Xc[j, k]
        xx[j] = s
    idx = np.empty(m, dtype=np.int64)
    idx[0] = first
    closest = np.empty(n)
    _sq_dist(Xc, xx, first, closest)
    pot = closest.sum()
    cum = np.empty(n)
    D = np.empty((trials, n))
    cand = np.empty(trials, dtype=np.int64)
    for c in range(1, m):
        acc = 0.0
        for j in range(n):
            acc += closest[j]
            cum[j] = acc
        best, best_pot = 0, np.inf
        for t in range(trials):
            cand[t] = min(np.searchsorted(cum, U[c - 1, t] * pot), n - 1)
            _sq_dist(Xc, xx, cand[t], D[t])
            s = 0.0
            for j in range(n):
                if closest[j] < D[t, j]:
                    D[t, j] = closest[j]
                s += D[t, j]
            if s < best_pot:
                best, best_pot = t, s
        pot = best_pot
        closest[:] = D[best]
        idx[c] = cand[best]
    return idx
