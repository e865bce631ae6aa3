"""The error samples share (an arm's identified gravity) in a law's intervals
(fricid.identify.static.shared_error, fricid.identify.static.uncertainty.assess)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy import stats

from fricid.identify import fit
from fricid.identify.static.shared_error import shared_covariance
from fricid.samples import FrictionSamples

SPEEDS = np.array([0.2, 0.4, 0.8])
#: Two base gravity parameters' standard errors; each level's regressor row is nearly the
#: same at every speed of a direction (a near-offset, as on a swept arm), with a part that
#: is not (another pose per speed), which the residuals do show.
SE_BETA = np.array([0.02, 0.01])
TRUTH = {"f_c_pos": 0.10, "beta_pos": 0.08, "f_c_neg": 0.05, "beta_neg": 0.04}


def _levels(velocity: np.ndarray) -> list[dict]:
    return [
        {
            "joint": "j",
            "temperature": 25.0,
            "velocity": float(v),
            "direction": int(np.sign(v)),
            "count": 500,
            "regressor": [0.3 + 0.4 * (abs(v) - 0.45) ** 2, -0.2 if v > 0 else 0.25],
        }
        for v in velocity
    ]


def _meta(velocity: np.ndarray, identified: bool = True) -> dict:
    cov = np.array([[1.0, 0.3], [0.3, 1.0]]) * np.outer(SE_BETA, SE_BETA)
    return {
        "gravity": {
            "method": "arm",
            "identified": identified,
            "parameters": [
                {"name": f"b{i}", "value": 1.0, "se": float(s)} for i, s in enumerate(SE_BETA)
            ],
            "covariance": cov.tolist(),
            "levels": _levels(velocity),
        },
        "extract": {"temperature_atol": 1.0},
    }


def _fs(velocity, friction, meta: dict | None = None) -> FrictionSamples:
    return FrictionSamples(velocity, None, 25.0, friction, meta=meta or {})


def _velocity() -> np.ndarray:
    return np.concatenate([SPEEDS, -SPEEDS])


def _law(v: np.ndarray) -> np.ndarray:
    pos = TRUTH["f_c_pos"] + TRUTH["beta_pos"] * v
    neg = -(TRUTH["f_c_neg"] + TRUTH["beta_neg"] * -v)
    return np.where(v > 0, pos, neg)


def _samples(rng, noise: float, meta: dict | None, shared: bool = True) -> FrictionSamples:
    v = _velocity()
    g = -np.array([lv["regressor"] for lv in _levels(v)])
    d_beta = rng.normal(0.0, SE_BETA) if shared else np.zeros(2)
    friction = _law(v) + g @ d_beta + rng.normal(0.0, noise, v.size)
    return _fs(v, friction, meta or {})


def _law_fit(samples: FrictionSamples):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(samples, "coulomb_viscous_asym", intervals="jacobian")


def _with_and_without(seed: int):
    """Samples with the shared error's record, and the law fitted to them with it and to
    the same frictions without it: ``(velocity, samples, with, without)``."""
    v = _velocity()
    samples = _samples(np.random.default_rng(seed), 0.002, _meta(v))
    return v, samples, _law_fit(samples), _law_fit(_fs(v, samples.friction))


def test_the_covariance_is_the_levels_regressors_through_beta():
    v = _velocity()
    s = _fs(v, _law(v), _meta(v))
    g = -np.array([lv["regressor"] for lv in _levels(v)])
    cov = np.array([[1.0, 0.3], [0.3, 1.0]]) * np.outer(SE_BETA, SE_BETA)
    np.testing.assert_allclose(shared_covariance(s), g @ cov @ g.T, rtol=1e-12)


def test_no_record_no_shared_error():
    v = _velocity()
    plain = _fs(v, _law(v))
    assert shared_covariance(plain) is None
    urdf = _fs(v, _law(v), _meta(v, identified=False))
    assert shared_covariance(urdf) is None
    broken = _meta(v)
    del broken["gravity"]["levels"][0]["regressor"]
    assert shared_covariance(_fs(v, _law(v), broken)) is None
    broken = _meta(v)
    broken["gravity"]["covariance"] = [[1.0]]
    assert shared_covariance(_fs(v, _law(v), broken)) is None


def test_a_sample_without_its_level_shares_nothing():
    """A row added by hand at a speed no level has gets no shared error (zero row)."""
    v = np.append(_velocity(), 1.6)
    meta = _meta(_velocity())
    s = _fs(v, _law(v), meta)
    cov = shared_covariance(s)
    assert cov.shape == (7, 7)
    assert np.all(cov[-1] == 0) and np.all(cov[:, -1] == 0)
    assert np.all(np.diag(cov)[:-1] > 0)


def test_an_undetermined_parameter_adds_nothing():
    v = _velocity()
    meta = _meta(v)
    meta["gravity"]["parameters"][1]["se"] = None
    s = _fs(v, _law(v), meta)
    g = -np.array([lv["regressor"] for lv in _levels(v)])
    np.testing.assert_allclose(shared_covariance(s), np.outer(g[:, 0], g[:, 0]) * SE_BETA[0] ** 2)


def test_intervals_widen_by_the_propagated_error_in_quadrature():
    """For the linear law the propagation is exact: the standard error is hypot(se',
    sd_shared), sd_shared from X^+ G Sigma G^T X^+T and se' the plain fit's scaled by the
    residual variance's own share (SSE - tr((I - H) G Sigma G^T)) / SSE, and the interval's
    half-width t_eff times it, t_eff with the Welch-Satterthwaite degrees of freedom."""
    v, samples, a, b = _with_and_without(0)
    pos, neg = v > 0, v < 0
    X = np.zeros((v.size, 4))
    X[pos, 0], X[pos, 1] = 1.0, v[pos]
    X[neg, 2], X[neg, 3] = -1.0, v[neg]
    a_map = np.linalg.pinv(X)
    sigma = shared_covariance(samples)
    extra = a_map @ sigma @ a_map.T
    resid = samples.friction - X @ (a_map @ samples.friction)
    seen = np.trace((np.eye(v.size) - X @ a_map) @ sigma)
    assert 0 < seen < resid @ resid
    own = (resid @ resid - seen) / (resid @ resid)
    names = ["f_c_pos", "beta_pos", "f_c_neg", "beta_neg"]
    dof = v.size - 4
    for k, name in enumerate(names):
        pa, pb = a.parameters[name], b.parameters[name]
        total = own * pb.stderr**2 + extra[k, k]
        t_eff = stats.t.ppf(0.975, dof * (total / (own * pb.stderr**2)) ** 2)
        assert pa.value == pytest.approx(pb.value, rel=1e-9)
        assert pa.stderr == pytest.approx(np.sqrt(total), rel=1e-5)
        half = max(t_eff * np.sqrt(total), pb.ci95_halfwidth)  # never shorter
        assert pa.ci95_halfwidth == pytest.approx(half, rel=1e-5)
        if not pb.low_open:
            assert pa.ci95[0] == pytest.approx(pb.value - half, rel=1e-5)
    share = a.provenance["shared_error"]["variance_share"]
    assert set(share) == set(names) and share["f_c_pos"] > 0.9
    assert "shared_error" not in b.provenance


@pytest.mark.slow
def test_coverage_with_the_shared_error_is_nominal():
    """A Monte Carlo over 300 campaigns: a per-direction offset shared by every sample, which
    the residuals cannot show. Without the record the Coulomb levels' intervals miss it
    (below 80 %); with it they cover 90-98 %."""
    rng = np.random.default_rng(12)
    v = _velocity()
    hits = {"with": [], "without": []}
    for _ in range(300):
        s = _samples(rng, 0.001, _meta(v))
        bare = _fs(v, s.friction)
        for tag, data in (("with", s), ("without", bare)):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                f = fit(data, "coulomb_viscous_asym")
            hits[tag].extend(
                f.parameters[n].ci95[0] <= TRUTH[n] <= f.parameters[n].ci95[1]
                for n in ("f_c_pos", "f_c_neg")
            )
    assert 0.90 <= np.mean(hits["with"]) <= 0.98
    assert np.mean(hits["without"]) < 0.80


def test_the_levels_own_errors_floor_a_residual_variance_of_zero():
    """Samples that fit the law exactly (no spare sample in a direction: a trial's arm had
    two set-points left there) leave no residual scatter; the levels' own standard errors, as
    the arm's fit measured them, still count: se^2 = X^+ diag(own) X^+T + the shared part."""
    from fricid.identify.static.shared_error import own_variance

    v = _velocity()
    meta = _meta(v)
    level_se = 0.02  # noise and shared part together, as the arm fit records it
    for lv in meta["gravity"]["levels"]:
        lv["friction_se"] = level_se
    exact = _fs(v, _law(v), meta)
    sigma = shared_covariance(exact)
    own = own_variance(exact, sigma)
    np.testing.assert_allclose(own, level_se**2 - np.diag(sigma))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = fit(exact, "coulomb_viscous_asym", intervals="jacobian")
    pos, neg = v > 0, v < 0
    X = np.zeros((v.size, 4))
    X[pos, 0], X[pos, 1] = 1.0, v[pos]
    X[neg, 2], X[neg, 3] = -1.0, v[neg]
    a_map = np.linalg.pinv(X)
    want = np.diag(a_map @ (np.diag(own) + sigma) @ a_map.T)
    for k, name in enumerate(["f_c_pos", "beta_pos", "f_c_neg", "beta_neg"]):
        p = f.parameters[name]
        assert p.stderr == pytest.approx(np.sqrt(want[k]), rel=1e-4), name
        # both parts known, not estimated: the normal point
        assert p.ci95_halfwidth == pytest.approx(stats.norm.ppf(0.975) * p.stderr, rel=1e-4)


