"""A stick's misfit left to each stop's columns (arm._sticks)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import scipy.ndimage
import scipy.signal

from fricid.identify.dynamic.arm._signals import _filt
from fricid.identify.dynamic.arm._sticks import (
    MERGE_PERIODS,
    project_out,
    stick_columns,
    stops,
)

RATE, CUTOFF, DECIMATION = 1000.0, 4.0, 50
EDGE = 25  # decimated rows dropped at each end (five periods of the cut-off)


def _sig(n: int) -> SimpleNamespace:
    """What stick_columns needs of the signals: the torque's filters, decimation, kept rows."""
    low = scipy.signal.butter(4, CUTOFF / (RATE / 2))
    anti = scipy.signal.butter(4, 60.0 / (RATE / 2))
    keep = slice(EDGE, len(range(0, n, DECIMATION)) - EDGE)

    def parallel(x):
        return _filt(anti, _filt(low, x))[::DECIMATION][keep]

    return SimpleNamespace(
        rate=RATE,
        cutoff=CUTOFF,
        low_pass=low,
        anti_alias=anti,
        parallel=parallel,
        rows=lambda: np.arange(len(range(0, n, DECIMATION)))[keep] * DECIMATION,
    )


def _sticks(rng, n: int, count: int = 30):
    """``count`` sticks of 10 to 60 ms, each holding its own torque (a level, a ramp and a
    bend the columns do not have): (near, misfit) at the log's rate."""
    near = np.zeros((n, 1), dtype=bool)
    misfit = np.zeros(n)
    for start in np.linspace(2_000, n - 2_000, count).astype(int) + rng.integers(-300, 300, count):
        length = int(rng.integers(10, 60))
        near[start : start + length, 0] = True
        s = np.linspace(-1.0, 1.0, length)
        misfit[start : start + length] = rng.normal(0, 1) + rng.normal(0, 1) * s + 0.3 * s**2
    return near, misfit


def test_runs_closer_than_the_gap_are_one_stop():
    near = np.zeros(100, dtype=bool)
    near[[3, 4, 5, 8, 9, 40, 41, 99]] = True
    assert stops(near, gap=4) == [(3, 10), (40, 42), (99, 100)]
    assert stops(near, gap=1) == [(3, 6), (8, 10), (40, 42), (99, 100)]
    assert stops(np.zeros(5, dtype=bool), gap=3) == []


def test_the_columns_are_the_stops_filtered_as_the_torque_is():
    """Summed from the impulse response, they are the indicator and the centred ramp of
    each stop through the torque's filters at the log's rate."""
    rng = np.random.default_rng(1)
    n = 30_000
    near, _ = _sticks(rng, n, count=12)
    near[5_000:5_002, 0] = True  # a reversal without a stick: two samples, no ramp
    sig = _sig(n)
    runs = stops(near[:, 0], round(MERGE_PERIODS * RATE / CUTOFF))
    X = np.zeros((n, 2 * len(runs)))
    for i, (a, b) in enumerate(runs):
        X[a:b, 2 * i] = 1.0
        X[a:b, 2 * i + 1] = np.linspace(-1.0, 1.0, b - a) if b - a > 2 else 0.0
    cols = stick_columns(sig, near)[0]
    direct = sig.parallel(X)
    assert cols.shape == direct.shape
    np.testing.assert_allclose(cols, direct, atol=1e-6 * np.abs(direct).max())


def test_what_a_joint_does_while_it_sticks_leaves_nothing_a_period_away():
    """A period of the cut-off or more from any stick, the filtered misfit is gone to within
    1 % once the stops' columns are projected out; the indicators alone (no ramps) leave
    about a fifth of it."""
    rng = np.random.default_rng(0)
    n = 60_000
    near, misfit = _sticks(rng, n)
    sig = _sig(n)
    leak = sig.parallel(misfit)
    distance = scipy.ndimage.distance_transform_edt(~near[:, 0])[sig.rows()] * CUTOFF / RATE
    far = distance >= 1.0
    cols = stick_columns(sig, near)[0]
    assert cols.shape == (leak.size, 2 * 30)
    left, lost = project_out(leak[far], cols[far])
    assert lost == 60
    rms = np.sqrt(np.mean(leak[far] ** 2))
    assert rms > 1e-3  # a leak to remove
    assert np.sqrt(np.mean(left**2)) < 0.01 * rms
    level_only, _ = project_out(leak[far], cols[far][:, ::2])
    assert np.sqrt(np.mean(level_only**2)) > 0.1 * rms
