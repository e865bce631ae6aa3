"""Issue 11, defects 5, 6 and 7: convergence said plainly, least squares that start anywhere
in the box, and intervals that can be true (API and CLI).

Made from issue 11's reproduction scripts ``defect_5.py``, ``defect_6.py`` and
``defect_7.py``: each test failed on the code before the fix (``lm`` = MINPACK in sin
coordinates; no convergence check; Wald intervals outside the box).
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

from _coverage import fewest_trials, gate
from _paths import TEST_DATA
from fricid.cli import app
from fricid.errors import ConvergenceWarning, FricidWarning, IdentifiabilityWarning
from fricid.extract import extract
from fricid.fitted import FittedModel
from fricid.identify import IdentificationProblem, fit
from fricid.identify.static.profile import profile_intervals, profile_threshold
from fricid.io import epos_steady_samples, write_samples
from fricid.models import get_model
from fricid.sim import preset, simulate

#: The paper2 preset's true Stribeck law (RWSAVSBAS paper eq. 7 with delta = 1).
PAPER2_TRUTH = {"tau_c": 0.084, "tau_s": 0.641, "w_s": 0.066, "tau_v": 0.0026}

#: A single start "reaches the optimum" when its SSE is within this factor of the best SSE.
AT_OPTIMUM = 1.001

#: Model files written by fricid's schema version 1 (tests/data/model_files_v1/README.md).
V1_FILES = TEST_DATA / "model_files_v1"


def _samples(name: str, size: str, seed: int = 0):
    scenario = preset(name, size)
    return extract(simulate(scenario, seed=seed), **scenario.extract_options()).samples


@pytest.fixture(scope="module")
def paper2():
    return _samples("paper2", "reduced")


@pytest.fixture(scope="module")
def paper1():
    return _samples("paper1", "quick")


@pytest.fixture(scope="module")
def leadscrew(leadscrew_dir):
    return epos_steady_samples(leadscrew_dir)


def quiet_fit(*args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FricidWarning)
        return fit(*args, **kw)


def optimum(samples, model: str) -> float:
    """The best SSE of a generous 16-start fit (the reference of the start tests)."""
    return quiet_fit(samples, model, "lm", options={"n_starts": 16}, max_evals=80_000).metrics[
        "sse"
    ]


def box_starts(samples, model: str, n_corners: int, n_random: int, seed: int = 1):
    """Middle, lower and upper bound, ``n_corners`` corners (all 2^d if fewer), random points."""
    b = get_model(model).bounds(samples.X, samples.y)
    lo, hi = b[:, 0], b[:, 1]
    d = lo.size
    starts = {"middle": 0.5 * (lo + hi), "lower": lo.copy(), "upper": hi.copy()}
    rng = np.random.default_rng(seed)
    if 2**d <= n_corners:
        bits = (np.arange(2**d)[:, None] >> np.arange(d)) & 1
    else:
        bits = rng.integers(0, 2, size=(n_corners, d))
    for k, c in enumerate(bits):
        starts[f"corner{k}"] = np.where(c, hi, lo)
    for k in range(n_random):
        starts[f"random{k}"] = lo + rng.random(d) * (hi - lo)
    return starts


# -- defect 6: lm from anywhere in the box -------------------------------------------------------


@pytest.mark.slow  # 22 s measured under load (default run kept short)
@pytest.mark.parametrize(
    ("data", "model", "n_corners", "n_random", "single_ok"),
    [
        # every corner of the 5-d box; the 8 corners with w_s at its lower bound and delta at
        # its upper one are degenerate: exp(-(v / w_s)^delta) underflows to 0 at every
        # sample, so w_s and delta have no gradient (measured: those 8 fail alone, 0 others)
        ("paper2", "stribeck", 32, 4, 0.75),
        # some corners of vlt's 8-d box lead one start to a local optimum (49x): measured 8/12
        ("paper1", "vlt", 6, 3, 0.6),
        ("leadscrew", "stribeck_asym", 8, 4, 0.6),  # local optima per direction too
    ],
)
def test_lm_reaches_the_optimum_from_starts_all_over_the_box(
    request, data, model, n_corners, n_random, single_ok
):
    """Every start, middle and bounds included: one start alone never stalls (the old lm
    stopped after about a dozen evaluations at 1e4-1e5x the optimum from mid-box), the middle
    reaches the optimum alone, most single starts do, and the default multi-start fit from
    every start does (a start in a degenerate region, such as the all-lower start of a
    Stribeck model, model identically 0, cannot move; the other starts rescue it)."""
    samples = request.getfixturevalue(data)
    m = get_model(model)
    best = optimum(samples, model)
    single, multi = {}, {}
    for name, x in box_starts(samples, model, n_corners, n_random).items():
        x0 = dict(zip(m.param_names, x, strict=True))
        one = quiet_fit(samples, model, "lm", x0=x0, options={"n_starts": 1}, max_evals=5000)
        single[name] = one.metrics["sse"] / best
        if single[name] > AT_OPTIMUM:
            nfev = one.optimizer.nfev
            assert nfev >= 50 or single[name] < 1.5, (name, nfev, single[name])
            multi[name] = quiet_fit(samples, model, "lm", x0=x0).metrics["sse"] / best
    assert single["middle"] <= AT_OPTIMUM, single
    ok = np.mean([r <= AT_OPTIMUM for r in single.values()])
    assert ok >= single_ok, single
    assert all(r <= AT_OPTIMUM for r in multi.values()), multi


def test_lm_is_the_bounded_trust_region_and_minpack_still_stalls(paper2):
    """The documented cause: MINPACK in sin coordinates from mid-box (kept as lm_minpack)."""
    m = get_model("stribeck")
    b = m.bounds(paper2.X, paper2.y)
    x0 = dict(zip(m.param_names, b.mean(axis=1), strict=True))
    best = optimum(paper2, "stribeck")
    old = quiet_fit(paper2, "stribeck", "lm_minpack", x0=x0, options={"n_starts": 1})
    new = quiet_fit(paper2, "stribeck", "lm", x0=x0, options={"n_starts": 1})
    assert old.metrics["sse"] > 100 * best and old.optimizer.nfev < 50
    assert new.metrics["sse"] <= AT_OPTIMUM * best


# -- defect 5: budget spent, no word --------------------------------------------------------------


def test_bas_far_from_the_optimum_warns_and_gives_no_interval(paper2, tmp_path):
    with pytest.warns(
        ConvergenceWarning,
        match=r"polish .* reaches .* % lower: the parameters move by .* standard errors"
        r".*\); use --method bas\+lm",
    ):
        f = fit(paper2, "stribeck", "bas")
    conv = f.convergence
    assert conv["converged"] is False and f.converged is False
    assert conv["polish_sse_ratio"] < 0.01 and f.optimizer.nfev == 3001
    assert f.optimizer.max_evals == 3001 and "advice" in conv and "reason" in conv
    assert not {"status", "message", "nfev", "max_evals"} & set(conv)  # stored once
    for p in f.parameters.values():
        assert np.isnan(p.stderr) and np.isnan(p.ci95_halfwidth) and not p.has_interval
        assert "did not converge" in p.note and not p.not_determined
    text = f.report()
    assert text.startswith("NOT CONVERGED:") and "95 % CI" not in text
    g = FittedModel.load(f.save(tmp_path / "bas.json"))  # validated against the schema
    assert g.convergence["converged"] is False and g.report() == text
    assert np.isnan(g.parameters["tau_c"].ci95[0])


def test_converged_fit_is_certified_and_keeps_its_intervals(paper2):
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConvergenceWarning)
        f = fit(paper2, "stribeck", "lm")
    assert f.converged and f.convergence["certified_by"] == "optimizer"
    assert f.convergence["polish_sse_ratio"] == pytest.approx(1.0, abs=1e-6)
    assert "converged (certified" in f.report()
    assert all(p.has_interval for p in f.parameters.values())


def test_budget_spent_before_the_optimum_is_not_converged(paper2):
    with pytest.warns(ConvergenceWarning, match="raise --max-evals"):
        f = fit(paper2, "stribeck", "lm", max_evals=40)
    assert not f.converged and f.optimizer.status == 1
    assert f.optimizer.max_evals == 40 and np.isnan(f.parameters["tau_c"].stderr)


@pytest.mark.slow  # 4 s measured under load (default run kept short)
def test_vlt_from_the_upper_corner_converges_within_the_default_budget(paper1):
    """defect_5.py case B: the old lm spent its whole 20 000 and stopped at 2.37x."""
    m = get_model("vlt")
    hi = m.bounds(paper1.X, paper1.y)[:, 1]
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConvergenceWarning)
        f = fit(paper1, "vlt", "lm", x0=dict(zip(m.param_names, hi, strict=True)))
    assert f.converged and f.optimizer.nfev < 20_000
    assert f.metrics["sse"] <= AT_OPTIMUM * optimum(paper1, "vlt")


def test_leadscrew_stribeck_asym_converges_and_says_so(leadscrew):
    """defect_5.py case C: the old lm spent its budget and recorded nothing."""
    f = quiet_fit(leadscrew, "stribeck_asym", "lm")
    assert f.converged and f.optimizer.status == 0 and f.optimizer.nfev < 20_000


def test_cli_fit_bas_says_not_converged(paper2, tmp_path):
    path = write_samples(paper2, tmp_path / "p2.csv")
    res = CliRunner().invoke(
        app, ["fit", str(path), "--method", "bas", "--out", str(tmp_path / "m.json")]
    )
    assert res.exit_code == 0, res.output
    # the CLI shows the ConvergenceWarning as one line on stderr (DESIGN.md, "Errors")
    lines = [ln for ln in res.stderr.splitlines() if ln.startswith("warning (convergence)")]
    assert len(lines) == 1, res.stderr
    assert "NOT CONVERGED" in res.output and "95 % CI" not in res.output
    saved = json.loads((tmp_path / "m.json").read_text())
    assert saved["convergence"]["converged"] is False
    assert saved["parameters"]["tau_c"]["ci95"] == [None, None]


# -- defect 7: intervals that can be true ---------------------------------------------------------


def _inside_box(f: FittedModel) -> None:
    for name, p in f.parameters.items():
        if p.bounds is None:
            continue
        (lo, hi), (low, high) = p.bounds, p.ci95
        if np.isfinite(low):
            assert lo <= low <= p.value <= high <= hi, (name, low, high, lo, hi)


def test_leadscrew_symmetric_stribeck_names_what_the_data_cannot_identify(leadscrew):
    """The issue's `w_s 0.024 +- 23.5 rad/s`, `delta 0.2 +- 34`: wider than the box. Now
    every interval lies in the box, and w_s and delta are named as not identified."""
    with pytest.warns(IdentifiabilityWarning, match=r"do not bound w_s .*delta") as rec:
        f = fit(leadscrew, "stribeck", "lm")
    assert f.ci_method == "profile"
    _inside_box(f)
    for name in ("w_s", "delta"):
        p = f.parameters[name]
        assert p.low_open and p.high_open and p.not_determined
        assert "not identified" in p.note
    assert "correlated with" in str(rec[0].message)
    # the Jacobian's intervals, asked for, are cut at the box and flagged there
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FricidWarning)
        g = fit(leadscrew, "stribeck", "lm", intervals="jacobian")
    assert g.ci_method == "jacobian"
    _inside_box(g)
    assert g.parameters["w_s"].low_open and g.parameters["w_s"].high_open


def test_leadscrew_per_direction_profile_finds_the_open_side(leadscrew):
    """Positive direction: no Coulomb plateau below the top speed, so w_s_pos is bounded
    below only (profile reaches the 20.8 rad/s bound); the negative side is identified."""
    with pytest.warns(IdentifiabilityWarning, match=r"do not bound w_s_pos \(reaches the bound"):
        f = fit(leadscrew, "stribeck_asym", "lm", intervals="profile")
    _inside_box(f)
    pos = f.parameters["w_s_pos"]
    assert not pos.low_open and pos.high_open
    assert pos.ci95[1] == pytest.approx(pos.bounds[1])
    for name in ("tau_c_neg", "tau_s_neg", "w_s_neg", "delta_neg"):
        assert not f.parameters[name].low_open and not f.parameters[name].high_open, name
    # the profile interval is asymmetric where the model is nonlinear in the parameter
    neg = f.parameters["w_s_neg"]
    assert neg.ci95[1] - neg.value > 1.3 * (neg.value - neg.ci95[0])
    assert "reaches the bound w_s_pos <= 20.84 rad/s" in f.report()


def test_degenerate_optimum_gets_no_interval(paper2):
    """One lm start at the corner with w_s at its lower bound and delta at its upper one:
    exp(-(v / w_s)^delta) underflows to 0 at every sample, so tau_s, w_s and delta have no
    effect; the start ends on that plateau (a stationary point, certified by the polish) far
    from the optimum. Linearised intervals there are the issue's `Coulomb 2e-10 +- 210 N m`:
    no interval at all, and the warning names what has no effect."""
    m = get_model("stribeck")
    b = m.bounds(paper2.X, paper2.y)
    x0 = dict(zip(m.param_names, b[:, 0], strict=True))
    x0["delta"] = b[-1, 1]
    with pytest.warns(IdentifiabilityWarning, match="degenerate optimum") as rec:
        f = fit(paper2, "stribeck", "lm", x0=x0, options={"n_starts": 1})
    assert f.metrics["sse"] > 100 * optimum(paper2, "stribeck")
    msgs = " ".join(str(w.message) for w in rec)
    assert "w_s has no effect" in msgs and "delta has no effect" in msgs
    assert all(np.isnan(p.ci95[0]) and np.isnan(p.stderr) for p in f.parameters.values())
    assert all("degenerate" in p.note or "not determined" in p.note for p in f.parameters.values())
    assert "+/-" not in f.report() and "95 % CI" not in f.report()


def test_profile_interval_matches_the_threshold(paper2):
    """At each closed end the profiled SSE equals the F threshold (to the bisection's
    resolution), and the estimate lies inside."""
    f = quiet_fit(paper2, "stribeck", "lm", fixed={"delta": 1.0})
    problem = IdentificationProblem(get_model("stribeck"), paper2, fixed={"delta": 1.0})
    x = np.array([f.params[n] for n in problem.free_names])
    thr = profile_threshold(f.metrics["sse"], problem.n_obs, problem.n_free)
    prof = profile_intervals(problem, x, which=[0])
    iv = prof["tau_c"]
    assert not iv.low_open and not iv.high_open
    for end in (iv.low, iv.high):
        g = quiet_fit(
            paper2, "stribeck", "lm", fixed={"delta": 1.0, "tau_c": end}, options={"n_starts": 4}
        )
        assert g.metrics["sse"] == pytest.approx(thr, rel=0.02)


@pytest.mark.slow
def test_profile_intervals_cover_the_truth_on_the_virtual_joint():
    """paper2 preset (the Stribeck law with delta = 1 is the truth), seeds x 4 parameters: as
    few seeds as still tell calibrated 95 % intervals from ones covering 80 %
    (:func:`_coverage.fewest_trials`: 69 trials, so 18 seeds; their 72 trials' pass mark is
    64: a calibrated method fails 1 % of the time at most, one covering 80 % passes 5 % at
    most). Slow but bounded: about 3 s a seed."""
    trials, _ = fewest_trials()
    seeds = -(-trials // len(PAPER2_TRUTH))
    covered = 0
    for seed in range(seeds):
        samples = _samples("paper2", "reduced", seed)
        f = quiet_fit(samples, "stribeck", "lm", fixed={"delta": 1.0}, seed=seed)
        assert f.converged and f.ci_method == "profile"
        ends = {k: f.parameters[k].ci95 for k in PAPER2_TRUTH}
        covered += sum(ends[k][0] <= v <= ends[k][1] for k, v in PAPER2_TRUTH.items())
    assert covered >= gate(seeds * len(PAPER2_TRUTH))[0], covered


def test_a_file_without_the_new_fields_loads_and_reports_as_before(tmp_path):
    """Old model files (schema version 1 without a convergence block or interval ends) still
    load and print their half-width intervals."""
    d = json.loads((V1_FILES / "stribeck.json").read_text())
    for key in ("convergence", "ci95_low", "ci95_high", "ci_open", "ci_method", "uncertainty_note"):
        d.pop(key)
    path = tmp_path / "old.json"
    path.write_text(json.dumps(d))
    g = FittedModel.load(path)
    assert g.convergence is None and g.converged is None
    assert not any(p.has_interval for p in g.parameters.values())
    text = g.report()
    assert "NOT CONVERGED" not in text and "# convergence" not in text
    assert f"95 % CI +/- {d['ci95']['tau_c']:.3g}" in text
    assert g.parameters["tau_c"].ci95_halfwidth == d["ci95"]["tau_c"]
