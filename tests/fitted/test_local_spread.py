"""The prediction intervals' local spread (:mod:`fricid.models._spread`,
:func:`fricid.identify._intervals.local_record`): narrow where the family follows the law,
wide where it misses, about nominal coverage on a law outside the family, the same spread
after pooling a long log, and a malformed record in a file refused by name."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

from fricid.errors import ConfigError
from fricid.fitted import FittedModel
from fricid.identify import fit
from fricid.identify._intervals import local_record
from fricid.models._spread import (
    MAX_POINTS,
    biased_half_width,
    input_spans,
    local_variance,
    spread_points,
)
from fricid.samples import FrictionSamples

SIGMA = 0.02


def _dip(v: np.ndarray) -> np.ndarray:
    """A Stribeck rise of 5 noise std at slow speeds that a Coulomb-viscous line cannot
    follow (a Lorentzian, not fricid's exponential)."""
    return np.sign(v) * (0.8 + 0.1 / (1 + (np.abs(v) / 0.03) ** 2)) + 0.3 * v


def _deep_dip(v: np.ndarray) -> np.ndarray:
    """A Lorentzian rise of 20 noise std: a bias that dwarfs the noise near the dip."""
    return np.sign(v) * (0.8 + 0.4 / (1 + (np.abs(v) / 0.03) ** 2)) + 0.3 * v


def _samples(seed: int, n_speeds: int = 24, law=_dip) -> FrictionSamples:
    rng = np.random.default_rng(seed)
    s = np.geomspace(0.005, 3.0, n_speeds)
    v = np.r_[s, -s]
    y = law(v) + SIGMA * rng.standard_normal(v.size)
    return FrictionSamples(
        velocity=v,
        load=None,
        temperature=None,
        friction=y,
        std=np.full(v.size, SIGMA * np.sqrt(50)),
        count=np.full(v.size, 50),
    )


def _fit(samples, model="coulomb_viscous"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(samples, model, intervals="none")


def _grid() -> np.ndarray:
    s = np.geomspace(0.005, 3.0, 400)
    v = np.r_[s, -s]
    return np.column_stack([v, np.zeros(v.size), np.full(v.size, 25.0)])


def _coverage(model, law=_dip) -> float:
    X = _grid()
    pi = model.predict_interval(X, 0.95, warn=False)
    F = law(X[:, 0])
    return float(
        np.mean(stats.norm.cdf((pi.high - F) / SIGMA) - stats.norm.cdf((pi.low - F) / SIGMA))
    )


def test_narrow_where_the_family_follows_and_wide_where_it_misses():
    model = _fit(_samples(0))
    assert "local" in model.prediction_interval
    X = np.column_stack([[0.006, 2.0], [0.0, 0.0], [25.0, 25.0]])
    half = model.predict_interval(X, 0.95, warn=False).half_width
    assert half[0] > 1.5 * half[1] and half[0] > 4 * SIGMA  # the dip: the bias
    assert half[1] < 3.5 * SIGMA  # the viscous range: the noise and a little misfit


def test_a_family_that_misses_covers_about_nominal():
    """Over 8 seeds the expected coverage of fresh samples on a dense grid lies within
    90-98 %."""
    cover = [_coverage(_fit(_samples(100 + seed))) for seed in range(8)]
    assert 0.90 <= np.mean(cover) <= 0.98, cover


def test_a_bias_many_times_the_noise_is_not_covered_twice():
    """Where a Coulomb-viscous line misses a dip of 20 noise std, an interval of 1.96 times
    the root mean square error there (about twice the bias) covered 99.9 % of new samples;
    the bias-aware width (the local bias plus the noise's share) covers about nominal."""
    cover = [_coverage(_fit(_samples(200 + seed, law=_deep_dip)), _deep_dip) for seed in range(8)]
    assert 0.90 <= np.mean(cover) <= 0.98, cover


@settings(max_examples=80, deadline=None)
@given(st.floats(-50.0, 50.0), st.floats(0.01, 10.0), st.sampled_from([0.5, 0.9, 0.95, 0.99]))
def test_the_bias_aware_width_holds_its_level(bias, std, level):
    """``P(|N(b, s^2)| <= h) = level``; ``z s`` without bias; between ``|b| + z' s`` and
    ``|b| + z s`` (``z'``, ``z`` the one- and two-sided normal quantiles)."""
    h = float(biased_half_width(np.array([bias]), np.array([std]), level)[0])
    held = stats.norm.cdf((h - bias) / std) - stats.norm.cdf((-h - bias) / std)
    assert held == pytest.approx(level, abs=1e-9)
    z1, z2 = stats.norm.ppf(level), stats.norm.ppf(0.5 + level / 2)
    assert abs(bias) + z1 * std * (1 - 1e-9) <= h <= abs(bias) + z2 * std * (1 + 1e-9)
    if bias == 0:
        assert h == pytest.approx(z2 * std)


def test_the_interval_round_trips_through_the_file(tmp_path):
    model = _fit(_samples(1))
    path = tmp_path / "m.json"
    model.save(path)
    again = FittedModel.load(path)
    X = _grid()[::40]
    assert np.allclose(
        again.predict_interval(X, 0.95, warn=False).half_width,
        model.predict_interval(X, 0.95, warn=False).half_width,
    )


@pytest.mark.parametrize(
    "damage",
    [
        lambda r: r.update(e2=r["e2"][:-1]),
        lambda r: r.update(e=r["e"][:-1]),
        lambda r: r.update(e=[float("nan")] * len(r["e"])),
        lambda r: r.update(weight=[0.0] * len(r["weight"])),
        lambda r: r.update(noise=-1.0),
        lambda r: r.pop("bandwidth"),
        lambda r: r.update(spans=[[1.0, 0.0], None]),
        lambda r: r.update(scale=["x", 2.0]),
        lambda r: r.update(scale=[1.6]),
    ],
)
def test_a_malformed_local_record_is_refused(damage):
    model = _fit(_samples(2))
    damage(model.prediction_interval["local"])
    with pytest.raises(ConfigError, match="local interval record is malformed"):
        model.predict_interval(_grid()[:5], 0.95, warn=False)


def test_pooling_a_long_log_keeps_the_spread():
    rng = np.random.default_rng(3)
    n = 3 * MAX_POINTS
    v = np.r_[1, -1][rng.integers(0, 2, n)] * 10 ** rng.uniform(-2, 0.5, n)
    X = np.column_stack([v, rng.uniform(0, 5, n), np.full(n, 25.0)])
    e2 = (0.01 + np.abs(np.log10(np.abs(v)))) ** 2 * rng.chisquare(1, n)
    spans = input_spans(X)
    full = dict(
        noise=0.01,
        bandwidth={"decades": 0.1, "span": 0.3},
        spans=spans,
        velocity=X[:, 0],
        load=X[:, 1],
        temperature=X[:, 2],
        e2=e2,
        weight=np.ones(n),
    )
    P, e2p, w, point = spread_points(X, e2, spans)
    assert len(w) <= MAX_POINTS and w.sum() == n and point.shape == (n,)
    pooled = {**full, "velocity": P[:, 0], "load": P[:, 1], "temperature": P[:, 2]}
    pooled.update(e2=e2p, weight=w)
    at = X[:200]
    assert np.allclose(local_variance(pooled, at), local_variance(full, at), rtol=0.1)


def test_learned_models_keep_their_held_out_spread():
    samples = _samples(4, n_speeds=16)
    for name in ("gp", "rbf"):
        model = _fit(samples, name)
        record = model.prediction_interval
        assert record["method"] == "heldout"
        local = record["local"]
        assert len(local["e2"]) + local["gross"] == len(samples.velocity)
        assert "e" not in local  # the spread about the model, no local bias (module notes)
        assert "_heldout_errors" not in str(model.state)
        half = model.predict_interval(_grid()[::50], 0.95, warn=False).half_width
        assert np.all(half >= 0.95 * 1.96 * SIGMA)  # never below the scatter's


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(0.001, 10.0),
            st.sampled_from([1.0, -1.0]),
            st.floats(0.0, 4.0),
        ),
        min_size=3,
        max_size=30,
    ),
    st.floats(-4.0, 2.0),
)
def test_the_spread_is_an_average_of_the_direction_s_errors(points, at):
    """Nadaraya-Watson: a convex combination of the errors of the same direction, finite
    anywhere on a direction with samples (far from all of them too), NaN on one without."""
    speed, sign, e = (np.array(c) for c in zip(*points, strict=True))
    X = np.column_stack([sign * speed, np.zeros(speed.size), np.full(speed.size, 25.0)])
    record = local_record(e, X, 0.01)
    assert record is not None
    q = np.array([[10**at, 0.0, 25.0], [-(10**at), 0.0, 25.0]])
    got = local_variance(record, q)
    for k, s in enumerate((1.0, -1.0)):
        side = np.asarray(record["e2"])[np.sign(record["velocity"]) == s]
        if side.size:
            assert side.min() * (1 - 1e-9) <= got[k] <= side.max() * (1 + 1e-9)
        else:
            assert np.isnan(got[k])


