"""Prediction intervals for every model (`FittedModel.predict_interval`, `fricid predict
--interval`): they cover held-out noisy samples of laws written here at about their level,
tiny data sets included, and travel in the model file."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy import stats
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import ConfigError
from fricid.fitted import FittedModel
from fricid.identify import fit
from fricid.identify.learned._conformal import conformal_half_widths
from fricid.samples import FrictionSamples

NOISE = 0.03


def law(v: np.ndarray) -> np.ndarray:
    """Not one of fricid's families: a sigmoid Coulomb term, a square-root viscous term."""
    return np.sign(v) * (0.6 * np.tanh(np.abs(v) / 0.05) + 0.25 * np.sqrt(np.abs(v)))


def samples_of(seed: int, n_speeds: int = 10, repeats: int = 1) -> FrictionSamples:
    rng = np.random.default_rng(seed)
    speeds = np.geomspace(0.2, 4.0, n_speeds) * rng.uniform(0.97, 1.03, n_speeds)
    v = np.repeat(np.r_[speeds, -speeds], repeats)
    y = law(v) + NOISE * rng.standard_normal(v.size)
    return FrictionSamples(
        velocity=v, load=np.zeros(v.size), temperature=np.full(v.size, 25.0), friction=y
    )


def coverage(model: str, seeds, **kw) -> float:
    """Mean share of 400 held-out noisy samples inside the 95 % interval, over ``seeds``."""
    out = []
    for seed in seeds:
        s = samples_of(seed, **kw)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            extra = {} if model in ("gp", "rbf", "hybrid") else {"intervals": "none"}
            m = fit(s, model, seed=seed, **extra)
        rng = np.random.default_rng(1000 + seed)
        speed = np.abs(s.velocity)
        v = rng.choice([-1.0, 1.0], 400) * np.exp(
            rng.uniform(np.log(speed.min()), np.log(speed.max()), 400)
        )
        X = np.column_stack([v, np.zeros(400), np.full(400, 25.0)])
        y = law(v) + NOISE * rng.standard_normal(400)
        pi = m.predict_interval(X, 0.95, warn=False)
        local = (m.prediction_interval or {}).get("method") == "heldout"
        own = {"gp": "gp", "rbf": "conformal", "hybrid": "conformal"}.get(model, "delta")
        assert pi.method == ("heldout" if local else own)
        out.append(np.mean((y >= pi.low) & (y <= pi.high)))
    return float(np.mean(out))


@pytest.mark.slow  # two multi-start Stribeck fits of a law outside the family: about 4 s
def test_analytic_interval_covers_a_law_outside_its_family():
    assert 0.9 <= coverage("stribeck", [0, 1]) <= 0.995


def test_delta_method_interval_covers_its_own_family():
    rng = np.random.default_rng(7)
    speeds = np.geomspace(0.1, 3.0, 8)
    v = np.r_[speeds, -speeds]
    X = np.column_stack([v, np.zeros(v.size), np.full(v.size, 25.0)])
    truth = np.sign(v) * 0.4 + 0.2 * v
    vh = rng.choice([-1.0, 1.0], 500) * rng.uniform(0.1, 3.0, 500)
    Xh = np.column_stack([vh, np.zeros(500), np.full(500, 25.0)])
    inside = []
    for seed in range(4):
        y = truth + NOISE * np.random.default_rng(seed).standard_normal(v.size)
        s = FrictionSamples(velocity=v, load=X[:, 1], temperature=X[:, 2], friction=y)
        m = fit(s, "coulomb_viscous", intervals="none")
        yh = np.sign(vh) * 0.4 + 0.2 * vh + NOISE * rng.standard_normal(500)
        pi = m.predict_interval(Xh, 0.95, warn=False)
        inside.append(np.mean((yh >= pi.low) & (yh <= pi.high)))
    assert 0.9 <= np.mean(inside) <= 0.99, inside


def test_gp_interval_covers():
    assert 0.88 <= coverage("gp", [0, 1]) <= 1.0


@pytest.mark.parametrize("model", ["rbf", "hybrid"])
def test_conformal_intervals_cover_on_twelve_samples(model):
    # 3 speeds per direction, each twice: the residual network's conformal intervals alone
    # covered about a third to three quarters of new samples
    assert 0.88 <= coverage(model, [0, 1], n_speeds=3, repeats=2) <= 1.0


