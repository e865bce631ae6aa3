"""A parameter outside the range the data can inform is not called determined: a Stribeck
velocity below the slowest measured speed, a Coulomb level the data never reach."""

from __future__ import annotations

import warnings

import numpy as np

from fricid.identify import fit
from fricid.identify.static.informed import uninformed
from fricid.samples import FrictionSamples


def samples(speeds: np.ndarray, w_s: float, seed: int = 0) -> FrictionSamples:
    v = np.r_[speeds, -speeds]
    y = np.sign(v) * (0.5 + 0.5 * np.exp(-np.abs(v) / w_s)) + 0.1 * v
    y = y + 0.005 * np.random.default_rng(seed).standard_normal(v.size)
    return FrictionSamples(
        velocity=v, load=np.zeros(v.size), temperature=np.full(v.size, 25.0), friction=y
    )


def test_rule_names_the_parameters_and_why():
    s = samples(np.geomspace(0.2, 5.0, 10), 0.05)
    theta = np.array([0.5, 1.0, 0.02, 0.1, 1.0])  # tau_c, tau_s, w_s, tau_v, delta
    notes = uninformed("stribeck", theta, s)
    assert set(notes) == {"tau_s", "w_s"}
    assert "below the slowest measured speed 0.2 rad/s" in notes["w_s"]
    notes = uninformed("stribeck", np.array([0.5, 1.0, 10.0, 0.1, 1.0]), s)
    assert set(notes) == {"tau_c"} and "extrapolation beyond the data" in notes["tau_c"]
    assert not uninformed("stribeck", np.array([0.5, 1.0, 0.5, 0.1, 1.0]), s)
    assert not uninformed("coulomb_viscous", np.array([0.5, 0.1]), s)
    asym = np.array([0.5, 1.0, 0.02, 0.1, 1.0, 0.5, 1.0, 0.5, 0.1, 1.0])
    assert set(uninformed("stribeck_asym", asym, s)) == {"tau_s_pos", "w_s_pos"}


def test_fit_does_not_call_an_unreached_coulomb_level_determined():
    # speeds up to 0.2 rad/s, Stribeck velocity 1 rad/s: the curve never reaches tau_c
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = fit(samples(np.geomspace(0.01, 0.2, 10), 1.0), "stribeck", fixed={"delta": 1.0})
    p = m.parameters["tau_c"]
    assert p.not_determined and "Coulomb level is an extrapolation" in p.note
    assert "tau_c" in m.report().split("[[Variables]]")[1].splitlines()[1]
    assert "[not determined]" in m.report().split("[[Variables]]")[1].splitlines()[1]
