"""A robust fit's verdict: the down-weighted samples named, the fit judged on the inliers."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from fricid.identify import fit
from fricid.identify._diagnostics import downweighted
from fricid.identify.trust import assess_trust
from fricid.samples import FrictionSamples

NOISE = 0.02
TRIPLED = [3, 14]


@pytest.fixture(scope="module")
def spiked():
    rng = np.random.default_rng(0)
    speed = np.geomspace(0.05, 2.0, 10)
    v = np.r_[-speed, speed]
    f = 0.8 + 0.5 * np.exp(-np.abs(v) / 0.3) + 0.4 * np.abs(v)
    y = np.sign(v) * f + rng.normal(0.0, NOISE, v.size)
    y[TRIPLED] *= 3.0  # two gross outliers
    std = NOISE * np.sqrt(10)
    return FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=y, std=std, count=10)


@pytest.fixture(scope="module")
def robust(spiked):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(spiked, "stribeck", loss="soft_l1", weights="std", fixed={"delta": 1.0})


def test_the_down_weighted_samples_are_found_by_row_velocity_and_load(robust, spiked):
    low, names = downweighted(robust, spiked)
    assert np.flatnonzero(low).tolist() == TRIPLED
    for i in TRIPLED:
        head = f"sample {i + 1}: v = {spiked.velocity[i]:+.4g} rad/s, load 0 N m"
        assert sum(name.startswith(head) for name in names) == 1
    assert downweighted(fit(spiked, "coulomb_viscous"), spiked) == (None, [])  # least squares


def test_a_robust_fit_is_judged_on_its_inliers_and_names_its_outliers(robust, spiked):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        trust = assess_trust(robust, spiked)
    text = trust.line()
    assert "cannot follow" not in text and "learned model" not in text
    assert trust.level != "no" and trust.heldout_ratio < 1.5
    assert "soft_l1 loss down-weighted 2 sample(s)" in text
    for i in TRIPLED:
        assert f"sample {i + 1}: v = {spiked.velocity[i]:+.4g} rad/s" in text
    assert trust.validation_note.startswith("judged on the 18 inliers")
    assert len(trust.downweighted) == 2
