"""A constant-velocity campaign read through a coarse encoder whose velocity column is the
position's finite difference: the set-points are the commanded speeds and their friction,
not the speeds of whole counts per sample.

The generator is this file's own: runs at closely and widely spaced speeds in both
directions with acceleration ramps and rests, integrated exactly (piecewise-constant
acceleration), a friction law written here (not fricid's models), torque noise, the position
rounded to ``counts`` per turn and the velocity its backward difference, as a drive without a
velocity estimate logs it. Read that way a run at 0.6 rad/s through 2^12 counts at 250 Hz
takes 1 or 2 counts per sample (0.38 or 0.77 rad/s) and extraction had kept 0.77 rad/s with
the friction of 0.6: a velocity 28 % off, with a warning only.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from fricid.errors import DataQualityWarning
from fricid.extract import extract
from fricid.samples import RawLog

SPEEDS = (0.02, 0.05, 0.055, 0.15, 0.6, 1.8)


def friction(v: np.ndarray) -> np.ndarray:
    """Coulomb 0.3, a Stribeck rise of 0.25 below 0.04 rad/s, viscous 0.08 N m s/rad."""
    return np.sign(v) * (0.3 + 0.25 * np.exp(-((np.abs(v) / 0.04) ** 2))) + 0.08 * v


def campaign(counts: int, rate: float, seed: int) -> tuple[RawLog, np.ndarray]:
    """Each speed up then down: 0.3 s ramp, 4 s run, 0.3 s ramp, 1 s rest."""
    rng = np.random.default_rng(seed)
    dt = 1.0 / rate
    profile = [np.zeros(round(rate))]
    for s in SPEEDS:
        for sign in (1.0, -1.0):
            ramp = np.linspace(0.0, sign * s, round(0.3 * rate))
            profile += [ramp, np.full(round(4.0 * rate), sign * s), ramp[::-1]]
            profile.append(np.zeros(round(rate)))
    v = np.concatenate(profile)
    q = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * dt)])  # exact for ramps
    step = 2 * np.pi / counts
    q_enc = np.round(q / step) * step
    v_log = np.concatenate([[0.0], np.diff(q_enc) / dt])
    a = np.gradient(v, dt)
    torque = 0.02 * a + friction(v) + rng.normal(0.0, 0.01, v.size)
    t = np.arange(v.size) * dt
    log = RawLog(
        time=t, position=q_enc, velocity=v_log, temperature=25.0, torque=torque, source="enc.csv"
    )
    return log, v


@pytest.mark.parametrize(("counts", "rate", "seed"), [(2**12, 250.0, 1), (2**10, 1000.0, 2)])
def test_set_points_through_a_coarse_encoder_are_the_commanded_speeds(counts, rate, seed):
    """Every set-point kept is a commanded speed (to 1 %: 0.6 % for 0.055 rad/s through 2^10
    counts, near what its counts resolve) with its friction (to 5 mN m,
    the noise 10 mN m); every run that moves 20 counts in half its length is kept (0.05 and
    0.055 rad/s apart); the slower ones, whose counts cannot show a plateau, are dropped as
    such, not kept at a wrong speed."""
    log, _ = campaign(counts, rate, seed)
    with pytest.warns(DataQualityWarning, match="position's least-squares slope over windows"):
        result = extract(log, gravity="none")
    s = result.by_direction
    truth = np.array([x * d for x in SPEEDS for d in (1.0, -1.0)])
    nearest = truth[np.abs(s.velocity[:, None] - truth[None, :]).argmin(axis=1)]
    assert np.all(np.abs(s.velocity - nearest) < 0.01 * np.abs(nearest)), s.velocity
    assert len(set(nearest)) == len(nearest)  # no speed twice
    assert np.all(np.abs(s.friction - friction(nearest)) < 0.005), s.friction
    step = 2 * np.pi / counts
    resolvable = {x * d for x in SPEEDS if x * 2.0 >= 20 * step for d in (1.0, -1.0)}
    assert resolvable <= set(nearest)
    if len(nearest) < truth.size:
        assert any("dropped as transient" in note for note in result.quality.note)


def test_a_fine_encoders_velocity_is_used_as_logged():
    """A 2^20-count encoder's difference resolves every speed: nothing is replaced."""
    log, _ = campaign(2**20, 250.0, 3)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = extract(log, gravity="none")
    assert not any("coarse encoder" in str(w.message) for w in caught)
    assert len(result.samples.velocity) == len(SPEEDS)
