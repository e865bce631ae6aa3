"""``auto`` over every family that fits the data's inputs: the temperature variants too."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from fricid.identify import fit
from fricid.identify.static.candidates import candidates
from fricid.samples import FrictionSamples

NOISE = 0.02


def _law(v: np.ndarray, temp: np.ndarray) -> np.ndarray:
    """Asymmetric Stribeck friction (a Gaussian drop) with an Arrhenius viscous term."""
    arrhenius = np.exp(2500.0 * (1.0 / (temp + 273.15) - 1.0 / 313.15))
    s = np.abs(v)
    pos = 0.6 + 0.4 * np.exp(-((s / 0.15) ** 2)) + 0.5 * arrhenius * s
    neg = 0.45 + 0.3 * np.exp(-((s / 0.25) ** 2)) + 0.35 * arrhenius * s
    return np.where(v > 0, pos, -neg)


def _samples(speeds: int, temps: list[float], seed: int = 0) -> FrictionSamples:
    s = np.geomspace(0.05, 2.0, speeds)
    v, t = (a.ravel() for a in np.meshgrid(np.r_[-s, s], np.asarray(temps)))
    y = _law(v, t) + np.random.default_rng(seed).normal(0.0, NOISE, v.size)
    return FrictionSamples(velocity=v, load=0.0, temperature=t, friction=y, std=NOISE, count=1)


def test_temperature_variants_are_candidates_when_the_temperature_varies():
    names = [c.model for c in candidates(_samples(6, [10.0, 40.0, 70.0])) if not c.note]
    assert {"coulomb_viscous_temp", "stribeck_temp", "stribeck_temp_asym"} <= set(names)
    two = {c.model: c.note for c in candidates(_samples(6, [10.0, 70.0]))}
    assert "needs 3" in two["stribeck_temp_asym"]
    one = [c.model for c in candidates(_samples(6, [25.0]))]
    assert not any("_temp" in m for m in one)
    # per-direction levels still count against one direction's parameters
    assert not {c.model: c.note for c in candidates(_samples(8, [25.0]))}["stribeck_asym"]


@pytest.mark.slow  # 21 s of CPU: every candidate validated by leave-one-velocity-out
def test_auto_picks_the_temperature_family_of_an_arrhenius_law():
    s = _samples(6, [10.0, 30.0, 50.0, 70.0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(s, "auto")
    assert "_temp" in fitted.selection["chosen"]
    grid = np.linspace(0.05, 2.0, 200)
    v, t = (a.ravel() for a in np.meshgrid(np.r_[-grid, grid], np.linspace(10.0, 70.0, 7)))
    x = np.column_stack([v, np.zeros_like(v), t])
    err = np.sqrt(np.mean((fitted.predict(x, warn=False) - _law(v, t)) ** 2) + NOISE**2)
    assert err / NOISE < 1.3  # measured 1.09 (15.5 when the temperature variants were left out)


def test_on_tiny_data_only_a_significant_gain_beats_the_simpler_family():
    from fricid.identify.static.select import _better

    rng = np.random.default_rng(0)
    y = rng.normal(0.0, 1.0, 12)
    best = y + rng.normal(0.0, 0.05, 12)
    assert not _better(best, y + rng.normal(0.0, 0.06, 12), y)  # noise apart
    assert _better(best, y + 0.5, y)  # every sample worse by far


def test_a_family_with_more_parameters_than_samples_is_noted_not_fitted():
    """Nine samples whose load differs at every one (an arm's gravity torque): the operating
    points are nine, enough for one direction of the load-dependent family, but its
    per-direction variant has 14 parameters; it is listed with the reason, and 'auto' fits
    the rest instead of failing on it."""
    speed = np.array([0.2, 0.35, 0.5, 0.75, 1.0])
    v = np.r_[speed, -speed[:4]]
    load = np.linspace(-0.05, 0.09, v.size)
    y = np.sign(v) * (0.08 + 0.02 * np.abs(v)) + 0.001 * np.cos(7 * v)
    s = FrictionSamples(v, load, 25.0, y, count=np.full(v.size, 100), std=np.full(v.size, 0.01))
    by = {c.model: c for c in candidates(s)}
    assert by["msk_asym"].note == "9 samples for 14 parameters"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chosen = fit(s, "auto")
    assert chosen.model != "msk_asym"
