"""Gravity without pairing (issue 13): eq. 7 and per-set-point friction identified jointly.

The virtual joint's friction grows with the load (the ``paper1`` truth), so the joint fit
models that load dependence (:mod:`fricid.extract.joint_gravity`). Tolerances: Z standard
errors of the fits (as in test_extract.py).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from fricid.errors import ConfigError, DataError
from fricid.extract import JointGravityFit, extract, fit_gravity_joint, moments
from fricid.sim import expected_noise_std, preset, simulate_log, true_gravity

Z = 5.0


@pytest.fixture(scope="module")
def quick1():
    return preset("paper1", "quick")


@pytest.fixture(scope="module")
def split1(quick1):
    """The quick paper1 campaign with one-sided coverage: forward below the middle of the
    range, backward above it."""
    return replace(quick1, design=replace(quick1.design, coverage="split"))


@pytest.fixture(scope="module")
def full_log(quick1):
    return simulate_log(quick1, seed=7)


def test_split_coverage_has_no_shared_positions(split1):
    log = simulate_log(split1, seed=7)
    low, high = split1.design.measured_range
    middle = 0.5 * (low + high)
    moving = np.abs(log.velocity) > 0.5 * split1.design.velocities.min()
    assert not np.any(moving & (log.velocity > 0) & (log.position > middle + 1e-9))
    assert not np.any(moving & (log.velocity < 0) & (log.position < middle - 1e-9))
    with pytest.raises(ConfigError, match="coverage"):
        replace(split1.design, coverage="half")


def test_joint_and_eq11_agree_on_the_virtual_joint(quick1, full_log):
    opts = quick1.extract_options()
    paired = extract(full_log, **opts).gravity
    joint = extract(full_log, **{**opts, "gravity": "joint"}).gravity
    assert isinstance(joint, JointGravityFit) and not isinstance(paired, JointGravityFit)
    for name in ("p_x", "p_y"):
        a, b = getattr(paired, name), getattr(joint, name)
        se = np.hypot(getattr(paired, f"{name}_se"), getattr(joint, f"{name}_se"))
        assert abs(a - b) <= 2 * se, (name, a, b, se)
    p_x, p_y = true_gravity(quick1)
    assert abs(joint.p_x - p_x) <= Z * joint.p_x_se and abs(joint.p_y - p_y) <= Z * joint.p_y_se
    # the joint fit uses every steady sample, inside the position bins or not: no bins needed
    unbinned = extract(full_log, gravity="joint")
    assert (unbinned.gravity.p_x, unbinned.gravity.p_y) == (joint.p_x, joint.p_y)
    assert len(unbinned.samples) == 3 * 2  # one row per velocity and temperature
    # one friction per set-point and direction, with its standard error
    assert joint.friction.size == 2 * 3 * 2 and np.all(joint.friction_se > 0)
    assert np.all(np.sign(joint.friction) == np.where(joint.group % 2 == 1, 1, -1))


def test_one_sided_coverage_falls_back_to_the_joint_fit(split1):
    log = simulate_log(split1, seed=7)
    opts = split1.extract_options()
    assert opts["gravity"] == "fit"
    r = extract(log, **opts)
    assert r.options["gravity"] == "joint" and r.options["gravity_requested"] == "fit"
    assert len(r.notes) == 1 and "lack one" in r.notes[0] and "gravity='joint'" in r.notes[0]
    assert "note: eq. 11" in r.summary() and "no pairing" in r.summary()
    assert r.summary().count(" rad/s ") >= 12  # every set-point friction, with its error
    g = r.gravity
    p_x, p_y = true_gravity(split1)
    assert abs(g.p_x - p_x) <= Z * g.p_x_se and abs(g.p_y - p_y) <= Z * g.p_y_se
    assert max(g.p_x_se, g.p_y_se) < 0.02
    # asked for directly, the same answer
    direct = extract(log, **{**opts, "gravity": "joint"})
    assert direct.gravity.p_x == g.p_x and not direct.notes
    # per direction: the measured torque with the fitted gravity removed matches the law
    law = split1.joint.law
    d = r.by_direction
    expected = law(d.velocity, d.load, d.temperature)
    sigma = float(np.max(expected_noise_std(split1, by_direction=True)))
    bound = Z * sigma + 2 * Z * (g.p_x_se + g.p_y_se)
    assert np.all(np.abs(d.friction - expected) <= bound), np.abs(d.friction - expected).max()
    assert set(np.unique(d.direction)) == {-1.0, 1.0}
    assert r.samples.meta["gravity"]["method"] == "joint"


def test_one_direction_only_is_not_determined(quick1, full_log):
    """Forward runs alone cannot tell gravity from load-dependent friction: an error that says
    so, after eq. 11's own complaint."""
    rows = np.flatnonzero(full_log.velocity >= 0)
    cols = ("time", "position", "velocity", "temperature", "current")
    forward = replace(full_log, **{k: getattr(full_log, k)[rows] for k in cols})
    with pytest.raises(DataError, match="lack one") as info:
        extract(forward, **quick1.extract_options())
    assert "nor can gravity='joint' stand in" in str(info.value)
    assert "only one direction of motion" in str(info.value)


