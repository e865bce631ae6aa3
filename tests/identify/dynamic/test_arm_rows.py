"""Each joint's reversal window from how far its sticks' misfit reaches (arm._rows)."""

from __future__ import annotations

import numpy as np
import scipy.stats

from fricid.identify.dynamic.arm._rows import (
    BIN_PERIODS,
    EXCESS,
    FAR_PERIODS,
    WINDOW_STEPS,
    adapted_windows,
    band_score,
)


def _rows(seed: int = 0, n: int = 40_000):
    rng = np.random.default_rng(seed)
    distance = rng.uniform(0.0, 6.0, (n, 1))  # periods of the cut-off from the nearest stop
    return distance, rng.normal(0.0, 1.0, (n, 1))


def test_a_joint_whose_residual_is_noise_keeps_the_given_window():
    d, noise = _rows()
    assert adapted_windows(d, noise, 1.0)[0] == 1.0
    assert adapted_windows(d, noise, 1.5)[0] == 1.5  # never below the given one


def test_the_window_grows_to_where_the_misfit_has_died_out():
    """A misfit of 80 noise std at a stop, falling as a filtered step's error does (2 % one
    period away, 0.1 % at two): the window moves out to where the excess is small."""
    d, noise = _rows(1)
    leak = 80.0 * np.exp(-3.0 * d)  # 4.0 at 1 period, 0.2 at 2
    windows = adapted_windows(np.hstack([d, d]), np.hstack([noise, noise + leak]), 1.0)
    assert windows[0] == 1.0
    assert 1.0 < windows[1] <= WINDOW_STEPS[-1]
    seen = noise[:, 0] + leak[:, 0]
    for lo in np.arange(windows[1], FAR_PERIODS, BIN_PERIODS):  # left in: near the noise
        rows = (d[:, 0] >= lo) & (d[:, 0] < lo + BIN_PERIODS)
        assert np.sqrt(np.mean(seen[rows] ** 2)) <= 1.0 + EXCESS
    # and the rows just inside it show the misfit
    below = WINDOW_STEPS[WINDOW_STEPS.index(windows[1]) - 1]
    inside = (d[:, 0] >= below) & (d[:, 0] < below + BIN_PERIODS)
    assert np.sqrt(np.mean(seen[inside] ** 2)) > 1.0 + EXCESS


def test_without_far_rows_the_window_given_is_kept():
    d, noise = _rows(2)
    short = d * (FAR_PERIODS - 0.1) / 6.0  # nothing as far as FAR_PERIODS
    assert adapted_windows(short, noise + 50.0 * np.exp(-3.0 * short), 1.0)[0] == 1.0


def _correlated(rng, kernel, size):
    """Noise with the autocorrelation ``kernel`` gives (a moving average of white noise)."""
    return np.convolve(rng.normal(0.0, 1.0, size + kernel.size - 1), kernel, mode="valid")


def test_the_band_score_is_chi_square_where_the_residual_is_correlated_noise():
    """Noise correlated as the filter correlates it: the statistic has the chi-square's mean
    and rejects at its level, while ignoring the correlation would reject far too often."""
    rng = np.random.default_rng(3)
    kernel = np.hanning(9)  # correlated over about four rows, as filtered rows are
    R = np.correlate(kernel, kernel, mode="full")[kernel.size - 1 :]
    rho = R / R[0]
    # a band's rows: runs of ten beside 30 stops
    t = (np.arange(30)[:, None] * 160 + rng.integers(0, 100, (30, 1)) + np.arange(10)).ravel()
    F = np.column_stack([np.sign(np.sin(t / 40.0)), t / 5_000.0])
    stats, naive = [], []
    for _ in range(400):
        r = _correlated(rng, kernel, 5_000)[t] / np.sqrt(R[0])
        stat, dof = band_score(F, r, t, rho, 1.0)
        stats.append(stat)
        naive.append(band_score(F, r, t, np.ones(1), 1.0)[0])
    assert dof == 2
    assert abs(np.mean(stats) - 2.0) < 0.35
    assert 0.02 < np.mean(np.array(stats) > scipy.stats.chi2.ppf(0.95, 2)) < 0.09
    assert np.mean(np.array(naive) > scipy.stats.chi2.ppf(0.95, 2)) > 0.3


def test_a_small_misfit_along_the_friction_columns_widens_the_window():
    """A stick's leak of 0.15 noise std along the direction of motion, too small for the RMS
    test (an excess of about 1 %), moves the window out; without the columns it does not."""
    rng = np.random.default_rng(4)
    n = 40_000
    d = rng.uniform(0.0, 6.0, n)
    direction = np.sign(rng.normal(size=n))
    F = np.column_stack([direction > 0, direction < 0]).astype(float)
    noise = rng.normal(0.0, 1.0, n)
    leak = 0.15 * (d < 1.5)
    rho = np.ones(1)  # uncorrelated rows
    along = adapted_windows(d[:, None], (noise + leak * direction)[:, None], 1.0, [F], rho)
    assert along[0] == 1.5
    assert adapted_windows(d[:, None], (noise + leak * direction)[:, None], 1.0)[0] == 1.0