@pytest.mark.slow  # 2.1 s, quiet machine (default run kept short)
def test_the_report_draws_the_band_where_the_file_has_an_interval():
    from dataclasses import replace

    from fricid.identify.trust import assess_trust
    from fricid.report.model import model_report

    samples = _samples(0)
    model = _fit(samples)

    def keys(m):
        doc = model_report(m, samples, trust=assess_trust(m, samples))
        return [f.name for f in doc.figures()]

    assert "prediction_interval" in keys(model)
    assert "prediction_interval" not in keys(replace(model, prediction_interval=None))


def test_no_interval_inside_a_gap_between_measured_speeds(tmp_path):
    """A decade with no sample: the interval is NaN there (nothing measured backs it),
    finite on either side; ``fricid predict --interval`` writes nan and says why."""
    from typer.testing import CliRunner

    from fricid.cli import app

    rng = np.random.default_rng(5)
    s = np.r_[np.geomspace(0.005, 0.02, 6), np.geomspace(0.5, 3.0, 6)]
    v = np.r_[s, -s]
    samples = FrictionSamples(
        velocity=v,
        load=None,
        temperature=None,
        friction=_dip(v) + SIGMA * rng.standard_normal(v.size),
        std=np.full(v.size, SIGMA * np.sqrt(50)),
        count=np.full(v.size, 50),
    )
    model = _fit(samples, "stribeck")
    X = np.column_stack([[0.01, 0.1, -0.1, 1.0], np.zeros(4), np.full(4, 25.0)])
    pi = model.predict_interval(X, 0.95, warn=False)
    assert np.isnan(pi.low[1:3]).all() and np.isnan(pi.high[1:3]).all()
    assert np.isfinite(pi.low[[0, 3]]).all() and np.isfinite(pi.friction).all()
    path = tmp_path / "m.json"
    model.save(path)
    args = ["predict", str(path), "--velocity", "0.1", "--velocity", "1", "--interval", "0.95"]
    got = CliRunner().invoke(app, args)
    assert got.exit_code == 0, got.output
    assert "nan,nan" in got.stdout and "no prediction interval at 1 of 2 points" in got.stderr