def test_the_prediction_interval_adds_the_shared_error_unscaled():
    """The model file keeps the shared part of the parameters' covariance apart; the
    prediction interval's variance gains exactly ``g^T S g`` over the same fit without the
    record (the residual-based part and its multiplier are the plain fit's)."""
    from fricid.fitted import FittedModel
    from fricid.fitted._interval import _delta_multiplier, gradient

    _, _, a, b = _with_and_without(3)
    rec = a.prediction_interval
    S = np.asarray(rec["shared_covariance"])
    assert S.shape == (4, 4) and np.all(np.diag(S) > 0)
    assert "shared_covariance" not in b.prediction_interval
    X = np.column_stack([np.array([0.3, 0.6, -0.3, -0.6]), np.zeros((4, 2))])
    theta = np.array([a.parameters[n].value for n in a.parameters])
    G = gradient(a.model, theta, rec["free"], X)
    gsg = np.einsum("pn,pq,qn->n", G, S, G)
    # the same record without the shared part gives the plain rule's half-width
    bare = FittedModel.from_dict(
        {
            **a.to_dict(),
            "prediction_interval": {k: val for k, val in rec.items() if k != "shared_covariance"},
        }
    )
    h_with = a.predict_interval(X, warn=False).half_width
    h_without = bare.predict_interval(X, warn=False).half_width
    assert np.all(h_with > h_without)
    # exactly g^T S g more in the variance the rule's multiplier applies to (samples
    # without a measured scatter: the delta rule, s the residual standard deviation)
    assert "local" not in rec and "noise_floor" not in rec
    s2 = rec["noise_std"] ** 2
    var = np.einsum("pn,pq,qn->n", G, np.asarray(rec["covariance"]), G) + s2
    k = _delta_multiplier(rec, 0.95)
    np.testing.assert_allclose(h_without, k * np.sqrt(var), rtol=1e-9)
    np.testing.assert_allclose(h_with, k * np.sqrt(var + gsg), rtol=1e-9)
    assert np.all(gsg > s2)  # the shared part dominates here: the interval is wider by it


