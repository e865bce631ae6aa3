"""The measurement scatter against the virtual joint's oracle, and the interior folds of lovo
(issue 11, done-when: held-out RMSE within 1.2x the scatter on the virtual joint).

The scatter that the held-out RMSE is compared with is the standard error of each
per-direction sample MEAN, from the scatter of its repeated passes
(``ExtractionResult.direction_sem``), pooled over set-points as a root mean square. The
oracle's :func:`fricid.sim.expected_noise_std` is the true standard deviation of those means.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from fricid.extract import extract
from fricid.identify import measurement_scatter, validate
from fricid.identify.validate import interior_rmse
from fricid.samples import FrictionSamples
from fricid.sim import expected_noise_std, preset, simulate, true_samples

#: One seed's scatter (12 samples of 3 passes: 24 degrees of freedom, a relative standard
#: deviation of about 15 %) lies within this factor of the oracle's noise: about 2.8 sigmas.
FACTOR_ONE_SEED = 1.5

#: Pooled over :data:`SEEDS` (120 degrees of freedom, about 6.5 %): within this factor.
FACTOR_POOLED = 1.15

SEEDS = range(5)


def _virtual(name: str, seed: int):
    scenario = preset(name, "quick")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the faults' data-quality warnings
        result = extract(simulate(scenario, seed=seed), **scenario.extract_options())
    noise = expected_noise_std(scenario, by_direction=True)
    truth = true_samples(scenario, by_direction=True)
    return result, noise, truth


@pytest.mark.parametrize("name", ["paper2", "paper2+faults"])
def test_scatter_of_the_passes_matches_the_oracle_noise(name):
    est2, oracle2, actual2 = [], [], []
    for seed in SEEDS:
        result, noise, truth = _virtual(name, seed)
        samples = result.by_direction
        sc = measurement_scatter(samples, sem=result.direction_sem)
        assert sc.method == "given"
        oracle = float(np.sqrt(np.mean(noise**2)))
        assert 1 / FACTOR_ONE_SEED < sc.value / oracle < FACTOR_ONE_SEED, (seed, sc.value)
        est2.append(sc.value**2)
        oracle2.append(oracle**2)
        actual2.append(np.mean((samples.y - truth.y) ** 2))
    pooled = np.sqrt(np.mean(est2) / np.mean(oracle2))
    assert 1 / FACTOR_POOLED < pooled < FACTOR_POOLED
    # the oracle is the noise the extracted means actually carry (not biased low or high)
    assert 1 / FACTOR_POOLED < np.sqrt(np.mean(actual2) / np.mean(oracle2)) < FACTOR_POOLED


def test_interior_rmse_leaves_out_the_slowest_and_fastest_folds():
    folds = [
        {"fold": 2, "speed": 2.0, "n": 2, "rmse": 9.0, "note": ""},
        {"fold": 0, "speed": 0.01, "n": 2, "rmse": 7.0, "note": ""},
        {"fold": 1, "speed": 0.1, "n": 2, "rmse": 3.0, "note": ""},
        {"fold": 3, "speed": 0.5, "n": 4, "rmse": 0.0, "note": ""},
        {"fold": 4, "speed": 1.0, "n": 2, "rmse": None, "note": "not fitted"},
    ]
    assert interior_rmse(folds) == pytest.approx(np.sqrt(2 * 9.0 / 6))
    assert np.isnan(interior_rmse(folds[:2]))
    assert np.isnan(interior_rmse([*folds[:2], folds[4]]))


def test_validation_interior_rmse_from_its_predictions():
    rng = np.random.default_rng(3)
    speed = np.geomspace(0.01, 2.0, 7)
    v = np.r_[-speed, speed]
    y = np.sign(v) * (0.1 + 0.05 * np.abs(v)) + rng.normal(0, 0.002, v.size)
    samples = FrictionSamples(
        velocity=v,
        load=np.zeros_like(v),
        temperature=np.full_like(v, 25.0),
        friction=y,
        direction=np.sign(v),
    )
    val = validate(samples, "coulomb_viscous")
    inner = (np.abs(v) > speed[0] * 1.01) & (np.abs(v) < speed[-1] * 0.99)
    expected = np.sqrt(np.mean((y[inner] - val.predictions[inner]) ** 2))
    assert val.interior_rmse == pytest.approx(expected)
    assert np.isnan(validate(samples, "coulomb_viscous", "kfold:3").interior_rmse)
