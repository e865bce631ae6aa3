"""The analytic models' prediction intervals are calibrated on the fit's own leave-one-out
residuals (:func:`fricid.identify._intervals.jackknife_scale`): a bounded spread (a run's
gravity offset) is not covered as if it had Gaussian tails, gross outliers do not widen
every prediction, and with Gaussian residuals the multiplier is about the normal one."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy import stats

from fricid.identify import fit
from fricid.identify._intervals import jackknife_scale
from fricid.samples import FrictionSamples


def _linear(v: np.ndarray) -> np.ndarray:
    return np.sign(v) * 0.8 + 0.3 * v


def _samples(
    law, seed: int, sigma: float, n_speeds: int = 20, outliers: int = 0, offset: float = 0.0
):
    """``n_speeds`` speeds per direction; ``outliers`` samples 15 sigma off; each sample
    with an offset ``offset sin(phi)``, ``phi`` uniform in (-pi/2, pi/2) (gravity at a
    run's mean position left in)."""
    rng = np.random.default_rng(seed)
    speeds = np.geomspace(0.01, 3.0, n_speeds)
    v = np.r_[speeds, -speeds]
    y = law(v) + sigma * rng.standard_normal(v.size)
    y += offset * np.sin(rng.uniform(-np.pi / 2, np.pi / 2, v.size))
    if outliers:
        bad = rng.choice(v.size, size=outliers, replace=False)
        y[bad] += np.sign(y[bad]) * 15 * sigma
    return FrictionSamples(
        velocity=v, load=np.zeros(v.size), temperature=np.full(v.size, 25.0), friction=y
    )


def _expected_coverage(model, law, sigma: float, offset: float = 0.0) -> float:
    """Expected share of fresh samples ``law + offset sin(phi) + sigma z`` inside the 95 %
    interval, on a log-uniform grid over the measured speeds (exact in ``z``, the midpoint
    rule in ``phi``)."""
    s = np.geomspace(0.01, 3.0, 300)
    v = np.r_[s, -s]
    X = np.column_stack([v, np.zeros(v.size), np.full(v.size, 25.0)])
    pi = model.predict_interval(X, 0.95, warn=False)
    phi = -np.pi / 2 + np.pi * (np.arange(200) + 0.5) / 200
    F = law(v)[None, :] + offset * np.sin(phi)[:, None]
    cov = stats.norm.cdf((pi.high - F) / sigma) - stats.norm.cdf((pi.low - F) / sigma)
    return float(np.mean(cov))


def _fit(samples, model="coulomb_viscous"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(samples, model, intervals="none")


def test_a_bounded_spread_is_not_covered_as_if_it_had_gaussian_tails():
    # an offset a sin(phi) per sample, 10x the noise: its std is a / sqrt(2) and t s reaches
    # 1.4 a, past every offset there is (coverage 99.5 % with t); the jackknife quantile
    # stops at about the 95 % point of the spread (94.5 %)
    cov = [
        _expected_coverage(_fit(_samples(_linear, k, 0.01, offset=0.1)), _linear, 0.01, 0.1)
        for k in range(4)
    ]
    assert 0.90 <= np.mean(cov) <= 0.98, cov


def test_gross_outliers_do_not_widen_every_interval():
    # two samples 15 sigma off inflate the residual variance, and every interval with it
    # (coverage 100 % with t); the jackknife leaves them out of its scores (94.8 %)
    cov, gross = [], []
    for k in range(4):
        m = _fit(_samples(_linear, k, 0.02, outliers=2))
        cov.append(_expected_coverage(m, _linear, 0.02))
        gross.append(m.prediction_interval["scale"]["gross"])
    assert 0.90 <= np.mean(cov) <= 0.98, cov
    assert gross == [2, 2, 2, 2]


def test_the_family_that_holds_keeps_about_the_normal_multiplier():
    cov, k95 = [], []
    for k in range(4):
        m = _fit(_samples(_linear, k, 0.02))
        cov.append(_expected_coverage(m, _linear, 0.02))
        k95.append(m.prediction_interval["scale"]["scale"][1])
    assert 0.90 <= np.mean(cov) <= 0.98, cov
    assert 1.6 <= np.mean(k95) <= 2.4, k95


def test_jackknife_scale_quantile_and_its_fall_back():
    rng = np.random.default_rng(1)
    r = rng.standard_normal(2000)
    got = jackknife_scale(r, np.zeros(r.size), 1.0, 1998)
    assert got["scale"] == pytest.approx([1.645, 1.96], abs=0.1)
    assert got["gross"] == 0
    few = jackknife_scale(r[:12], np.zeros(12), 1.0, 9)  # 12 scores: no rank at 95 %
    assert few["scale"][1] == pytest.approx(stats.t.ppf(0.975, 9))
    assert few["scale"][0] == pytest.approx(np.quantile(np.abs(r[:12]), 0.9, method="weibull"))
    assert jackknife_scale(r[:12], np.zeros(12), 0.0, 9) is None


def test_the_noise_term_is_never_below_the_measured_scatter():
    # six speeds per direction whose residuals come out at a fraction of the scatter the
    # samples state (std / sqrt(count)): a new sample still scatters by that much
    rng = np.random.default_rng(3)
    speeds = np.geomspace(0.05, 2.0, 6)
    v = np.r_[speeds, -speeds]
    y = _linear(v) + 0.005 * rng.standard_normal(v.size)
    given = 0.03
    s = FrictionSamples(
        velocity=v,
        load=np.zeros(v.size),
        temperature=np.full(v.size, 25.0),
        friction=y,
        count=np.full(v.size, 25),
        std=np.full(v.size, given * 5.0),
    )
    m = _fit(s)
    rec = m.prediction_interval
    assert rec["noise_std"] < given / 2
    assert rec["noise_floor"] == pytest.approx(given)
    X = np.array([[0.3, 0.0, 25.0], [-1.0, 0.0, 25.0]])
    half = m.predict_interval(X, 0.95, warn=False).half_width
    # six scores per direction are too few for the rank: the multiplier of the known
    # noise is the normal quantile, not the Student-t one of 10 residual dof
    assert rec["scale"]["student_t"] == [False, True]  # 12 scores: a rank at 90 %, not 95 %
    assert np.all(half >= 1.959 * given)
    assert np.all(half < stats.t.ppf(0.975, rec["dof"]) * given)