ASYMMETRIC = (np.eye(4) * 1e-4 + np.triu(np.ones((4, 4)), 1) * 1e-4).tolist()
INDEFINITE = (np.eye(4) * 1e-4 + (np.ones((4, 4)) - np.eye(4)) * 2e-4).tolist()


@pytest.mark.parametrize(
    "bad", [[[1.0]], [[np.nan] * 4] * 4, (-np.eye(4)).tolist(), "abc", ASYMMETRIC, INDEFINITE]
)
def test_a_malformed_shared_covariance_is_refused(bad):
    from fricid.errors import ConfigError, DataError
    from fricid.fitted import FittedModel

    a = _law_fit(_samples(np.random.default_rng(4), 0.002, _meta(_velocity())))
    d = a.to_dict()
    d["prediction_interval"] = {**d["prediction_interval"], "shared_covariance": bad}
    with pytest.raises((ConfigError, DataError), match="shared_covariance"):
        # refused when read (a number that is not finite) or when used (its shape or sign)
        FittedModel.from_dict(d).predict_interval(np.array([[0.3, 0.0, 0.0]]), warn=False)


def test_predict_names_the_file_and_says_a_no_verdict(tmp_path):
    """`fricid predict`: a malformed shared_covariance is refused naming the model file; a
    model whose own check says 'no' is predicted with a warning saying so."""
    from typer.testing import CliRunner

    from fricid.cli import app
    from fricid.fitted import FittedModel

    a = _law_fit(_samples(np.random.default_rng(5), 0.002, _meta(_velocity())))
    d = a.to_dict()
    d["prediction_interval"] = {**d["prediction_interval"], "shared_covariance": INDEFINITE}
    bad = FittedModel.from_dict(d).save(tmp_path / "bad.json")
    args = ["-v", "0.3", "--interval", "0.95"]
    res = CliRunner().invoke(app, ["predict", str(bad), *args])
    assert res.exit_code == 2
    assert "bad.json" in res.output and "shared_covariance" in res.output
    d = a.to_dict()
    d["trust"] = {**(d.get("trust") or {}), "level": "no", "reasons": ["misses the law"]}
    untrusted = FittedModel.from_dict(d).save(tmp_path / "no.json")
    res = CliRunner().invoke(app, ["predict", str(untrusted), *args])
    assert res.exit_code == 0, res.output
    assert "trust verdict is 'no' (misses the law)" in res.stderr


