"""Extraction against the virtual joint's truth: raw log -> friction samples (eq. 7-13).

Tolerances come from the noise. ``expected_noise_std`` gives each averaged sample's standard
deviation (per-traverse offset over R passes plus median-filtered sensor noise over a bin's
samples); errors are Gaussian, so a row misses by more than 5 sigma with probability 6e-7.
Rows of one set-point share their passes, so a campaign is at most a few dozen independent
draws: a false alarm has odds below 1e-4, while a bias of 5 sigma (a few mN m, 1-3 % of the
friction) fails the test.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fricid.errors import ConfigError, DataError
from fricid.extract import (
    PositionBins,
    cluster,
    extract,
    fit_gravity,
    separate,
)
from fricid.extract.bins import Cells, CellTable, pool_cells
from fricid.samples import RawLog
from fricid.sim import (
    Noise,
    expected_noise_std,
    preset,
    simulate,
    simulate_log,
    true_gravity,
    true_samples,
)

Z = 5.0  # tolerance in standard deviations of the noise, see the module docstring


@pytest.fixture(scope="module")
def quick1():
    return preset("paper1", "quick")


@pytest.fixture(scope="module")
def quick1_log(quick1):
    return simulate_log(quick1, seed=7)


@pytest.fixture(scope="module")
def quick1_result(quick1, quick1_log):
    return extract(quick1_log, **quick1.extract_options())


def _assert_samples_equal(a, b):
    for name in ("velocity", "load", "temperature", "friction", "direction", "count", "std"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


# -- recovery of the truth ----------------------------------------------------------------------


def test_recovers_gravity_and_friction_paper1(quick1, quick1_result):
    r = quick1_result
    truth = true_samples(quick1)
    sigma = expected_noise_std(quick1)
    assert len(r.samples) == len(truth)
    np.testing.assert_allclose(r.samples.velocity, truth.velocity, rtol=0.01)
    np.testing.assert_allclose(r.samples.temperature, truth.temperature, atol=0.1)
    assert (r.samples.direction == 0).all()
    err = r.samples.friction - truth.friction
    assert np.all(np.abs(err) <= Z * sigma), np.abs(err / sigma).max()

    truth_d = true_samples(quick1, by_direction=True)
    sigma_d = expected_noise_std(quick1, by_direction=True)
    np.testing.assert_array_equal(r.by_direction.direction, truth_d.direction)
    assert np.all(np.sign(r.by_direction.velocity) == truth_d.direction)
    err_d = r.by_direction.friction - truth_d.friction
    assert np.all(np.abs(err_d) <= Z * sigma_d), np.abs(err_d / sigma_d).max()

    # gravity: within 5 standard errors of the fit, and the errors are honest (small)
    p_x, p_y = true_gravity(quick1)
    g = r.gravity
    assert abs(g.p_x - p_x) <= Z * g.p_x_se and abs(g.p_y - p_y) <= Z * g.p_y_se
    assert max(g.p_x_se, g.p_y_se) < 2e-3
    # load = fitted gravity at the bin (eq. 12): its error is bounded by the coefficients'
    assert np.all(np.abs(r.samples.load - truth.load) <= Z * (g.p_x_se + g.p_y_se))
    # the pass-to-pass standard error sees the same noise floor, within its own scatter (2 passes)
    assert 0.2 < np.median(r.sem / sigma) < 3.0


def test_recovers_friction_paper2_horizontal_joint():
    s = preset("paper2", "quick")
    r = extract(simulate(s, seed=3), **s.extract_options())
    truth = true_samples(s)
    sigma = expected_noise_std(s)
    assert r.gravity is None
    np.testing.assert_array_equal(r.samples.load, 0.0)
    err = r.samples.friction - truth.friction
    assert np.all(np.abs(err) <= Z * sigma), np.abs(err / sigma).max()
    assert r.diagnostics.velocity_setpoints.size == s.design.velocities.size


@pytest.mark.parametrize("name", ["paper1", "paper2"])
def test_noiseless_is_exact(name):
    s = preset(name, "quick").with_noise(Noise.none())
    r = extract(simulate(s, seed=0), **s.extract_options())
    law = s.joint.law
    for samples in (r.samples, r.by_direction):
        expected = law(samples.velocity, samples.load, samples.temperature)
        np.testing.assert_allclose(samples.friction, expected, rtol=0, atol=1e-5)
    if r.gravity is not None:
        # averaging cos/sin over a bin of half-width h shifts eq. 7 by ~h^2/6 relative
        h = s.design.bin_halfwidth
        bound = 2 * h * h / 6 * (abs(s.joint.p_x) + abs(s.joint.p_y))
        assert abs(r.gravity.p_x - s.joint.p_x) < bound
        assert abs(r.gravity.p_y - s.joint.p_y) < bound
    assert r.diagnostics.spikes == 0


def test_median_filter_removes_spikes(quick1):
    spiky = quick1.with_noise(Noise(spike_rate=0.01, spike_min=1.0, spike_max=3.0))
    log = simulate_log(spiky, seed=1)
    truth = true_samples(spiky).friction
    sigma = expected_noise_std(spiky)
    filtered = extract(log, median_window=5, **spiky.extract_options())
    # no filter and no outlier screen (which would catch the spikes too)
    raw = extract(log, median_window=1, outlier_sigmas=None, **spiky.extract_options())
    err_f = filtered.samples.friction - truth
    err_r = raw.samples.friction - truth
    assert np.all(np.abs(err_f) <= Z * sigma)
    rms_f, rms_r = np.sqrt(np.mean(err_f**2)), np.sqrt(np.mean(err_r**2))
    assert rms_r > 3 * rms_f, (rms_r, rms_f)
    # the diagnostics count about spike_rate of the steady samples as spikes
    d = filtered.diagnostics
    steady = d.binned + d.outside_bins
    assert 0.7 * 0.01 * steady < d.spikes < 1.3 * 0.01 * steady
    assert raw.diagnostics.spikes == 0


# -- reproducibility and streaming --------------------------------------------------------------


def test_same_seed_same_samples(quick1, quick1_result):
    again = extract(simulate(quick1, seed=7), **quick1.extract_options())
    _assert_samples_equal(again.samples, quick1_result.samples)
    _assert_samples_equal(again.by_direction, quick1_result.by_direction)
    other = extract(simulate(quick1, seed=8), **quick1.extract_options())
    assert not np.array_equal(other.samples.friction, quick1_result.samples.friction)


@pytest.mark.parametrize("chunk", ["period", "experiment"])
def test_simulator_chunks_extract_identically(quick1, quick1_result, chunk):
    r = extract(simulate(quick1, seed=7, chunk=chunk), **quick1.extract_options())
    _assert_samples_equal(r.samples, quick1_result.samples)
    _assert_samples_equal(r.by_direction, quick1_result.by_direction)
    assert r.gravity == quick1_result.gravity


def test_arbitrary_chunks_with_segments_straddling_boundaries(quick1, quick1_log, quick1_result):
    n = len(quick1_log)
    cuts = np.sort(np.random.default_rng(0).choice(np.arange(1, n), size=40, replace=False))
    # make sure cuts fall inside constant-velocity stretches, not only in dwells
    assert (np.abs(quick1_log.velocity[cuts]) > 0.01).sum() > 20
    bounds = np.concatenate(([0], cuts, [n]))
    chunks = (quick1_log.slice(a, b) for a, b in itertools.pairwise(bounds))
    r = extract(chunks, **quick1.extract_options())
    _assert_samples_equal(r.samples, quick1_result.samples)
    _assert_samples_equal(r.by_direction, quick1_result.by_direction)
    assert r.diagnostics.chunks == 41
    assert r.diagnostics.segments == quick1_result.diagnostics.segments


def test_time_restart_between_files(quick1):
    """Two files, the second's clock restarting at 0, extract as if they were one."""
    a, b = simulate(quick1, seed=2, chunk="experiment")
    b0 = replace(b, time=b.time - b.time[0])
    ref = extract([a, b], **quick1.extract_options())
    r = extract([a, b0], **quick1.extract_options())
    _assert_samples_equal(r.samples, ref.samples)


