"""Each joint's reversal window from how far its sticks' misfit reaches (arm._rows)."""

from __future__ import annotations

import numpy as np

from fricid.identify.dynamic.arm._rows import (
    BIN_PERIODS,
    EXCESS,
    FAR_PERIODS,
    WINDOW_STEPS,
    adapted_windows,
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
