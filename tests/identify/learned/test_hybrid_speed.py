"""The hybrid's fast training paths (issue 15's training-time goal) give what the slow ones
gave: the lean backbone selection chooses the family the full fits choose, and the residual
network's batched cross-validation solves the systems the per-system path solves."""

from __future__ import annotations

import numpy as np
import pytest

from fricid.identify.learned._rbf_select import _CrossValidation
from fricid.identify.learned.hybrid import fit_backbone
from fricid.sim.heldout_laws import draw


@pytest.mark.slow  # 7 s measured under load (default run kept short)
@pytest.mark.parametrize(("kind", "seed"), [("asym_arrhenius", 7), ("sigmoid", 3)])
def test_lean_backbone_selection_picks_the_full_fits_family(kind, seed):
    samples = draw(kind, seed).train  # tuning seeds
    lean, lean_table, _ = fit_backbone(samples)
    full, full_table, _ = fit_backbone(samples, lean=False)
    assert lean.model == full.model
    assert lean.fixed == full.fixed
    assert [r["model"] for r in lean_table] == [r["model"] for r in full_table]
    for a, b in zip(lean_table, full_table, strict=True):
        assert (a["bic"] is None) == (b["bic"] is None)
        if a["bic"] is not None:  # one start, tolerance 1e-8: the same optimum
            assert a["bic"] == pytest.approx(b["bic"], abs=0.01)
    # the winner is fitted in full (convergence certified) but without parameter intervals
    assert lean.convergence["converged"]
    assert lean.statistics["bic"] == pytest.approx(full.statistics["bic"], abs=1e-6)
    assert lean.params == pytest.approx(full.params, rel=1e-5, abs=1e-9)


def test_batched_ridge_solves_match_the_per_system_solves():
    rng = np.random.default_rng(0)
    X = rng.uniform(size=(120, 2))
    t = np.sin(4 * X[:, 0]) + X[:, 1] + 0.01 * rng.normal(size=120)
    cv = _CrossValidation(X, t, {"random_state": 0, "fit_bias": True}, (1e-11, 1e-8, 1e-5))
    A = rng.uniform(size=(120, 30))
    Gs = [A[:90].T @ A[:90] / 90, A[30:].T @ A[30:] / 90]
    hs = [A[:90].T @ t[:90] / 90, A[30:].T @ t[30:] / 90]
    batched = cv._solve_all(Gs, hs)
    cv.BATCH_MAX = 0  # the per-system Cholesky path
    single = cv._solve_all(Gs, hs)
    assert batched.shape == (2, 3, 30)
    for f in range(2):
        for k in range(3):
            r_b = Gs[f] @ batched[f, k] + cv.alphas[k] * batched[f, k] - hs[f]
            r_s = Gs[f] @ single[f, k] + cv.alphas[k] * single[f, k] - hs[f]
            assert np.linalg.norm(r_b) <= 1e-8 * np.linalg.norm(hs[f]) + np.linalg.norm(r_s)
    # well-conditioned penalty: the same weights
    np.testing.assert_allclose(batched[:, 2], single[:, 2], rtol=1e-8, atol=1e-10)


def _kmeans_problems(lattice: bool):
    """30 random k-means problems (sizes, dimensions, numbers of centres); on a lattice (the
    data rounded: duplicate points and exact ties) or not."""
    for seed in range(30):
        rng = np.random.default_rng(seed)
        n = int(rng.integers(20, 600))
        d = int(rng.integers(1, 4))
        m = int(rng.integers(2, min(n, 150)))
        Z = rng.normal(size=(n, d)) * rng.uniform(0.1, 10, size=d)
        yield (np.round(Z) if lattice else Z), m


def _inertia(Z, C):
    return float(((Z[:, None, :] - C[None]) ** 2).sum(-1).min(axis=1).sum())


@pytest.mark.slow  # 10 s measured under load (default run kept short)
@pytest.mark.parametrize("lattice", [False, True])
def test_kmeans_centres_are_scikit_learns(lattice):
    """The compiled k-means (:mod:`fricid.identify.learned._kmeans_kernel`) follows scikit-learn's
    recipe and random stream; its sums round differently from scikit-learn's BLAS calls, so
    where two candidates tie within rounding it may choose the other one. Without exact ties:
    scikit-learn's centres (to rounding) on nearly every problem, as good on the rest; on a
    lattice, where exact ties abound: centres as good as scikit-learn's overall."""
    import warnings

    from sklearn.cluster import KMeans

    from fricid.identify.learned._rbf_estimator import kmeans_centres

    equal, ratios, ours, theirs = 0, [], 0.0, 0.0
    for Z, m in _kmeans_problems(lattice):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            expected = KMeans(n_clusters=m, n_init=1, random_state=12345).fit(Z).cluster_centers_
        got = kmeans_centres(Z, m, 12345)
        ours, theirs = ours + _inertia(Z, got), theirs + _inertia(Z, expected)
        if np.allclose(got, expected, rtol=1e-9, atol=1e-9 * np.abs(Z).max()):
            equal += 1
        elif not lattice:
            ratios.append(_inertia(Z, got) / _inertia(Z, expected))
    if lattice:
        assert 0.9 <= ours / theirs <= 1.1, (ours, theirs)
    else:
        assert equal >= 27, equal
        assert all(0.8 <= r <= 1.25 for r in ratios), ratios


def test_memoised_uniform_streams_are_randomstates_draws():
    """The k-means++ seeding's memoised streams are ``RandomState(seed)``'s draws, whatever
    length was asked for first."""
    from fricid.identify.learned._rbf_estimator import _uniforms

    for seed in (0, 7, 2**31 - 2):
        short = _uniforms(seed, 10)
        long = _uniforms(seed, 5000)  # longer than the first stream: drawn again
        expected = np.random.RandomState(seed).random_sample(5000)
        np.testing.assert_array_equal(long, expected)
        np.testing.assert_array_equal(short, expected[:10])
        assert not long.flags.writeable


def test_lloyd_runs_through_public_kmeans_and_draws_nothing_from_its_random_state():
    """Lloyd's iterations are scikit-learn's public ``KMeans`` started from the compiled
    k-means++ seeds: the same centres as ``KMeans(init=seeds, n_init=1)`` with its own checks,
    and the one random state every call hands it is never drawn from."""
    from sklearn.cluster import KMeans

    from fricid.identify.learned import _rbf_estimator as est

    before = est._LLOYD_RANDOM_STATE.get_state()
    for Z, m in list(_kmeans_problems(False))[:6]:
        seeds = Z[est._kmeans_plusplus(Z - Z.mean(axis=0), m, 5)]
        expected = KMeans(m, init=seeds, n_init=1, random_state=5).fit(Z).cluster_centers_
        np.testing.assert_array_equal(est.kmeans_centres(Z, m, 5), expected)
    after = est._LLOYD_RANDOM_STATE.get_state()
    assert after[0] == before[0] and np.array_equal(after[1], before[1])
    assert after[2:] == before[2:]
