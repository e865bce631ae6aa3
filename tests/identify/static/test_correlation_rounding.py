"""The correlations a fit records are the parameters', not the arithmetic's.

A new user's trial on the real lead-screw log (``fricid report`` of a ``stribeck_asym`` fit):
the forwards and backwards parameters, which share no sample, were written as correlated by
-2.79e-16, and the diagonal as 0.9999999999999998.
"""

from __future__ import annotations

import numpy as np

from fricid.identify import fit
from fricid.samples import FrictionSamples


def test_independent_directions_are_uncorrelated_and_the_diagonal_is_one():
    rng = np.random.default_rng(4)
    v = np.concatenate([np.geomspace(0.02, 2, 12), -np.geomspace(0.02, 2, 12)])
    f = np.where(v > 0, 0.1, -0.08) + 0.03 * v + 0.001 * rng.standard_normal(v.size)
    s = FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=f, source="s")
    fitted = fit(s, "coulomb_viscous_asym")
    corr = np.asarray(fitted.correlation, dtype=float)
    names = list(fitted.free)
    pos = [i for i, n in enumerate(names) if n.endswith("_pos")]
    neg = [i for i, n in enumerate(names) if n.endswith("_neg")]
    assert pos and neg
    assert (corr[np.ix_(pos, neg)] == 0).all(), corr[np.ix_(pos, neg)]
    assert (np.diag(corr) == 1).all(), np.diag(corr)
    assert abs(corr[pos[0], pos[1]]) > 0.1  # a real correlation stays
