"""The extraction reads durations, not clock readings: a log's time shifted (a recorder that
starts its clock elsewhere, a ROS bag's epoch seconds, the second of two joined recordings)
gives the same samples."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest

from _sweeps import sweep_log
from fricid.extract import extract


def _samples(log):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = extract(log, gravity="none")
    s = res.by_direction
    return s.velocity, s.friction, s.count


@pytest.mark.parametrize("rate", [100.0, 200.0, 1000.0])
def test_a_shifted_clock_gives_the_same_samples(rate):
    """Before: the settle time was cut where ``t >= t0 + settle_time`` in floating point, so
    a shift of the clock moved the cut by a sample on some runs, and the settle test's blocks
    with it (on a double pendulum's sweep at 200 Hz, a 31.3 s shift turned 40 kept samples of
    a run into 119, its friction -0.047 into -0.055 N m)."""
    log = sweep_log([0.2, 0.5, 1.0], rate=rate, seed=3)
    v0, f0, n0 = _samples(log)
    for shift in (31.3, 1234.567, 1.7e9):
        v, f, n = _samples(replace(log, time=log.time + shift))
        np.testing.assert_array_equal(n, n0, err_msg=f"shift {shift}")
        np.testing.assert_allclose(f, f0, rtol=0, atol=1e-9, err_msg=f"shift {shift}")
        np.testing.assert_allclose(v, v0, rtol=1e-9, err_msg=f"shift {shift}")