LEVELS = (0.5, 0.8, 0.89, 0.9, 0.91, 0.94, 0.95, 0.96, 0.99)


@pytest.mark.parametrize("name", ["coulomb_viscous", "gp"])
def test_a_higher_level_never_gives_a_narrower_interval(name):
    """Levels between and beyond the calibrated 0.9 and 0.95 follow them (the reference
    quantile times the calibrated ratio): at 0.94 the normal quantile alone was twice the
    calibrated 0.95's on the lead screw."""
    model = _fit(_samples(6), name)
    X = _grid()[::80]
    half = np.array([model.predict_interval(X, q, warn=False).half_width for q in LEVELS])
    assert np.all(np.diff(half, axis=0) >= -1e-12)


def test_with_a_bias_a_higher_level_is_never_narrower_either():
    """Where the bias dominates, the bias-aware width grows with the level by the one-sided
    quantile only: a 0.95 multiplier calibrated below the normal one (light tails) and a
    0.9 one at it made the 95 % interval narrower than the 90 % one at the dip."""
    model = _fit(_samples(7, law=_deep_dip))
    local = model.prediction_interval["local"]
    local["scale"] = [stats.norm.ppf(0.95), 0.8 * stats.norm.ppf(0.975)]
    X = _grid()[::20]
    half = np.array([model.predict_interval(X, q, warn=False).half_width for q in LEVELS])
    assert np.all(np.diff(half, axis=0) >= -1e-12)


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.tuples(st.floats(0.05, 0.995), st.floats(0.01, 5.0)), min_size=1, max_size=4),
    st.lists(st.floats(0.01, 0.999), min_size=2, max_size=6),
)
def test_nested_multipliers_grow_with_the_level(calibrated, asked):
    from fricid.fitted._interval import _norm_ppf, nested_multiplier

    levels, scale = (list(c) for c in zip(*calibrated, strict=True))
    asked = sorted(asked)
    k = [nested_multiplier(levels, scale, q, lambda q: _norm_ppf(0.5 + q / 2)) for q in asked]
    assert np.all(np.diff(k) >= -1e-9)


