"""The binomial gate that sizes the coverage tests (tests/_coverage.py)."""

from __future__ import annotations

from scipy.stats import binom

from _coverage import fewest_trials, gate


def test_the_gate_fails_a_calibrated_method_rarely_and_a_miscalibrated_one_mostly():
    n, k = fewest_trials()
    assert (n, k) == (69, 61)
    assert binom.cdf(k - 1, n, 0.95) <= 0.01 < binom.cdf(k, n, 0.95)  # the largest such mark
    assert binom.sf(k - 1, n, 0.80) <= 0.05
    assert binom.sf(gate(n - 1)[0] - 1, n - 1, 0.80) > 0.05  # one trial fewer is not enough
