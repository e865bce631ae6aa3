"""Issue 15, trust of the learned models: what their files record (convergence, effective
degrees of freedom, the held-out error of the chosen settings), what ``fricid fit`` prints and
the report's verdict; and what to do about a model that misses the data (every family)."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

from _synthetic import averaged_samples
from fricid.cli import app
from fricid.fitted import FittedModel
from fricid.identify import fit
from fricid.identify._scatter import measurement_scatter
from fricid.identify.learned._trust import CV_SOURCE, hat_trace, learned_statistics
from fricid.identify.learned.rbf import RBFNetRegressor
from fricid.identify.trust import LOVO_INTERIOR, OWN_CV, RUN_HERE, assess_trust
from fricid.io import write_samples
from fricid.samples import FrictionSamples


def _samples(seed: int = 0, noise: float = 1e-3, reps: int = 3) -> FrictionSamples:
    """A Stribeck-like joint: 8 speeds from 0.01 to 1 rad/s, 3 temperatures, ``reps``
    repeats, noise ``noise`` N m (known to the samples through std and count)."""
    rng = np.random.default_rng(seed)
    v = np.repeat(np.geomspace(0.01, 1.0, 8), 3 * reps)
    temp = np.tile(np.repeat([20.0, 30.0, 40.0], reps), 8)
    f = 0.1 + 0.05 * np.exp(-((v / 0.05) ** 2)) + 0.05 * v + 0.0005 * (temp - 30)
    return averaged_samples(v, temp, f, noise, rng)


@pytest.fixture(scope="module")
def samples():
    return _samples()


@pytest.fixture(scope="module")
def rbf(samples):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(samples, "rbf")


@pytest.fixture(scope="module")
def gp(samples):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(samples, "gp")


# -- effective degrees of freedom (finding c) ---------------------------------------------------


@pytest.mark.slow  # 2 s measured under load (default run kept short)
@pytest.mark.parametrize(
    "options",
    [{"alpha": 1e-5}, {"alpha": 1e-5, "linear_tail": True}, {"alpha": 1e-3, "fit_bias": False}],
)
def test_hat_trace_is_the_trace_of_the_fitted_map(options):
    # the hat matrix column by column: the network refitted to each unit target (k-means does
    # not see the targets, so the hidden layer is the same)
    rng = np.random.default_rng(1)
    X = rng.uniform(size=(40, 2))
    y = np.sin(3 * X[:, 0]) + X[:, 1]
    est = RBFNetRegressor(8, random_state=0, **options).fit(X, y)
    H = np.column_stack(
        [RBFNetRegressor(8, random_state=0, **options).fit(X, e).predict(X) for e in np.eye(40)]
    )
    assert hat_trace(est, X) == pytest.approx(np.trace(H), rel=1e-8)
    assert hat_trace(RBFNetRegressor(8, trainer="bas").set_params(), X) is None


@pytest.mark.parametrize("exact", [True, False])
def test_gp_smoother_trace_is_the_trace_of_the_posterior_mean_map(exact):
    from fricid.identify.learned import _gp_posterior as G

    rng = np.random.default_rng(0)
    Z = rng.normal(size=(50, 2))
    A = np.column_stack([np.ones(50), Z[:, 0]])
    P = Z if exact else Z[:15]
    args = (np.array([0.8, 1.3]), 1.2, 0.05, exact)
    alpha, _, _, _, dbeta = G._posterior(P, Z, np.eye(50), A, *args)
    S = A @ dbeta + G._kernel_matrix(Z, P, args[0], args[1]) @ alpha
    assert G._smoother_trace(P, Z, A, *args) == pytest.approx(np.trace(S), rel=1e-6)


def test_learned_statistics_count_effective_dof(rbf, gp, samples):
    for fitted in (rbf, gp):
        st = fitted.statistics
        assert "nvarys" not in st and "nfree" not in st
        assert 1 < st["nvarys_effective"] < len(samples) / 2
        assert st["nfree_effective"] == pytest.approx(len(samples) - st["nvarys_effective"])
        assert np.isfinite(st["redchi"]) and np.isfinite(st["aic"]) and np.isfinite(st["bic"])
        assert "effective degrees of freedom" in fitted.statistics_note
    assert "ESL eq. 3.50" in rbf.statistics_note and "R&W" in gp.statistics_note
    assert "(effective)" in rbf.report() and "# statistics" in rbf.report()
    # undefined: none of the numbers that would need it
    st, note = learned_statistics(samples.y, samples.y * 0.99, None, "searched")
    assert set(st) == {"ndata", "chisqr", "rsquared"} and note.startswith("no AIC, BIC")


# -- convergence and held-out error in the file (finding b) -------------------------------------


def test_learned_files_record_convergence_and_their_cv(rbf, gp, samples, tmp_path):
    assert rbf.converged and rbf.convergence["certified_by"] == "closed_form"
    assert gp.optimizer.nfev > 0 and "nfev" not in gp.convergence  # stored once
    assert gp.converged == (gp.convergence["certified_by"] == "optimizer")

    v = rbf.validation
    # 8 speeds: the 4 interior levels held out whole (fricid.identify.learned._rbf_folds)
    assert v["source"] == CV_SOURCE and v["scheme"] == "levels:4"
    state = rbf.state["n_centers_selection"]
    assert v["rmse"] == pytest.approx(state["cv_rmse_levels_chosen"])
    # the samples repeat every operating point: the scatter between the repeated runs,
    # an estimate of the 1e-3 N m noise
    sc = measurement_scatter(samples)
    assert sc.method == "between repeated runs" and sc.value == pytest.approx(1e-3, rel=0.3)
    assert v["scatter"] == pytest.approx(sc.value)
    assert v["ratio"] == pytest.approx(v["rmse"] / sc.value)
    assert "between the measured speeds, not beyond them" in v["note"]
    from fricid.cli.fit import goodness_text

    assert "note: out-of-fold error of the settings" in goodness_text(rbf)
    back = FittedModel.load(rbf.save(tmp_path / "rbf.json"))
    assert back.validation == json.loads(json.dumps(rbf.to_dict()))["validation"]
    assert back.statistics_note == rbf.statistics_note


def test_gp_convergence_from_the_optimisers_status():
    from fricid.identify.learned._trust import process_convergence

    ok = {"starts": 3, "nfev": 40, "converged": True, "message": "CONVERGENCE"}
    bad = {**ok, "converged": False, "message": "ABNORMAL_TERMINATION_IN_LNSRCH"}
    assert process_convergence([ok], ["length scale near its bound"])["converged"]
    block = process_convergence([ok, bad], [])
    assert not block["converged"] and "ABNORMAL" in block["reason"] and "nfev" not in block


def test_optimiser_trainer_out_of_budget_is_not_converged(samples):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(
            samples,
            "rbf",
            "bas",
            max_evals=30,
            settings={"network": {"n_centers": 6, "target_mse": 1e-12}},
        )
    conv = fitted.convergence
    assert conv["converged"] is False and "budget" in conv["reason"]
    assert "--method lsq" in conv["advice"]
    assert "nvarys_effective" not in fitted.statistics  # centres searched: undefined
    assert fitted.validation is None  # the lsq CV does not describe the searched network


def test_hybrid_records_both_parts(samples):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(samples, "hybrid", settings={"backbone": "stribeck"})
    conv = fitted.convergence
    assert conv["converged"] and conv["backbone"]["converged"]
    assert "backbone" in fitted.report().split("# convergence")[1].splitlines()[0]
    p = len(fitted.state["backbone"]["params"])
    assert f"the backbone's {p} free parameters plus" in fitted.statistics_note
    assert fitted.validation["source"] == CV_SOURCE


def test_old_learned_files_still_load(rbf, tmp_path):
    d = rbf.to_dict()
    for key in ("statistics_note", "convergence", "validation", "loss"):
        d.pop(key)
    d["statistics"] = {"ndata": 96, "nvarys": 411, "nfree": -315, "chisqr": 1e-4}
    path = tmp_path / "old.json"
    path.write_text(json.dumps(d))
    old = FittedModel.load(path)
    assert old.converged is None and "# variables        = 411" in old.report()


# -- the report's verdict -----------------------------------------------------------------------


def test_report_verdict_of_a_learned_model_rests_on_lovo(gp, rbf, samples):
    trust = assess_trust(gp, samples)
    assert (trust.heldout_source, trust.heldout_scheme) == (RUN_HERE, LOVO_INTERIOR)
    assert "each retrained" in trust.validation_note
    # not run: the verdict falls back to the file's CV, with its caveat
    quick = assess_trust(rbf, samples, validate=False)
    assert (quick.heldout_source, quick.heldout_scheme) == (OWN_CV, "levels:4")
    assert "held out between the measured speeds only" in quick.line()
    assert "convergence is not recorded" not in quick.line()


# -- what to do (finding a) ---------------------------------------------------------------------


@pytest.mark.slow  # 3 s measured under load (default run kept short)
def test_cli_report_says_what_to_do_about_a_family_that_cannot_follow(samples, tmp_path):
    csv = write_samples(samples, tmp_path / "syn.csv")
    runner = CliRunner()
    res = runner.invoke(
        app, ["fit", str(csv), "--model", "coulomb_viscous", "--out", str(tmp_path / "cv.json")]
    )
    assert res.exit_code == 0, res.output
    res = runner.invoke(
        app, ["report", str(tmp_path / "cv.json"), str(csv), "--out", str(tmp_path / "r")]
    )
    assert res.exit_code == 0, res.output
    line = next(x for x in res.stderr.splitlines() if x.startswith("Trust:"))
    assert line.startswith("Trust: no, because the held-out error misses by")
    assert "What to do: the coulomb_viscous family cannot follow these data" in line
    assert "--model hybrid" in line and "--model auto --learned" in line


@pytest.mark.slow  # 8 s measured under load (default run kept short)
def test_cli_fit_prints_the_learned_models_held_out_error(samples, tmp_path):
    csv = write_samples(samples, tmp_path / "syn.csv")
    res = CliRunner().invoke(
        app, ["fit", str(csv), "--model", "gp", "--out", str(tmp_path / "gp.json"), "--quiet"]
    )
    assert res.exit_code == 0, res.output
    assert "(effective)" in res.stdout and "RMSE / scatter" in res.stdout
    assert "# convergence" in res.stdout
    res = CliRunner().invoke(
        app, ["report", str(tmp_path / "gp.json"), str(csv), "--out", str(tmp_path / "r")]
    )
    assert res.exit_code == 0, res.output
    line = next(x for x in res.stderr.splitlines() if x.startswith("Trust:"))
    # before: "with caveats, because convergence is not recorded in this model file; no
    # held-out validation (in-sample error only)"
    assert "not recorded" not in line and "in-sample error only" not in line
    assert "held-out error" in line or line.startswith("Trust: yes")


def test_misfit_advice_reads_in_sample_interior_and_end_folds(rbf, samples):
    from fricid.identify._advice import misfit_advice

    def folds(interior: float, ends: float) -> dict:
        speeds = np.geomspace(0.01, 1.0, 6)
        rows = [
            {"fold": k, "speed": v, "n": 10, "rmse": ends if k in (0, 5) else interior}
            for k, v in enumerate(speeds)
        ]
        return {"scheme": "lovo", "folds": rows}

    # rbf follows the set-points (in-sample under the threshold)
    gaps = misfit_advice(rbf, folds(10e-3, 10e-3), 1e-3, 3.0, samples)
    assert "not the velocity levels held out (interior folds 10x)" in gaps
    assert "up to 2.51x apart" in gaps and "--model auto --learned" in gaps
    ends = misfit_advice(rbf, folds(1e-3, 50e-3), 1e-3, 3.0, samples)
    assert "misses when the slowest or fastest level is held out" in ends
    assert "between 0.01 and 1 rad/s held up" in ends