def test_diagnostics(quick1, quick1_result):
    d = quick1_result.diagnostics
    n_t, n_v, _ = quick1.design.shape
    assert d.segments == 2 * quick1.design.repetitions * n_v * n_t
    assert d.dropped["no_plateau"] == d.dropped["short_steady"] == 0
    assert d.passes_min == d.passes_max == quick1.design.repetitions
    np.testing.assert_allclose(d.velocity_setpoints, quick1.design.velocities, rtol=0.01)
    np.testing.assert_allclose(d.temperature_setpoints, quick1.design.temperatures, atol=0.1)
    assert d.spikes > 0
    assert "gravity (eq. 7)" in quick1_result.summary()


# -- bad input ----------------------------------------------------------------------------------


def test_no_constant_velocity_segment():
    n = 500
    log = RawLog(
        time=np.arange(n) / 250.0,
        position=np.zeros(n),
        velocity=np.random.default_rng(0).normal(0, 1e-4, n),  # at rest, noisy
        temperature=25.0,
        torque=np.zeros(n),
        source="rest.csv",
    )
    with pytest.raises(
        DataError, match=r"rest\.csv: no constant-velocity segment found in 500 rows"
    ):
        extract(log, gravity="none")


def test_non_finite_values_are_refused_with_row_and_column():
    velocity = np.full(50, 0.1)
    velocity[17] = np.nan
    with pytest.raises(DataError, match=r"bad\.csv, row 17, column 'velocity'"):
        RawLog(np.arange(50.0), np.zeros(50), velocity, 20.0, torque=np.zeros(50), source="bad.csv")