def test_conformal_fall_back_on_few_residuals():
    r = np.array([1.0, -1.0, 1.0, -1.0, 1.0, -1.0])
    q = stats.t.ppf(0.975, 5) * np.sqrt(7 / 6)
    assert conformal_half_widths(r, (0.95,)) == pytest.approx([q])
    many = np.random.default_rng(0).standard_normal(1000)
    assert conformal_half_widths(many, (0.95,))[0] == pytest.approx(1.96, abs=0.15)


@pytest.fixture(scope="module")
def stribeck() -> FittedModel:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(samples_of(3), "stribeck", intervals="none")


def test_interval_travels_in_the_file_and_needs_a_record(stribeck, tmp_path):
    X = np.array([[0.5, 0.0, 25.0], [-2.0, 0.0, 25.0], [0.0, 0.0, 25.0]])
    a = stribeck.predict_interval(X)
    b = FittedModel.load(stribeck.save(tmp_path / "m.json")).predict_interval(X)
    np.testing.assert_allclose(a.low, b.low)
    assert np.all(a.high[:2] > a.friction[:2]) and np.isnan(a.half_width[2])  # at rest: none
    assert np.all(stribeck.predict_interval(X, 0.9).half_width[:2] < a.half_width[:2])
    old = FittedModel.from_dict({**stribeck.to_dict(), "prediction_interval": None})
    with pytest.raises(ConfigError, match="stores no prediction interval"):
        old.predict_interval(X)
    with pytest.raises(ConfigError, match="level"):
        stribeck.predict_interval(X, 1.5)


def test_cli_predict_writes_the_interval(stribeck, tmp_path):
    path = stribeck.save(tmp_path / "m.json")
    res = CliRunner().invoke(app, ["predict", str(path), "-v", "0.5", "--interval", "0.95"])
    assert res.exit_code == 0, res.output
    head, row = res.stdout.strip().splitlines()
    assert head.endswith("friction [N m],low [N m],high [N m]")
    *_, f, low, high = (float(x) for x in row.split(","))
    pi = stribeck.predict_interval(np.array([[0.5, 0.0, 25.0]]))
    assert (low, f, high) == pytest.approx((pi.low[0], pi.friction[0], pi.high[0]))


def test_no_interval_for_a_fit_without_spare_samples_says_why():
    """Four samples for four free parameters: no residual, no interval; the refusal says so
    (not "fit it again", which would give the same)."""
    v = np.array([-0.8, -0.2, 0.2, 0.8])
    y = np.sign(v) * (0.1 + 0.05 * np.abs(v)) + np.array([1e-3, -2e-3, 2e-3, -1e-3])
    s = FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=y)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = fit(s, "coulomb_viscous_asym")
    assert f.prediction_interval is None
    with pytest.raises(ConfigError, match="4 samples for 4 free parameters leave no residual"):
        f.predict_interval(np.array([[0.5, 0.0, 25.0]]))


def test_no_interval_outside_the_operating_range(stribeck, tmp_path):
    """A 95 % interval at twice the largest measured speed, or below the slowest, was as
    narrow as inside (an RBF network's a constant +/-7e-5 N m at 40 rad/s, missing the
    measured friction): nothing measured backs one there, so none is given, and predict says
    why."""
    X = np.array([[8.0, 0.0, 25.0], [-0.05, 0.0, 25.0], [0.5, 0.0, 25.0], [-2.0, 0.0, 25.0]])
    pi = stribeck.predict_interval(X, warn=False)
    assert np.isnan(pi.half_width[:2]).all() and np.isfinite(pi.half_width[2:]).all()
    assert np.isfinite(pi.friction).all()  # the prediction itself stays (with its warning)
    path = stribeck.save(tmp_path / "m.json")
    res = CliRunner().invoke(
        app, ["predict", str(path), "-v", "8", "-v", "0.5", "--interval", "0.95"]
    )
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert "no prediction interval at 1 of 2 points: outside the range the model was" in text
    assert "in a gap" not in text
    # below the slowest speed: the note must not read as 'above the range'
    res = CliRunner().invoke(
        app, ["predict", str(path), "-v", "-0.05", "-v", "0.5", "--interval", "0.95"]
    )
    assert res.exit_code == 0, res.output
    (note,) = [x for x in res.stderr.splitlines() if x.startswith("note: no prediction")]
    assert "outside the range" in note and "above" not in note, note
    assert "the warnings before this note say where" in note