def test_a_no_verdicts_reasons_are_never_cut_short(tmp_path):
    """`fricid predict` cut the reasons at 300 characters, and a parameter's name after a
    long first reason was lost ("not bounded by the data: )"): whole reasons, then how many
    more the file gives; an export refused for it likewise."""
    from typer.testing import CliRunner

    from fricid.cli import app
    from fricid.export import ExportError, refuse_untrusted
    from fricid.fitted import FittedModel

    d = _law_fit(_samples(np.random.default_rng(5), 0.002, _meta(_velocity()))).to_dict()
    first = "the log's velocity is not its position's derivative: " + "a long reason " * 17
    named = "not bounded by the data: tau_s"
    reasons = [first.strip(), named, "misses by 1.38x", "gravity may be left in " * 10]
    d["trust"] = {**(d.get("trust") or {}), "level": "no", "reasons": reasons}
    model = FittedModel.from_dict(d)
    res = CliRunner().invoke(app, ["predict", str(model.save(tmp_path / "no.json")), "-v", "0.3"])
    assert res.exit_code == 0, res.output
    said = " ".join(res.stderr.split())
    assert f"{first.strip()}; {named}; misses by 1.38x; 1 more in the model file)" in said
    d["trust"]["reasons"] = ["word " * 200, named]
    with pytest.raises(ExportError) as err:
        refuse_untrusted(FittedModel.from_dict(d), allow=False)
    assert "word ...; 1 more in the model file" in str(err.value)


def test_the_report_band_says_why_it_is_missing_and_names_the_shared_error():
    from fricid.fitted import FittedModel
    from fricid.report.band import prediction_band_figure
    from fricid.report.document import Figure, Note

    rng = np.random.default_rng(6)
    v = _velocity()
    samples = _samples(rng, 0.002, _meta(v))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a = fit(samples, "coulomb_viscous_asym", intervals="jacobian")
    good = prediction_band_figure(a, samples, "rad/s")
    assert isinstance(good, Figure) and "error every sample shares" in good.caption
    d = a.to_dict()
    d["prediction_interval"] = {**d["prediction_interval"], "shared_covariance": ASYMMETRIC}
    note = prediction_band_figure(FittedModel.from_dict(d), samples, "rad/s")
    assert isinstance(note, Note) and note.kind == "warning" and "shared_covariance" in note.text
    d["prediction_interval"] = None
    assert prediction_band_figure(FittedModel.from_dict(d), samples, "rad/s") is None


def _measured(v: np.ndarray, friction: np.ndarray, std: float = 0.02) -> FrictionSamples:
    """Samples each the mean of 400 with ``std`` (a standard error of std / 20), with the
    shared gravity error's record."""
    n = v.size
    return FrictionSamples(
        v, None, 25.0, friction, count=np.full(n, 400), std=np.full(n, std), meta=_meta(v)
    )


def _with_scatter(meta: dict, se: float) -> dict:
    for lv in meta["gravity"]["levels"]:
        lv["friction_se"] = se
    return meta