def test_one_direction_only(quick1, quick1_log):
    rows = np.flatnonzero(quick1_log.velocity >= 0)
    forward = replace(
        quick1_log,
        **{
            k: getattr(quick1_log, k)[rows]
            for k in ("time", "position", "velocity", "temperature", "current")
        },
    )
    with pytest.raises(DataError, match="lack one") as info:
        extract(forward, **quick1.extract_options())
    message = str(info.value)
    assert "no negative-direction data in 5 of 5 bins" in message
    assert "gravity='none'" in message
    # a horizontal-joint reading takes the single direction as measured: that direction's
    # samples (direction +1), not "both directions combined" (direction 0 made an export
    # mirror the unmeasured side as a direction-combined model's)
    r = extract(forward, **{**quick1.extract_options(), "gravity": "none"})
    assert (r.by_direction.direction == 1).all() and len(r.samples) == len(r.by_direction)
    assert (r.samples.direction == 1).all() and (r.samples.velocity > 0).all()
    np.testing.assert_array_equal(r.samples.friction, r.by_direction.friction)
    assert "(one direction only;" in r.summary() and "(both directions" not in r.summary()
    assert any("measured forwards only" in n for n in r.notes)
    rows = np.flatnonzero(quick1_log.velocity <= 0)
    backward = replace(
        quick1_log,
        **{
            k: getattr(quick1_log, k)[rows]
            for k in ("time", "position", "velocity", "temperature", "current")
        },
    )
    r = extract(backward, **{**quick1.extract_options(), "gravity": "none"})
    assert (r.samples.direction == -1).all() and (r.samples.velocity < 0).all()
    assert (r.samples.friction < 0).all()


