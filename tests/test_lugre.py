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
