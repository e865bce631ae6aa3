"""Dahl (1976): exact update, consistency (|F_d| <= tau_c), passivity, LuGre special case."""

import numpy as np
import pytest

from fricid.errors import ConfigError
from fricid.models import dahl, get_model, lugre

THETA = np.array([1e4, 0.5, 1.0, 0.2])


@pytest.mark.parametrize("alpha", [0.5, 1.0, 2.0])
def test_sliding_settles_at_coulomb_plus_viscous(alpha):
    theta = THETA.copy()
    theta[2] = alpha
    for v in (0.3, -0.05):
        F, Fd = dahl.simulate(theta, np.full(20000, v), 1e-3)
        assert F[-1] == pytest.approx(dahl.steady_state(theta, [v])[0], rel=1e-3)
        assert abs(Fd[-1]) <= 0.5


def test_alpha_one_is_lugre_without_damping_and_stribeck():
    v = 0.3 * np.sin(np.linspace(0, 30, 6000))
    F, _ = dahl.simulate(THETA, v, 1e-3)
    as_lugre = np.array([1e4, 0.0, 0.2, 0.5, 0.5, 0.1, 1.0])
    F_l, _ = lugre.simulate(as_lugre, v, 1e-3)
    np.testing.assert_allclose(F, F_l, atol=1e-9)


def test_presliding_stiffness_is_sigma0():
    _F, Fd = dahl.simulate(THETA, np.full(100, 1e-6), 1e-3)
    assert Fd[-1] == pytest.approx(1e4 * 1e-7, rel=1e-2)


@pytest.mark.parametrize("alpha", [0.5, 1.0, 3.0])
def test_consistent_and_passive_along_any_motion(alpha):
    rng = np.random.default_rng(alpha.__hash__() % 100)
    theta = THETA.copy()
    theta[2] = alpha
    v = np.cumsum(rng.normal(0, 0.02, 20000))  # a random walk crossing zero many times
    dt = 1e-4
    F, Fd = dahl.simulate(theta, v, dt, f0=0.0)
    assert np.all(np.abs(Fd) <= 0.5 + 1e-12)
    # passivity: the work done on the friction is at least the stored energy F_d^2 / 2 sigma_0
    work = np.cumsum(F * v * dt)
    stored = Fd**2 / (2 * theta[0])
    assert np.all(work - stored >= -1e-9 * np.max(np.abs(work)))
    assert dahl.is_passive(theta) and dahl.passivity_margin(theta) > 0


def test_outside_state_is_projected_and_bad_parameters_refused():
    _F, Fd = dahl.simulate(THETA, [0.1, 0.1], 1e-3, f0=5.0)
    assert np.all(np.abs(Fd) <= 0.5)
    bad = THETA * np.array([1, -1, 1, 1])
    assert not dahl.is_passive(bad) and dahl.passivity_margin(bad) < 0
    assert np.isnan(dahl.simulate(bad, [0.1], 1e-3)[0]).all()
    with pytest.raises(ConfigError, match="4 parameters"):
        dahl.simulate(THETA[:3], [0.1], 1e-3)


def test_registered_with_steady_state_prediction():
    X = np.array([[0.5, 0.0, 25.0], [-0.5, 0.0, 25.0]])
    np.testing.assert_allclose(get_model("dahl").predict(THETA, X), [0.6, -0.6])
    theta = np.array([1e4, 1.0, 0.2, 0.5, 0.8, 0.1, 1.0])
    np.testing.assert_allclose(
        get_model("lugre").predict(theta, X), lugre.steady_state(theta, X[:, 0])
    )
