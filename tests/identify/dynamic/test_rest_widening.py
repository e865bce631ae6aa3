"""LuGre's calibrated widening chooses its factors by how much the log rests
(:func:`fricid.identify.dynamic._data.rest_share`,
:func:`fricid.identify.dynamic._outcome.widen_calibrated`): on the independent simulator's
tuning logs the resting ones (trapezoids with dwells, most torque steps) needed wider intervals
than the pooled factors gave, and the report's trapezoids missed sigma_0 and sigma_1 more
often than 10 %."""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
from tests._paths import REPO

from fricid.identify.dynamic._data import rest_share, uniform_series
from fricid.identify.dynamic._outcome import (
    CALIBRATED_WIDENING,
    RESTING,
    RESTING_WIDENING,
    widen_calibrated,
)
from fricid.identify.dynamic._routes import _Stage
from fricid.io import read_rawlog
from fricid.samples import RawLog

sys.path.insert(0, str(REPO / "benchmarks"))
import _lugre_truth as lt


def _share(kind: str, seed: int, rate: float = 1000.0) -> float:
    truth = lt.ALL_TRUTHS["geared"]
    log = lt.simulate(truth, kind, 4.0, rate, 2**17, seed)
    with tempfile.TemporaryDirectory() as tmp:
        raw = read_rawlog(lt.write_log(log, Path(tmp) / "a.csv", truth, {}))
    return rest_share(uniform_series(raw))


@pytest.mark.parametrize("rate", [1000.0, 200.0])
def test_a_trapezoid_rests_and_a_chirp_does_not(rate):
    """Another simulator's logs, as the fit reads them: a PD-tracked trapezoid dwells 0.2-0.6 s
    at each target, a chirp only turns."""
    assert _share("trapezoid_pd", 7, rate) >= RESTING + 0.1
    assert _share("chirp_pd", 7, rate) <= RESTING - 0.1


def _series(position: np.ndarray, rate: float = 1000.0):
    t = np.arange(position.size) / rate
    zero = np.zeros_like(t)
    v = np.gradient(position, t) if t.size > 1 else zero
    log = RawLog(time=t, position=position, velocity=v, torque=zero, temperature=zero + 25.0)
    return uniform_series(log)


def test_the_rest_share_counts_only_stretches_long_enough():
    t = np.arange(4000) / 1000.0
    moving = 0.5 * t  # 0.5 rad/s throughout
    assert rest_share(_series(moving)) == 0.0
    held = np.where(t < 1.0, 0.0, 0.5 * (t - 1.0))  # a second at rest, then moving
    assert rest_share(_series(held)) == pytest.approx(0.25, abs=0.01)
    # rests of 50 ms between moves are reversals, not dwells
    blips = np.cumsum(np.where((t % 0.2) < 0.05, 0.0, 0.5)) / 1000.0
    assert rest_share(_series(blips)) == 0.0
    assert rest_share(_series(np.zeros(16), rate=100.0)) == 1.0  # 0.16 s held
    assert rest_share(_series(np.zeros(16), rate=1000.0)) == 0.0  # 16 ms: no rest of 0.1 s


def _stage():
    names = ["sigma_0", "sigma_2", "inertia"]
    v = np.array([2e4, 0.4, 0.05])
    lo, hi = v * 0.9, v * 1.1
    box = np.array([[1e2, 1e7], [0.0, 2.0], [0.01, 0.25]])
    return _Stage(names, v, v * 0.05, lo, hi, np.eye(3), None, 0.0, 20, {}, box)


def test_a_resting_log_takes_the_wider_factors_and_says_so():
    for rest, table in ((0.05, CALIBRATED_WIDENING), (0.4, RESTING_WIDENING)):
        stage = _stage()
        record = widen_calibrated(stage, rest)
        assert record["factors"] == table and record["resting"] == (rest >= RESTING)
        k = table["sigma_2"]
        assert stage.low[1] == pytest.approx(0.4 - k * 0.04) and stage.stderr[1] == pytest.approx(
            k * 0.02
        )
        k = table["sigma_0"]  # on a log scale
        assert math.log10(2e4 / stage.low[0]) == pytest.approx(k * math.log10(1 / 0.9))
    assert "the log rests 40 % of its time" in record["how"]
    for name, k in CALIBRATED_WIDENING.items():  # never narrower than the pooled factors
        assert RESTING_WIDENING[name] >= k
