"""The virtual joint: designs, physics, noise, reproducibility and the oracle."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import least_squares

from fricid.errors import ConfigError
from fricid.models import LoadDependent, Stribeck, VelocityLoadTemperature
from fricid.samples import RawLog
from fricid.sim import (
    PRESETS,
    SIZES,
    Design,
    LoadTemperatureLaw,
    ModelLaw,
    Noise,
    expected_noise_std,
    gravity_torque,
    operating_grid,
    preset,
    simulate,
    simulate_log,
    true_gravity,
    true_samples,
)

DEG = math.pi / 180.0


@pytest.fixture(scope="module")
def quick1():
    return preset("paper1", "quick")


# -- presets and designs ------------------------------------------------------------------------


def test_paper1_full_is_the_papers_design():
    d = preset("paper1", "full").design
    assert d.shape == (21, 15, 21)
    np.testing.assert_allclose(np.degrees(d.positions[[0, -1]]), [-60, -20])
    np.testing.assert_allclose(np.degrees(d.velocities[[0, 4, -1]]), [0.1, 2, 50])
    np.testing.assert_allclose(d.temperatures[[0, -1]], [5, 45])
    assert d.repetitions == 10 and d.sample_rate == 250
    assert 60e6 < d.n_samples() < 90e6  # tens of millions of raw samples
    assert true_gravity(preset("paper1")) == (0.2011, 0.06175)


def test_paper2_truth_is_table_2_stribeck():
    s = preset("paper2", "full")
    assert s.design.velocities.size == 17 and s.gravity == "none"
    truth = true_samples(s)
    expected = Stribeck().predict([0.084, 0.641, 0.066, 0.0026, 1.0], truth.X)
    np.testing.assert_allclose(truth.friction, expected, rtol=1e-12)
    np.testing.assert_array_equal(truth.load, 0.0)


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_sizes_shrink(name):
    n = [preset(name, size).design.n_samples() for size in SIZES]
    assert n[0] > n[1] > n[2]
    assert n[2] < 2e5  # quick stays sub-second


def test_unknown_preset_or_size():
    with pytest.raises(ConfigError, match="paper1"):
        preset("paper3")
    with pytest.raises(ConfigError, match="quick"):
        preset("paper1", "tiny")


def test_design_rejects_bad_values():
    base = dict(velocities=[0.1], temperatures=[20.0], positions=[0.0, 0.1], bin_halfwidth=0.05)
    Design(**base)
    with pytest.raises(ConfigError, match="overlap"):
        Design(**{**base, "bin_halfwidth": 0.06})
    with pytest.raises(ConfigError, match="positive"):
        Design(**{**base, "velocities": [-0.1]})
    with pytest.raises(ConfigError, match="repetitions"):
        Design(**{**base, "repetitions": 0})


# -- the motion ---------------------------------------------------------------------------------


@pytest.mark.parametrize("v_deg", [0.1, 6.0, 50.0])
def test_traverse_is_a_trapezoid_covering_the_range_at_constant_speed(v_deg):
    d = preset("paper1").design
    tr = d.traverse(v_deg * DEG)
    t = np.arange(tr.n_period) / d.sample_rate
    p = tr.profile(t)
    v = v_deg * DEG
    assert np.abs(p.velocity).max() == pytest.approx(v)
    assert np.abs(p.acceleration).max() == pytest.approx(d.acceleration)
    # position is the integral of velocity (trapezoid rule, one sample step)
    dp = np.diff(p.position)
    mean_v = 0.5 * (p.velocity[1:] + p.velocity[:-1]) / d.sample_rate
    assert np.abs(dp - mean_v).max() < d.acceleration / d.sample_rate**2
    # every position of the measured range, widened by the settle travel, is crossed at speed v
    low, high = d.measured_range
    margin = v * d.settle_time * 0.99
    inside = (p.position > low - margin) & (p.position < high + margin) & (p.velocity != 0)
    np.testing.assert_allclose(np.abs(p.velocity[inside]), v, rtol=1e-12)
    np.testing.assert_array_equal(p.acceleration[inside], 0.0)
    # a period starts at rest at the low end and ends (within a sample's travel) back there
    assert p.position[0] == tr.start
    assert abs(p.position[-1] - tr.start) <= v / d.sample_rate


# -- physics and measurement ---------------------------------------------------------------------


def test_noiseless_current_follows_eq_8_and_13(quick1):
    s = quick1.with_noise(Noise.none())
    log = next(simulate(s, seed=0, chunk="period"))
    j = s.joint
    T = s.design.temperatures[0]
    accel = np.gradient(log.velocity, log.time)
    steady = (log.velocity != 0) & (np.abs(accel) < 1e-9)
    load = gravity_torque(log.position, j.p_x, j.p_y)
    expected = (j.law(log.velocity, load, T) - load) / j.torque_constant  # eq. 8, 13
    np.testing.assert_allclose(log.current[steady], expected[steady], atol=1e-12)
    assert steady.sum() > 0.8 * np.count_nonzero(log.velocity)
    # while accelerating, J * acc is added (eq. 6)
    ramp = (log.velocity > 0) & (accel > 1.0)
    assert (
        log.current[ramp] - expected[ramp]
    ).min() > 0.5 * j.inertia * s.design.acceleration / j.torque_constant
    assert log.torque_constant == j.torque_constant and log.torque is None


def test_noise_levels_and_spikes(quick1):
    noisy = next(simulate(quick1, seed=3, chunk="setpoint"))
    clean = next(simulate(quick1.with_noise(Noise.none()), seed=3, chunk="setpoint"))
    n = len(noisy)
    diff = noisy.current - clean.current
    spikes = np.abs(diff) > 0.3
    rate = spikes.mean()
    assert 0.5 * quick1.noise.spike_rate < rate < 1.5 * quick1.noise.spike_rate
    # Gaussian part: the 10 mA sensor noise plus the per-pass friction offset (2 mN m / K = 4 mA)
    assert 0.009 < diff[~spikes].std() < 0.013
    # ADC quantisation: every current is a multiple of the 1 mA step
    steps = noisy.current / quick1.noise.current_lsb
    np.testing.assert_allclose(steps, np.round(steps), atol=1e-6)
    assert np.abs(noisy.temperature - quick1.design.temperatures[0]).max() < 0.5
    assert n == len(clean)


def test_per_pass_offset_is_shared_by_a_whole_traverse(quick1):
    only_pass = Noise(**{**vars(Noise.none()), "pass_offset_std": 0.01})
    s = quick1.with_noise(only_pass)
    log = next(simulate(s, seed=4, chunk="period"))
    clean = next(simulate(quick1.with_noise(Noise.none()), seed=4, chunk="period"))
    d = (log.current - clean.current) * s.joint.torque_constant
    fwd, back = d[log.velocity > 0], d[log.velocity < 0]
    assert np.ptp(fwd) < 1e-12 and np.ptp(back) < 1e-12
    assert abs(fwd[0]) > 0 and fwd[0] != -back[0]


# -- reproducibility ----------------------------------------------------------------------------


def _columns(log: RawLog):
    return (log.time, log.position, log.velocity, log.current, log.temperature)


def test_same_seed_identical_any_chunking(quick1):
    whole = simulate_log(quick1, seed=11)
    for chunk in ("period", "setpoint", "experiment"):
        parts = RawLog.concatenate(list(simulate(quick1, seed=11, chunk=chunk)))
        for a, b in zip(_columns(whole), _columns(parts), strict=True):
            np.testing.assert_array_equal(a, b)
    other = simulate_log(quick1, seed=12)
    assert not np.array_equal(whole.current, other.current)


def test_generator_seed_and_global_state(quick1):
    state = np.random.get_state()[1].copy()  # noqa: NPY002 (checking it is untouched)
    a = simulate_log(quick1, seed=np.random.default_rng(5))
    b = simulate_log(quick1, seed=np.random.default_rng(5))
    np.testing.assert_array_equal(a.current, b.current)
    np.testing.assert_array_equal(np.random.get_state()[1], state)  # noqa: NPY002
    with pytest.raises(ConfigError, match="seed"):
        simulate_log(quick1, seed=-1)
    with pytest.raises(ConfigError, match="chunk"):
        next(simulate(quick1, seed=1, chunk="row"))


def test_time_is_increasing_across_chunks(quick1):
    logs = list(simulate(quick1, seed=1, chunk="period"))
    ends = np.array([g.time[-1] for g in logs[:-1]])
    starts = np.array([g.time[0] for g in logs[1:]])
    assert (starts > ends).all()


# -- laws and oracle ----------------------------------------------------------------------------


@settings(max_examples=50, deadline=None)
@given(
    v=st.floats(1e-4, 2.0),
    load=st.floats(-0.5, 0.5),
    temp=st.floats(0.0, 50.0),
    dl=st.floats(0.01, 0.3),
    dt=st.floats(1.0, 20.0),
)
def test_load_temperature_law_shape(v, load, temp, dl, dt):
    law = LoadTemperatureLaw()
    f = float(law(v, load, temp))
    assert f > 0 and float(law(-v, load, temp)) == pytest.approx(-f)
    assert float(law(v, abs(load) + dl, temp)) > float(law(v, abs(load), temp))  # load raises it
    assert float(law(v, load, temp + dt)) < f  # warming lowers it
    assert float(law(0.0, load, temp)) == 0.0


def test_model_law_matches_model():
    law = ModelLaw(Stribeck(), [0.1, 0.3, 0.05, 0.01, 1.0])
    v = np.linspace(-1, 1, 7).reshape(7, 1)
    out = law(v, 0.0, 20.0)
    assert out.shape == (7, 1)
    X = np.column_stack([v.ravel(), np.zeros(7), np.full(7, 20.0)])
    np.testing.assert_allclose(out.ravel(), Stribeck().predict(law.theta, X))
    with pytest.raises(ConfigError):
        ModelLaw(Stribeck(), [0.1, 0.2])


def test_oracle_rows_and_noise(quick1):
    comb = true_samples(quick1)
    both = true_samples(quick1, by_direction=True)
    n = np.prod(quick1.design.shape)
    assert len(comb) == n and len(both) == 2 * n
    np.testing.assert_array_equal(both.direction, np.tile([-1, 1], n))
    np.testing.assert_allclose(both.friction[1::2], comb.friction)  # the law is odd
    _, _, pos = operating_grid(quick1)
    np.testing.assert_allclose(comb.load, gravity_torque(pos, 0.2011, 0.06175))
    np.testing.assert_array_equal(pos[:5], quick1.design.positions)
    keys = np.column_stack([comb.temperature, comb.velocity])
    assert (np.diff(keys[:, 0]) >= 0).all()
    sig = expected_noise_std(quick1)
    sig_d = expected_noise_std(quick1, by_direction=True)
    assert sig.shape == (n,) and sig_d.shape == (2 * n,)
    np.testing.assert_allclose(sig_d[::2] / np.sqrt(2), sig)
    assert (
        sig > quick1.noise.pass_offset_std / np.sqrt(2 * quick1.design.repetitions) - 1e-15
    ).all()
    # faster means fewer samples per bin, so more noise
    assert (
        sig[comb.velocity == comb.velocity.max()].min()
        > sig[comb.velocity == comb.velocity.min()].max()
    )


def _r2(model, X, y, starts):
    lb, ub = model.bounds(X, y).T
    best = min(
        (
            least_squares(
                lambda th: model.predict(th, X) - y,
                np.clip(x0, lb + 1e-9, ub - 1e-9),
                bounds=(lb, ub),
            )
            for x0 in starts
        ),
        key=lambda r: r.cost,
    )
    return 1.0 - 2.0 * best.cost / np.sum((y - y.mean()) ** 2)


def test_paper1_fitness_ordering_stribeck_msk_vlt():
    """The paper1 truth must rank the models as the paper does (Table 1): velocity only <
    velocity + load < velocity + load + temperature, with clear margins."""
    truth = true_samples(preset("paper1", "reduced"))
    X, y = truth.X, truth.friction
    rng = np.random.default_rng(0)
    r2 = {}
    for model in (Stribeck(), LoadDependent(), VelocityLoadTemperature()):
        lb, ub = model.bounds(X, y).T
        starts = [model.defaults(X, y)] + [lb + (ub - lb) * rng.random(lb.size) for _ in range(4)]
        r2[model.name] = _r2(model, X, y, starts)
    assert 0.6 < r2["stribeck"] < r2["msk"] - 0.02 < r2["vlt"] - 0.07
    assert r2["vlt"] > 0.95
