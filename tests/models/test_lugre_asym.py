"""Per-direction LuGre (``lugre_asym``): one kernel for both widths, mirror symmetry, the
steady state as ``stribeck_asym``'s, passivity per direction."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fricid.errors import ConfigError
from fricid.models import get_model, lugre

SYM = np.array([1e4, 1.0, 0.2, 0.5, 0.8, 0.1, 1.0])
# forwards as SYM; backwards 30 % weaker levels and a larger viscous coefficient
ASYM = np.array([1e4, 1.0, 0.2, 0.5, 0.8, 0.1, 1.0, 0.3, 0.35, 0.56])


def mirrored(theta: np.ndarray) -> np.ndarray:
    """The same joint seen with the axis reversed: the direction sets swapped."""
    return theta[[0, 1, 7, 8, 9, 5, 6, 2, 3, 4]]


def motion(n: int = 4000, dt: float = 1e-3) -> np.ndarray:
    t = np.arange(n) * dt
    v = 0.3 * np.sin(2 * np.pi * 0.7 * t) + 0.05 * np.sin(2 * np.pi * 3.1 * t)
    v[1000:1200] = 0.0  # a rest
    return v


def test_symmetric_levels_per_direction_give_the_symmetric_model_bit_for_bit():
    same = lugre.wide(SYM)[0]
    v = motion()
    for fn in (lambda th: lugre.simulate(th, v, 1e-3)[0], lambda th: lugre.steady_state(th, v)):
        np.testing.assert_array_equal(fn(same), fn(SYM))
    tau = 2.0 * np.sin(np.arange(v.size) * 2e-3)
    a, b = (lugre.simulate_joint(th, 0.01, 0.3, -0.2, 1e-3, tau)["position"] for th in (same, SYM))
    np.testing.assert_array_equal(a, b)


def test_the_mirrored_joint_gives_the_friction_negated():
    v = motion()
    F, z = lugre.simulate(ASYM, v, 1e-3)
    Fm, zm = lugre.simulate(mirrored(ASYM), -v, 1e-3)
    np.testing.assert_allclose(Fm, -F, rtol=0, atol=1e-12)
    np.testing.assert_allclose(zm, -z, rtol=0, atol=1e-15)
    up = 4
    v_sub = np.concatenate([v[:1], np.repeat(v[1:], up)])
    M = lugre.mean_friction(ASYM, v_sub, 1e-3, up, 0.0)
    Mm = lugre.mean_friction(mirrored(ASYM), -v_sub, 1e-3, up, 0.0)
    np.testing.assert_allclose(Mm, -M, rtol=0, atol=1e-12)
    # the joint: q -> -q, torque -> -torque, p_x -> -p_x (the gravity torque is odd then)
    t = np.arange(3000) * 1e-3
    tau = 1.5 * np.sin(2 * np.pi * 0.5 * t) + 0.4
    run = lugre.simulate_joint(ASYM, 0.01, 0.3, -0.2, 1e-3, tau, q0=0.1)
    back = lugre.simulate_joint(mirrored(ASYM), 0.01, -0.3, -0.2, 1e-3, -tau, q0=-0.1)
    np.testing.assert_allclose(back["position"], -run["position"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(back["friction"], -run["friction"], rtol=0, atol=1e-9)


def test_each_direction_follows_its_own_levels():
    v = np.concatenate([np.full(2000, 0.2), np.full(2000, -0.2)])
    F, _ = lugre.simulate(ASYM, v, 1e-3)
    forward, backward = SYM, mirrored(ASYM)[:7]  # the backward set as a symmetric law
    assert F[1999] == pytest.approx(lugre.steady_state(forward, [0.2])[0], rel=1e-9)
    assert F[-1] == pytest.approx(-lugre.steady_state(backward, [0.2])[0], rel=1e-9)
    assert F[-1] != pytest.approx(-F[1999], rel=1e-3)


def test_the_steady_state_is_stribeck_asym_with_the_shape_shared():
    v = np.linspace(-1.0, 1.0, 201)
    static = get_model("stribeck_asym")
    by_name = dict(zip(lugre.ASYM_NAMES, ASYM, strict=True))
    rename = {"tau_v": "sigma_2", "w_s": "w_s", "delta": "delta"}
    theta = []
    for name in static.param_names:
        base, side = name.rsplit("_", 1)
        shared = base in ("w_s", "delta")
        theta.append(by_name[rename.get(base, base) + ("" if shared else f"_{side}")])
    expected = static.predict(np.array(theta), v)
    np.testing.assert_allclose(get_model("lugre_asym").predict(ASYM, v), expected)


def test_passivity_holds_only_if_it_holds_in_each_direction():
    assert lugre.passivity_margin(ASYM) >= 0
    weak = ASYM.copy()
    weak[7] = 0.001  # backwards hardly any viscous damping: sigma_1 beats 4 s2 tc / gap
    assert lugre.passivity_margin(weak) < 0
    assert lugre.passivity_margin(mirrored(weak)) == pytest.approx(lugre.passivity_margin(weak))
    assert lugre.passivity_margin(weak[:7]) >= 0  # its forward set alone is passive


def test_widths_other_than_7_or_10_are_refused_by_name():
    with pytest.raises(ConfigError, match="7 parameters"):
        lugre.simulate(np.ones(8), np.zeros(3), 1e-3)
    assert get_model("lugre_asym").param_names == lugre.ASYM_NAMES
    assert get_model("lugre", asymmetric=True).name == "lugre_asym"
    with pytest.raises(ConfigError, match="one level for both directions"):
        get_model("dahl_asym")


positive = st.floats(0.05, 2.0)


@settings(max_examples=30, deadline=None)
@given(
    sigma_0=st.floats(1e2, 1e6),
    sigma_1=st.floats(0.0, 50.0),
    levels=st.lists(positive, min_size=6, max_size=6),
    w_s=st.floats(1e-3, 0.5),
    delta=st.floats(0.3, 3.0),
    seed=st.integers(0, 2**16),
)
def test_any_joint_mirrored_gives_the_friction_negated(sigma_0, sigma_1, levels, w_s, delta, seed):
    """The invariant behind the per-direction columns, for any parameters and motion: the
    mirrored joint (the direction sets swapped, v negated) gives -F; equal sets give the
    symmetric model bit for bit."""
    s2p, tcp, tsp, s2n, tcn, tsn = levels
    theta = np.array([sigma_0, sigma_1, s2p, tcp, tsp, w_s, delta, s2n, tcn, tsn])
    v = np.random.default_rng(seed).normal(0.0, 0.3, 300)
    v[50:60] = 0.0
    F, _ = lugre.simulate(theta, v, 1e-3)
    Fm, _ = lugre.simulate(mirrored(theta), -v, 1e-3)
    np.testing.assert_allclose(Fm, -F, rtol=0, atol=1e-12 * max(1.0, np.abs(F).max()))
    sym = theta[:7]
    np.testing.assert_array_equal(lugre.simulate(lugre.wide(sym)[0], v, 1e-3)[0],
                                  lugre.simulate(sym, v, 1e-3)[0])  # fmt: skip
