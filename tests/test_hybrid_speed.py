"""The hybrid's fast training paths (issue 15's training-time goal) give what the slow ones
gave: the lean backbone selection chooses the family the full fits choose, and the residual
network's batched cross-validation solves the systems the per-system path solves."""

from __future__ import annotations

import numpy as np
import pytest

from fricid.identify._rbf_select import _CrossValidation
from fricid.identify.hybrid import fit_backbone
from fricid.sim.heldout_laws import draw


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


@pytest.mark.parametrize(
    ("n", "d", "m", "dup"), [(60, 1, 5, False), (300, 3, 40, True), (500, 2, 120, False)]
)
def test_kmeans_centres_are_scikit_learns_bit_for_bit(n, d, m, dup):
    import warnings

    from sklearn.cluster import KMeans

    from fricid.identify._rbf_estimator import kmeans_centres

    rng = np.random.default_rng(n)
    Z = rng.normal(size=(n, d)) * rng.uniform(0.1, 10, size=d)
    if dup:
        Z = np.round(Z)  # duplicate points
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        expected = KMeans(n_clusters=m, n_init=1, random_state=12345).fit(Z).cluster_centers_
    np.testing.assert_array_equal(kmeans_centres(Z, m, 12345), expected)