def test_missing_direction_at_one_setpoint_is_named(quick1, quick1_log):
    v = quick1_log.velocity
    slow = quick1.design.velocities[0]
    drop = (v < 0) & (np.abs(np.abs(v) - slow) < 0.1 * slow)
    rows = np.flatnonzero(~drop)
    log = replace(
        quick1_log,
        **{
            k: getattr(quick1_log, k)[rows]
            for k in ("time", "position", "velocity", "temperature", "current")
        },
    )
    # eq. 11 cannot pair them; the joint fit (issue 13) stands in, and the note names them
    r = extract(log, **quick1.extract_options())
    assert r.options["gravity"] == "joint"
    (note,) = r.notes
    assert "2 set-point(s) lack one" in note
    assert "(1 deg/s): no negative-direction data" in note
    assert "(6 deg/s)" not in note


def test_gravity_fit_needs_position_bins(quick1_log):
    with pytest.raises(ConfigError, match="needs position bins"):
        extract(quick1_log, positions=None, gravity="fit")
    # bins given, but the log covers only one of them
    with pytest.raises(DataError, match="two or more distinct positions"):
        extract(quick1_log, positions=[-math.pi / 3, 3.0], bin_halfwidth=0.02, gravity="fit")


def test_positions_outside_the_log(quick1_log):
    with pytest.raises(DataError, match="none has samples inside the position bins"):
        extract(quick1_log, positions=[3.0, 3.1], gravity="fit")


def test_bad_options(quick1_log):
    with pytest.raises(ConfigError, match="median_window"):
        extract(quick1_log, median_window=4, gravity="none")
    with pytest.raises(ConfigError, match="gravity"):
        extract(quick1_log, gravity="upward")
    with pytest.raises(ConfigError, match="overlap"):
        extract(quick1_log, positions=[0.0, 0.1], bin_halfwidth=0.06)
    with pytest.raises(ConfigError, match="single position"):
        extract(quick1_log, positions=[0.0])
    with pytest.raises(ConfigError, match="not a RawLog"):
        extract([quick1_log, np.zeros(3)], gravity="none")
    with pytest.raises(ConfigError, match="velocity_tolerance"):
        extract(quick1_log, velocity_tolerance=0.0, gravity="none")


# -- the building blocks ------------------------------------------------------------------------


def test_cluster():
    labels, centres = cluster(np.array([1.0, 1.01, 3.0, 0.99, 3.02, 10.0]), 0.05, relative=True)
    np.testing.assert_array_equal(labels, [0, 0, 1, 0, 1, 2])
    np.testing.assert_allclose(centres, [1.0, 3.01, 10.0])
    labels, centres = cluster(np.array([25.1, 4.9, 5.1, 24.8]), 1.0, relative=False)
    np.testing.assert_array_equal(labels, [1, 0, 0, 1])


def test_position_bins():
    bins = PositionBins(np.array([0.2, 0.0, 0.1]), 0.02)
    np.testing.assert_array_equal(bins.assign([-0.02, 0.05, 0.09, 0.2199, 0.3]), [0, -1, 1, 2, -1])
    assert PositionBins(np.array([0.0, 0.1])).halfwidth == pytest.approx(0.05)
    auto = PositionBins()
    assert auto.auto and auto.n_bins == 1
    np.testing.assert_array_equal(auto.assign([5.0, -5.0]), [0, 0])


@settings(max_examples=30, deadline=None)
@given(
    sizes=st.lists(st.integers(1, 40), min_size=1, max_size=6),
    seed=st.integers(0, 2**32 - 1),
)
def test_pooling_equals_direct_statistics(sizes, seed):
    rng = np.random.default_rng(seed)
    parts = [rng.normal(rng.normal(), rng.uniform(0.1, 2), n) for n in sizes]
    cells = [
        Cells.of(np.zeros(n, np.intp), x, x, x, x, 1) for n, x in zip(sizes, parts, strict=True)
    ]
    table = CellTable(
        group=np.zeros(len(cells), np.intp),
        **{
            k: np.concatenate([getattr(c, k) for c in cells])
            for k in ("count", "torque", "m2", "position", "velocity", "temperature")
        },
    )
    pooled = pool_cells(table, 1)
    allx = np.concatenate(parts)
    assert pooled.count[0] == allx.size and pooled.passes[0] == len(sizes)
    np.testing.assert_allclose(pooled.torque[0], allx.mean(), rtol=1e-10, atol=1e-12)
    if allx.size > 1:
        np.testing.assert_allclose(pooled.std[0], allx.std(ddof=1), rtol=1e-9, atol=1e-12)