def test_the_verdict_counts_the_shared_error_in_the_scatter_and_grades_no_leverage():
    """Six samples (three speeds a direction) and a correct per-direction law: random folds
    that cannot all be fitted are not graded (the one fold left predicts from two samples a
    direction: its error is leverage), and the scatter graded against includes the shared
    error, as much as the trace formula gives; a wrong (symmetric) law is still 'no'."""
    from fricid.identify._heldout import shared_mse
    from fricid.identify.trust import assess_trust

    rng = np.random.default_rng(0)
    v = _velocity()
    noisy = _samples(rng, 0.002, _with_scatter(_meta(v), 0.002))
    # each sample the mean of 400 with std 0.04: a standard error of 0.002, the noise's
    samples = FrictionSamples(
        v,
        None,
        25.0,
        noisy.friction,
        count=np.full(v.size, 400),
        std=np.full(v.size, 0.04),
        meta=noisy.meta,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        right = fit(samples, "coulomb_viscous_asym")
        wrong = fit(samples, "coulomb_viscous")
        t = assess_trust(right, samples)
        w = assess_trust(wrong, samples)
    assert t.level != "no", t.reasons
    assert "not graded" in t.validation_note
    S = shared_covariance(samples)
    pos, neg = v > 0, v < 0
    X = np.zeros((v.size, 4))
    X[pos, 0], X[pos, 1] = 1.0, v[pos]
    X[neg, 2], X[neg, 3] = -1.0, v[neg]
    B = np.eye(v.size) - X @ np.linalg.pinv(X)
    expected = np.trace(B @ S @ B.T) / v.size
    assert shared_mse(right, samples, None) == pytest.approx(expected, rel=1e-4)
    assert t.shared_rms == pytest.approx(np.sqrt(expected), rel=1e-4)
    assert w.level == "no"


def test_a_miss_the_shared_error_explains_is_a_caveat_never_a_pass():
    """A symmetric law on samples whose per-direction Coulomb levels differ by less than the
    shared gravity error can offset: the miss of the measurement scatter stands (never
    'yes'), but the samples cannot tell it from the shared error, and the verdict says so
    ('with caveats'), not 'no'."""
    from fricid.identify.trust import assess_trust

    rng = np.random.default_rng(1)
    v = _velocity()
    g = -np.array([lv["regressor"] for lv in _levels(v)])
    law = np.where(v > 0, 0.10 + 0.08 * v, -(0.088 + 0.08 * -v))  # 0.012 N m asymmetric
    friction = law + g @ rng.normal(0.0, SE_BETA) + rng.normal(0.0, 0.001, v.size)
    samples = _measured(v, friction)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sym = fit(samples, "coulomb_viscous")
        t = assess_trust(sym, samples)
    assert t.heldout_ratio > 3.0  # it misses the measurement scatter
    assert t.level == "with caveats", t.reasons
    assert any("cannot tell a misfit of this law" in r for r in t.reasons)


def test_an_oversized_matrix_is_refused_before_the_schema_walks_it(tmp_path):
    """The schema's size limits on named fields are checked first: a covariance of more
    rows than it allows is refused naming the field (before, the schema's own walk
    descended into every item: 31 s for 1500 x 1500)."""
    import json

    from fricid.errors import DataError
    from fricid.fitted import FittedModel

    a = _law_fit(_samples(np.random.default_rng(7), 0.002, _meta(_velocity())))
    d = json.loads(json.dumps(a.to_dict()))
    d["prediction_interval"]["shared_covariance"] = [[0.0]] * 1001
    path = tmp_path / "big.json"
    path.write_text(json.dumps(d))
    with pytest.raises(DataError, match=r"prediction_interval/shared_covariance.*more than 1000"):
        FittedModel.load(path)


def test_a_shared_error_larger_than_the_scatter_is_never_a_pass():
    """A law within the measurement scatter on samples whose shared error is larger than it:
    a misfit of that size would not show, so 'with caveats', saying so."""
    from fricid.identify.trust import assess_trust

    rng = np.random.default_rng(2)
    v = _velocity()
    law = np.sign(v) * (0.10 + 0.08 * np.abs(v))  # symmetric: coulomb_viscous is right
    friction = law + rng.normal(0.0, 0.0005, v.size)  # this draw of the shared error: 0
    samples = _measured(v, friction)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t = assess_trust(fit(samples, "coulomb_viscous"), samples)
    assert t.heldout_ratio <= 1.2 and t.shared_rms > t.scatter
    assert t.level == "with caveats", t.reasons
    assert any("share an error larger than their scatter" in r for r in t.reasons)
