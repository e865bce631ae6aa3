"""LuGre (Canudas de Wit et al. 1995): steady state, exact update, passivity (Barabanov-Ortega)."""

import numpy as np
import pytest

from fricid.errors import ConfigError
from fricid.models import lugre

THETA = np.array([1e4, 1.0, 0.2, 0.5, 0.8, 0.1, 1.0])


def test_constant_velocity_settles_to_the_static_stribeck_law():
    for v in (0.3, -0.05, 2.0):
        F, z = lugre.simulate(THETA, np.full(3000, v), 1e-3)
        assert F[-1] == pytest.approx(lugre.steady_state(THETA, np.array([v]))[0], rel=1e-9)
        assert z[-1] == pytest.approx(np.sign(v) * lugre.stribeck_curve(THETA, [v])[0] / 1e4)


def test_presliding_is_a_spring_of_stiffness_sigma0():
    # a tiny displacement well inside the bristle range: F ~ (sigma_0 + ...) * position
    dt, n = 1e-4, 200
    v = np.full(n, 1e-6)
    F, z = lugre.simulate(THETA, v, dt)
    x = np.cumsum(v) * dt
    assert np.allclose(z, x, rtol=1e-3)
    assert F[-1] == pytest.approx(1e4 * x[-1] + (1.0 + 0.2) * 1e-6, rel=1e-2)


def test_batch_rows_match_single_runs_and_rest_holds_the_state():
    v = np.concatenate([np.full(500, 0.2), np.zeros(300), np.full(200, -0.1)])
    other = THETA * np.array([2, 1, 1, 1, 1, 1, 1])
    F, Z = lugre.simulate(np.vstack([THETA, other]), v, 1e-3)
    for row, th in zip(F, (THETA, other), strict=True):
        np.testing.assert_allclose(row, lugre.simulate(th, v, 1e-3)[0])
    assert np.all(Z[0, 500:800] == Z[0, 499])  # at rest the bristles hold their deflection


def test_stiff_bristles_stay_stable():
    stiff = THETA.copy()
    stiff[0] = 1e8
    F, _ = lugre.simulate(stiff, np.sin(np.linspace(0, 20, 5000)), 1e-3)
    assert np.all(np.isfinite(F)) and np.max(np.abs(F)) < 2.0


def test_passivity_margin_follows_barabanov_ortega():
    assert lugre.passivity_margin(THETA) == pytest.approx(4 * 0.2 * 0.5 / 0.3 - 1.0)
    damped = THETA.copy()
    damped[1] = 10.0
    assert lugre.passivity_margin(damped) < 0
    flat = THETA.copy()
    flat[4] = flat[3]
    assert lugre.passivity_margin(flat) == np.inf
    assert lugre.passivity_margin(THETA * np.array([-1, 1, 1, 1, 1, 1, 1])) == -np.inf


def test_wrong_shapes_and_periods_are_refused():
    with pytest.raises(ConfigError, match="7 parameters"):
        lugre.simulate(THETA[:5], [0.1], 1e-3)
    with pytest.raises(ConfigError, match="periods"):
        lugre.simulate(THETA, [0.1, 0.2], [1e-3, -1.0])


@pytest.mark.slow  # 3 s measured under load (default run kept short)
def test_joint_under_torque_slides_at_the_steady_state_or_sticks():
    # above break-away the joint settles where steady friction balances the torque
    r = lugre.simulate_joint(THETA, 0.01, 0.0, 0.0, 1e-3, np.full(4000, 0.9))
    assert r["friction"][-1] == pytest.approx(0.9, rel=1e-6)
    assert lugre.steady_state(THETA, r["velocity"][-1:])[0] == pytest.approx(0.9, rel=1e-6)
    # below it the joint only deflects the bristles: micro-radians, then rest
    r = lugre.simulate_joint(THETA, 0.01, 0.0, 0.0, 1e-3, np.full(4000, 0.3))
    assert abs(r["velocity"][-1]) < 1e-9 and 0 < r["position"][-1] < 1e-3
    assert r["friction"][-1] == pytest.approx(0.3, rel=1e-6)


def test_joint_sub_steps_converge_and_batches_match():
    t = np.arange(8000) * 1e-3
    tau = np.sin(2 * np.pi * 0.5 * t)
    fine = lugre.simulate_joint(THETA, 0.01, 0.1, 0.05, 1e-3, tau, n_sub=64)
    errors = [
        np.max(
            np.abs(
                lugre.simulate_joint(THETA, 0.01, 0.1, 0.05, 1e-3, tau, n_sub=m)["velocity"]
                - fine["velocity"]
            )
        )
        for m in (2, 8)
    ]
    assert errors[1] < errors[0] / 8 and errors[1] < 1e-3
    other = THETA * np.array([3, 2, 1, 1, 1, 1, 1])
    both = lugre.simulate_joint(np.vstack([THETA, other]), 0.01, 0.1, 0.05, 1e-3, tau)
    one = lugre.simulate_joint(other, 0.01, 0.1, 0.05, 1e-3, tau)
    np.testing.assert_allclose(both["position"][1], one["position"])


def test_joint_reset_needs_measurements():
    with pytest.raises(ConfigError, match="measured"):
        lugre.simulate_joint(THETA, 0.01, 0, 0, 1e-3, np.zeros(5), reset=np.ones(5, bool))


@pytest.mark.parametrize("threads", [2, 3])
def test_rows_in_threads_are_the_rows_of_one_thread_bit_for_bit(monkeypatch, threads):
    """A batch split over threads (:func:`fricid.models.lugre.in_row_threads`: a Jacobian's
    columns) gives every row exactly as one thread does, for the joint and the friction
    averaged over each period."""
    rng = np.random.default_rng(0)
    k, n = 5, 400
    batch = THETA * np.exp(0.2 * rng.standard_normal((k, 7)))
    t = np.arange(n) * 1e-3
    tau = 0.9 * np.sin(2 * np.pi * 2 * t)
    v = 0.3 * np.sin(2 * np.pi * 1.5 * np.arange(4 * (n - 1) + 1) * 2.5e-4)
    runs = {}
    for count in (1, threads):
        monkeypatch.setattr(lugre, "ROW_THREADS", count)
        joint = lugre.simulate_joint(
            batch, 0.01, 0.1, 0.05, 1e-3, tau, reference=(t, 0 * t), gains=(5.0, 0.2)
        )
        runs[count] = (joint, lugre.mean_friction(batch, v, 1e-3, 4))
    for key in runs[1][0]:
        assert np.array_equal(runs[1][0][key], runs[threads][0][key], equal_nan=True)
    assert np.array_equal(runs[1][1], runs[threads][1])
