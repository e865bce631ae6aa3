"""Analytic models: shapes, oddness in velocity, the papers' equations, registry errors."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fricid.errors import ConfigError, DataError
from fricid.models import MODELS, get_model

V = np.array([-1.0, -0.1, -0.01, 0.01, 0.1, 1.0])
X = np.column_stack([V, np.full(V.size, 0.2), np.full(V.size, 25.0)])


@pytest.mark.parametrize("name", [*MODELS, *(f"{n}_asym" for n in MODELS)])
def test_shapes_single_and_batch(name):
    m = get_model(name)
    theta = m.defaults()
    single = m.predict(theta, X)
    batch = m.predict(np.vstack([theta, theta * 1.1]), X)
    assert single.shape == (len(V),)
    assert batch.shape == (2, len(V))
    np.testing.assert_array_equal(batch[0], single)


@pytest.mark.parametrize("name", list(MODELS))
def test_symmetric_models_are_odd_in_velocity(name):
    m = get_model(name)
    X_neg = X.copy()
    X_neg[:, 0] *= -1
    np.testing.assert_allclose(m.predict(m.defaults(), X_neg), -m.predict(m.defaults(), X))


def test_stribeck_matches_rwsavsbas_eq7():
    """f(w) = tau_c + (tau_s - tau_c) exp(-(w/w_s)^delta) + tau_v w, for w > 0 (eq. 7)."""
    tau_c, tau_s, w_s, tau_v, delta = 0.084, 0.641, 0.066, 0.0026, 1.0
    w = np.array([0.001, 0.066, 0.5, 3.0])
    expected = tau_c + (tau_s - tau_c) * np.exp(-((w / w_s) ** delta)) + tau_v * w
    got = get_model("stribeck").predict([tau_c, tau_s, w_s, tau_v, delta], w)
    np.testing.assert_allclose(got, expected, rtol=1e-14)
    # at zero velocity from above the model tends to the static friction tau_s
    assert get_model("stribeck").predict([tau_c, tau_s, w_s, tau_v, delta], [1e-12])[0] == (
        pytest.approx(tau_s)
    )


def test_msk_reduces_to_stribeck_without_load_terms():
    """Eq. 3 with F_ck = F_sk = 0 is eq. 2."""
    msk, stribeck = get_model("msk"), get_model("stribeck")
    f_c, f_s, v_s, xi, beta = 0.1, 0.3, 0.05, 1.3, 0.02
    a = msk.predict([f_c, f_s, 0.0, 0.0, v_s, xi, beta], X)
    b = stribeck.predict([f_c, f_s, v_s, beta, xi], X)
    np.testing.assert_allclose(a, b, rtol=1e-14)


def test_vlt_reading_of_eq4():
    m = get_model("vlt")
    p = dict(f_c=0.05, f_ctl=0.2, f_stl=0.1, f_v0=0.3, f_vT=-0.002, v_tl0=0.05, v_v0=1.0, v_vT=0.01)
    v, load, T = 0.3, -0.2, 30.0
    expected = (p["f_c"] + (p["f_ctl"] + p["f_stl"] * np.exp(-v / p["v_tl0"])) * abs(load)) + (
        p["f_v0"] + p["f_vT"] * T
    ) * (1 - np.exp(-v / (p["v_v0"] + p["v_vT"] * T)))
    got = m.predict(m.param_vector(p), [[v, load, T]])[0]
    assert got == pytest.approx(expected, rel=1e-14)


def test_asymmetric_uses_each_direction_set():
    m = get_model("coulomb_viscous_asym")
    theta = m.param_vector({"f_c_pos": 1.0, "beta_pos": 0.0, "f_c_neg": 3.0, "beta_neg": 0.0})
    got = m.predict(theta, [[0.5, 0, 0], [-0.5, 0, 0]])
    np.testing.assert_allclose(got, [1.0, -3.0])


@settings(max_examples=50, deadline=None)
@given(
    scale_f=st.floats(1e-3, 1e3),
    scale_v=st.floats(1e-3, 1e2),
    name=st.sampled_from(sorted(MODELS)),
)
def test_data_scaled_defaults_lie_within_data_scaled_bounds(scale_f, scale_v, name):
    m = get_model(name)
    Xd = np.column_stack([np.linspace(-scale_v, scale_v, 7), np.full(7, 0.3), np.full(7, 20.0)])
    y = np.linspace(-scale_f, scale_f, 7)
    b = m.bounds(Xd, y)
    d = m.defaults(Xd, y)
    assert np.all(b[:, 0] < b[:, 1])
    assert np.all((b[:, 0] <= d) & (d <= b[:, 1]))


def test_bad_model_name_lists_choices():
    with pytest.raises(ConfigError, match="choose one of analytic: coulomb_viscous"):
        get_model("coulomb")


def test_wrong_parameter_vector_shape_names_parameters():
    with pytest.raises(ConfigError, match=r"takes 5 parameters \(tau_c, tau_s"):
        get_model("stribeck").predict([1.0, 2.0], X)


def test_wrong_input_shape():
    with pytest.raises(DataError, match="shape"):
        get_model("stribeck").predict(get_model("stribeck").defaults(), np.ones((4, 2)))


def test_param_vector_names_missing_and_unknown():
    with pytest.raises(ConfigError, match="missing: beta; unknown: b"):
        get_model("coulomb_viscous").param_vector({"f_c": 1.0, "b": 2.0})


def test_an_unknown_model_is_told_every_family_and_the_nearest_name():
    """A new user's trial: '--model strbeck' was offered four analytic families, none of
    the dynamic ones, and no nearest name."""

    with pytest.raises(ConfigError) as info:
        get_model("strbeck")
    text = str(info.value)
    assert "did you mean 'stribeck'" in text, text
    for name in ("coulomb_viscous", "stribeck", "msk", "vlt", "lugre", "lugre_asym", "dahl"):
        assert name in text, (name, text)


def test_fit_names_the_learned_families_too():
    from fricid.identify import fit
    from fricid.samples import FrictionSamples

    v = np.linspace(-1, 1, 20)
    s = FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=0.1 * np.sign(v))
    with pytest.raises(ConfigError) as info:
        fit(s, "rbff")
    text = str(info.value)
    assert "did you mean 'rbf'" in text and "hybrid" in text and "auto" in text, text


def test_a_trajectory_model_typo_is_told_the_nearest_name():
    from fricid.identify.dynamic._routes import route_for

    with pytest.raises(ConfigError, match="did you mean 'lugre'"):
        route_for("lugree", "filtered", False)