def test_moments_pool_exactly_over_chunks():
    rng = np.random.default_rng(1)
    theta = rng.uniform(-1, 1, 1000)
    tau = 0.3 + 0.2 * np.cos(theta) + rng.normal(0, 0.01, 1000)
    whole = fit_gravity_joint([moments(theta, tau), moments(-theta, -tau)], [1, 0], [1, -1])
    parts = [moments(theta[:300], tau[:300]), moments(theta[300:], tau[300:])]
    split = fit_gravity_joint([*parts, moments(-theta, -tau)], [1, 1, 0], [1, 1, -1])
    assert split.p_x == pytest.approx(whole.p_x, rel=1e-9, abs=1e-12)
    assert split.friction == pytest.approx(whole.friction, rel=1e-9)


def test_joint_fit_recovers_a_known_line_exactly():
    """tau = F_k - p_x cos + p_y sin + s q.z, noiseless: every coefficient exact."""
    p, q = np.array([0.4, -0.1]), np.array([0.05, 0.02])
    stats, group, direction = [], [], []
    for k, (lo, hi, s, f) in enumerate([(-1.2, -0.2, 1, 0.3), (0.1, 1.0, -1, -0.35)]):
        theta = np.linspace(lo, hi, 500)
        z = np.column_stack([-np.cos(theta), np.sin(theta)])
        stats.append(moments(theta, f + z @ p + s * z @ q))
        group.append(k)
        direction.append(s)
    fit = fit_gravity_joint(stats, group, direction)
    np.testing.assert_allclose([fit.p_x, fit.p_y], p, atol=1e-9)
    np.testing.assert_allclose(fit.load_friction, q, atol=1e-9)


def test_cli_simulate_split_then_extract_joint(tmp_path):
    from typer.testing import CliRunner

    from fricid.cli import app

    runner = CliRunner()
    log = tmp_path / "split.parquet"
    res = runner.invoke(
        app, ["simulate", "--size", "quick", "--coverage", "split", "-o", str(log), "--seed", "2"]
    )
    assert res.exit_code == 0, res.output
    res = runner.invoke(app, ["extract", str(log), "-o", str(tmp_path / "a.csv")])
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert "note: eq. 11 separates" in text and "gravity='joint'" in text
    res = runner.invoke(
        app, ["extract", str(log), "-o", str(tmp_path / "b.csv"), "--gravity", "joint"]
    )
    assert res.exit_code == 0, res.output
    assert "joint fit with 12 set-point frictions, no pairing" in " ".join(res.output.split())
    assert "note:" not in res.output
    bad = runner.invoke(app, ["simulate", "--coverage", "half", "-o", str(tmp_path / "x.csv")])
    assert bad.exit_code == 2 and "coverage" in bad.output
