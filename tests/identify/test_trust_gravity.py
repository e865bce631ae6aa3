"""Gravity left in the friction (eq. 7: ``p_x cos q - p_y sin q`` at the joint's position) is
named in the verdict, and the same design without it still gets "Trust: yes".

Samples: friction ``sign(v)(1 + 2|v|)`` at 12 speeds per direction, 3 runs each, every run a
mean of 50 raw samples with noise 0.02 N m (``std`` and ``count`` carried); with gravity, each
run at its own position ``q`` in +-1.2 rad, ``p = (0, 0.3)`` N m (gravity ``-0.3 sin q``, no
mean offset, so a law odd in the velocity follows the runs' average).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from fricid.extract import extract
from fricid.identify import fit
from fricid.identify._diagnostics import LEFT_IN, OWN_SEM, between_run_excess, gravity_caveat
from fricid.identify.trust import assess_trust
from fricid.samples import FrictionSamples

NOISE = 0.02
COUNT = 50


def _runs(seed: int, p=(0.0, 0.0), runs: int = 3) -> FrictionSamples:
    rng = np.random.default_rng(seed)
    speed = np.geomspace(0.05, 2.0, 12)
    v = np.repeat(np.r_[speed, -speed], runs) * (1 + rng.uniform(-0.003, 0.003, 24 * runs))
    q = rng.uniform(-1.2, 1.2, v.size)
    gravity = p[0] * np.cos(q) - p[1] * np.sin(q)
    y = np.sign(v) * (1 + 2 * np.abs(v)) - gravity + rng.normal(0.0, NOISE, v.size)
    std = NOISE * np.sqrt(COUNT)
    return FrictionSamples(
        velocity=v, load=None, temperature=None, friction=y, std=std, count=COUNT
    )


def _trust(samples: FrictionSamples):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return assess_trust(fit(samples, "coulomb_viscous"), samples)


def test_gravity_left_in_between_runs_is_a_caveat_not_yes():
    """The runs' positions differ, so their means differ by gravity (about 0.18 N m RMS,
    nine times the runs' standard error): the scatter between the runs holds it, and the
    model's error, within that scatter (1.14x), was "Trust: yes"."""
    got = _trust(_runs(1, p=(0.0, 0.3)))
    assert got.level == "with caveats"
    said = [r for r in got.reasons if r.startswith(LEFT_IN)]
    assert len(said) == 1 and "repeated runs at 24 operating point(s)" in said[0]
    assert "std/sqrt(count)" in said[0]


def test_the_same_design_without_gravity_is_trusted():
    got = _trust(_runs(1))
    assert got.level == "yes", got.line()
    assert not any(LEFT_IN in r for r in got.reasons)


def test_runs_differing_by_noise_alone_are_never_flagged():
    """Over 40 draws of clean runs the ratio stays near 1 and no caveat is made."""
    ratios = []
    for seed in range(40):
        samples = _runs(seed)
        excess = between_run_excess(samples)
        assert excess is not None and excess.dof == 48 and excess.points == 24
        ratios.append(excess.ratio)
        assert gravity_caveat(samples) == []
    assert 0.9 < np.median(ratios) < 1.1
    assert max(ratios) < 1.4


def test_offsets_beyond_the_raw_scatter_are_said_to_be_beyond_autocorrelation():
    """Run means that differ by more than the raw samples scatter (0.14 N m here) cannot come
    from autocorrelated noise: the caveat says so (gravity 0.06 N m RMS between runs is not
    beyond it, 0.6 N m is)."""
    small, large = _runs(2, p=(0.0, 0.1)), _runs(2, p=(0.0, 1.0))
    assert not between_run_excess(small).beyond_std
    assert between_run_excess(large).beyond_std
    assert "no autocorrelation explains" in gravity_caveat(large)[0]


def test_no_repeats_or_no_std_gives_no_excess():
    one = _runs(3, p=(0.0, 0.3), runs=1)
    assert between_run_excess(one) is None
    bare = _runs(3, p=(0.0, 0.3))
    bare = FrictionSamples(
        velocity=bare.velocity, load=None, temperature=None, friction=bare.friction
    )
    assert between_run_excess(bare) is None and gravity_caveat(bare) == []


@pytest.mark.parametrize(
    ("gravity", "position", "said"),
    [
        ("none", "channel", True),
        ("none", "integrated velocity", False),
        ("joint", "channel", False),
    ],
)
def test_extraction_provenance(gravity, position, said):
    """An extraction that left gravity in although the log has a position channel is a caveat;
    one without a position channel (nothing to remove it with) or that removed it is not."""
    base = _runs(4, runs=1)
    meta = {"extract": {"gravity": gravity, "position_source": position}}
    samples = FrictionSamples(
        velocity=base.velocity,
        load=None,
        temperature=None,
        friction=base.friction,
        std=base.std,
        count=base.count,
        meta=meta,
    )
    got = gravity_caveat(samples)
    assert bool(got) is said
    if said:
        assert got[0].startswith(f"{LEFT_IN}: the extraction did not remove it")


def test_extraction_with_gravity_none_records_the_position_channel():
    from _sweeps import sweep_log

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = extract(sweep_log([0.2, 0.4, 0.8]), gravity="none")
    assert res.samples.meta["extract"]["position_source"] == "channel"
    assert gravity_caveat(res.samples)[0].startswith(LEFT_IN)


def test_the_samples_own_standard_errors_are_used_where_given():
    """Raw samples so autocorrelated that std/sqrt(count) is 5x too small flag clean runs
    (the caveat says autocorrelation may be why); the standard errors the samples carry
    (``meta["sem"]``, autocorrelation-corrected, here the true 0.02 N m) do not."""
    clean = _runs(5)
    fooled = FrictionSamples(
        velocity=clean.velocity,
        load=None,
        temperature=None,
        friction=clean.friction,
        std=clean.std,
        count=clean.count * 25,
    )
    said = gravity_caveat(fooled)
    assert len(said) == 1 and "far more autocorrelated than std/sqrt(count)" in said[0]
    corrected = FrictionSamples(
        velocity=clean.velocity,
        load=None,
        temperature=None,
        friction=clean.friction,
        std=clean.std,
        count=clean.count * 25,
        meta={"sem": [NOISE] * len(clean), "sem_method": "within-run, autocorrelation-corrected"},
    )
    excess = between_run_excess(corrected)
    assert excess.within == OWN_SEM and 0.7 < excess.ratio < 1.4
    assert gravity_caveat(corrected) == []
