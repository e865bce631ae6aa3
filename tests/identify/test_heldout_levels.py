"""The verdict's held-out error on few velocity levels and on tiny data: leave-one-velocity-out
graded on its interior folds, random folds beside it on tiny data (the worse graded)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from fricid.identify import fit
from fricid.identify._heldout import LOVO_INTERIOR, graded_rmse
from fricid.identify.trust import KFOLD_HERE, RUN_HERE, assess_trust
from fricid.identify.validate import interior_rmse
from fricid.samples import FrictionSamples

NOISE = 0.05


def _stribeck(seed: int, speeds: np.ndarray, reps: int = 1, **kw) -> FrictionSamples:
    rng = np.random.default_rng(seed)
    s = np.repeat(speeds, reps) * (1.0 + rng.uniform(-0.002, 0.002, speeds.size * reps))
    v = np.r_[-s, s]
    f = 0.8 + 0.5 * np.exp(-((np.abs(v) / 0.3) ** 2)) + 0.4 * np.abs(v)
    y = np.sign(v) * f + rng.normal(0.0, NOISE, v.size)
    return FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=y, **kw)


def test_graded_rmse_leaves_out_the_end_folds_of_lovo_only():
    folds = [
        {"fold": 0, "speed": 0.05, "n": 2, "rmse": 0.4, "note": ""},
        {"fold": 1, "speed": 0.1, "n": 2, "rmse": 0.05, "note": ""},
        {"fold": 2, "speed": 0.5, "n": 2, "rmse": 0.07, "note": ""},
        {"fold": 3, "speed": 2.0, "n": 2, "rmse": 0.9, "note": ""},
    ]
    lovo = {"scheme": "lovo", "rmse": 0.5, "folds": folds}
    assert graded_rmse(lovo) == (pytest.approx(np.sqrt((0.05**2 + 0.07**2) / 2)), LOVO_INTERIOR)
    assert graded_rmse({**lovo, "folds": folds[:2]}) == (0.5, "lovo")  # no interior fold
    assert graded_rmse({"scheme": "kfold:5", "rmse": 0.3, "folds": folds}) == (0.3, "kfold:5")


@pytest.mark.slow  # 2.5 s measured under load: each fold refitted
def test_six_levels_graded_on_the_interior_folds():
    s = _stribeck(1, np.geomspace(0.05, 2.0, 6), reps=3)  # 36 samples, repeats: a true scatter
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(s, "stribeck", fixed={"delta": 2.0})  # the true family
        trust = assess_trust(fitted, s)
    assert (trust.heldout_source, trust.heldout_scheme) == (RUN_HERE, LOVO_INTERIOR)
    assert "random folds" not in trust.validation_note  # 36 samples: not tiny
    inner = interior_rmse(trust.validation["folds"]) / trust.scatter
    assert trust.heldout_ratio == pytest.approx(inner)
    assert trust.heldout_ratio < trust.validation["ratio"]  # the end folds extrapolate
    assert trust.level != "no"


@pytest.mark.slow  # about 10 s: the hybrid is retrained for every fold
def test_a_hybrid_on_six_levels_is_not_failed_by_extrapolating_end_folds():
    rng = np.random.default_rng(0)
    speed = np.linspace(0.2, 2.0, 6)
    v = np.r_[-speed, speed]
    y = np.sign(v) * (1.0 + 2.0 * np.abs(v)) + rng.normal(0.0, NOISE, v.size)
    s = FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=y, std=NOISE, count=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        trust = assess_trust(fit(s, "hybrid"), s)  # a neighbour-to-neighbour lovo: "no", 6.9x
    assert trust.level != "no" and trust.heldout_ratio < 1.5


@pytest.mark.slow  # 3.7 s measured under load: the GP retrained per fold
def test_tiny_data_grade_the_worse_of_lovo_and_random_folds():
    s = _stribeck(0, np.geomspace(0.05, 2.0, 6), std=NOISE, count=1)  # 12 samples
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        trust = assess_trust(fit(s, "gp"), s)
    assert trust.heldout_source == KFOLD_HERE and trust.heldout_scheme == "kfold:5"
    assert "worse than lovo" in trust.validation_note
    assert trust.heldout_ratio == pytest.approx(trust.validation["ratio"])
    assert trust.level != "yes"