@settings(max_examples=50, deadline=None)
@given(
    p_x=st.floats(-5, 5),
    p_y=st.floats(-5, 5),
    friction=st.lists(st.floats(0.0, 3.0), min_size=1, max_size=8),
    theta0=st.floats(-math.pi, math.pi),
)
def test_eq11_separation_and_eq7_fit_are_exact(p_x, p_y, friction, theta0):
    f = np.array(friction)
    theta = theta0 + np.linspace(-0.5, 0.5, f.size + 2)[: f.size]
    theta = np.concatenate([theta, theta0 + np.array([0.7, 0.9])])
    f = np.concatenate([f, [0.1, 0.2]])
    tau_g = p_x * np.cos(theta) - p_y * np.sin(theta)
    tau_f, g = separate(f - tau_g, -f - tau_g)  # eq. 9: tau+- = +-tau_f - tau_g
    np.testing.assert_allclose(tau_f, f, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(g, tau_g, rtol=1e-12, atol=1e-12)
    fit = fit_gravity(theta, g)
    assert fit.p_x == pytest.approx(p_x, abs=1e-9) and fit.p_y == pytest.approx(p_y, abs=1e-9)
    assert fit.residual_rms < 1e-9


def _sweep_log(p_x, p_y, friction, speeds, fs=100.0):
    """Noiseless torque log: each speed forwards then backwards over [-1, 1] rad, with dwells."""
    pos, vel, tau = [], [], []
    for v, f in zip(speeds, friction, strict=True):
        theta = np.linspace(-1.0, 1.0, round(2.0 / v * fs) + 1)
        for d in (1.0, -1.0):
            th = theta if d > 0 else theta[::-1]
            tau_g = p_x * np.cos(th) - p_y * np.sin(th)
            pos += [th, np.full(10, th[-1])]
            vel += [np.full(th.size, d * v), np.zeros(10)]
            tau += [d * f - tau_g, np.full(10, -tau_g[-1])]
    pos = np.concatenate(pos)
    return RawLog(
        time=np.arange(pos.size) / fs,
        position=pos,
        velocity=np.concatenate(vel),
        temperature=20.0,
        torque=np.concatenate(tau),
    )


@settings(max_examples=25, deadline=None)
@given(
    p_x=st.floats(-3, 3),
    p_y=st.floats(-3, 3),
    friction=st.lists(st.floats(0.01, 2.0), min_size=2, max_size=2),
)
def test_pipeline_separation_exact_on_noiseless_torque(p_x, p_y, friction):
    speeds = [0.4, 1.0]
    centres = np.array([-0.6, -0.3, 0.0, 0.3, 0.6])
    h = 0.02
    r = extract(
        _sweep_log(p_x, p_y, friction, speeds), positions=centres, bin_halfwidth=h, median_window=1
    )
    f = np.repeat(friction, centres.size)
    np.testing.assert_allclose(r.samples.friction, f, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(r.samples.velocity, np.repeat(speeds, centres.size))
    # eq. 7 fitted to bin means: exact up to the bin's curvature, ~h^2/6 relative
    tol = h * h / 3 * (abs(p_x) + abs(p_y)) + 1e-12
    assert abs(r.gravity.p_x - p_x) < tol and abs(r.gravity.p_y - p_y) < tol
    true_load = p_x * np.cos(r.position) - p_y * np.sin(r.position)
    np.testing.assert_allclose(r.samples.load, true_load, atol=2 * tol)
    np.testing.assert_allclose(
        r.by_direction.friction, np.repeat(f, 2) * np.tile([-1, 1], f.size), atol=2 * tol + 1e-9
    )