def test_predict_says_when_the_model_rests_on_undetermined_parameters(tmp_path):
    from dataclasses import replace

    from typer.testing import CliRunner

    from fricid.cli import app

    model = _fit(_samples(7), "stribeck")
    loose = replace(model.parameters["w_s"], not_determined=True)
    path = replace(model, parameters={**model.parameters, "w_s": loose}).save(tmp_path / "m.json")
    got = CliRunner().invoke(app, ["predict", str(path), "--velocity", "0.1"])
    assert got.exit_code == 0, got.output
    assert "do not determine w_s" in got.stderr
    clean = CliRunner().invoke(app, ["predict", str(model.save(tmp_path / "c.json")), "-v", "0.1"])
    assert "do not determine" not in clean.stderr


def test_a_trajectory_model_says_why_it_has_no_interval():
    model = FittedModel.from_values(
        "coulomb_viscous", {"f_c": 1.0, "beta": 0.1}, provenance={"trajectory": {"route": "x"}}
    )
    with pytest.raises(ConfigError, match="identified from a trajectory"):
        model.predict_interval(_grid()[:3], 0.95, warn=False)


def _trajectory_lugre(tmp_path, *undetermined: str):
    """A LuGre model file as a trajectory fit writes it, ``undetermined`` marked so."""
    from dataclasses import replace

    model = FittedModel.from_values(
        "lugre",
        dict(sigma_0=1e3, sigma_1=0.5, sigma_2=0.1, tau_c=0.3, tau_s=0.5, w_s=0.05, delta=2.0),
        operating_range={"velocity": [-2.0, 2.0]},
        provenance={"trajectory": {"route": "filtered"}},
    )
    for name in undetermined:
        model.parameters[name] = replace(
            model.parameters[name], not_determined=True, bounds=(1e-3, 1e3)
        )
    return model.save(tmp_path / "lugre.json")


def test_predict_warns_only_of_undetermined_parameters_the_friction_reads(tmp_path):
    """Steady friction does not read LuGre's sigma_1 (its transients): no warning for it; its
    tau_s (the Stribeck level, at a speed near w_s) is read."""
    from typer.testing import CliRunner

    from fricid.cli import app

    path = _trajectory_lugre(tmp_path, "sigma_1", "tau_s")
    got = CliRunner().invoke(app, ["predict", str(path), "-v", "0.05"])
    assert got.exit_code == 0, got.output
    assert "do not determine tau_s:" in got.stderr and "sigma_1" not in got.stderr
    got = CliRunner().invoke(
        app, ["predict", str(_trajectory_lugre(tmp_path, "sigma_1")), "-v", "0.5"]
    )
    assert got.exit_code == 0 and "do not determine" not in got.stderr
    # sigma_2 held at 0 with no search range: 1 % of 0 moves nothing, yet it sets the viscous
    # part at 0.5 rad/s (it had been left out of the warning)
    from dataclasses import replace

    held = FittedModel.load(_trajectory_lugre(tmp_path))
    held.parameters["sigma_2"] = replace(
        held.parameters["sigma_2"], value=0.0, not_determined=True, bounds=None
    )
    got = CliRunner().invoke(app, ["predict", str(held.save(tmp_path / "h.json")), "-v", "0.5"])
    assert got.exit_code == 0 and "do not determine sigma_2" in got.stderr, got.stderr


def test_predict_interval_of_a_trajectory_model_writes_the_friction_and_says_why(tmp_path):
    from typer.testing import CliRunner

    from fricid.cli import app

    path = _trajectory_lugre(tmp_path)
    args = ["predict", str(path), "-v", "0.5", "-v", "-0.3", "--interval", "0.95"]
    got = CliRunner().invoke(app, args)
    assert got.exit_code == 0, got.output
    rows = got.stdout.strip().splitlines()
    assert len(rows) == 3 and all(r.endswith(",nan,nan") for r in rows[1:])
    friction = FittedModel.load(path).predict(np.array([[0.5, 0.0, 25.0]]), warn=False)[0]
    assert float(rows[1].split(",")[1]) == pytest.approx(friction)
    assert "identified from a trajectory" in " ".join(got.stderr.split())
    bad = CliRunner().invoke(app, [*args[:-1], "1.5"])
    assert bad.exit_code == 2 and "--interval must lie in (0, 1)" in bad.output
    assert str(path) not in bad.output  # the option is at fault, not the model file
