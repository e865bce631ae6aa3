"""Tests of the RWSAVSBAS study (fricid.experiments.stribeck_study) and ``fricid bench``."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares

from fricid.experiments import stribeck_study as study
from fricid.report.studies import stribeck as render


@pytest.fixture(scope="module")
def problem() -> study.StribeckProblem:
    v, y = study.paper2_samples(0)
    return study.StribeckProblem(v, y)


@pytest.mark.slow  # 6 s measured under load (default run kept short)
def test_paper2_samples_and_global_optimum(problem) -> None:
    assert problem.velocity.shape == problem.friction.shape == (17,)
    theta, f_opt = study.global_optimum(problem)
    assert 0.5e-4 < f_opt < 3e-4  # the preset is calibrated to the paper's 1.3e-4
    assert np.all(theta >= study.BOUNDS[:, 0]) and np.all(theta <= study.BOUNDS[:, 1])
    # no local search from the truth (Table 2 of the paper) does better
    truth = np.array([0.084, 0.641, 0.066, 0.0026])
    sol = least_squares(lambda t: problem.residuals(t[None])[0], truth, method="lm", xtol=1e-15)
    assert f_opt <= 2 * sol.cost * (1 + 1e-9)
    assert np.allclose(theta, truth, rtol=0.3)


def test_compiled_kernel_matches_the_model(problem) -> None:
    from fricid.models._kernels import loss_kernel
    from fricid.optim import JitObjective

    fast = problem.objective(jit=True)
    # numba is a dependency: a fallback to the NumPy objective here means its import broke
    assert isinstance(fast, JitObjective), "the compiled objective is missing: does numba import?"
    # one objective: the study runs the analytic models' loss kernel, not a copy of its own
    assert fast.jit_kernel is loss_kernel
    X = study.BOUNDS[:, 0] + np.random.default_rng(0).random((50, 4)) * np.diff(study.BOUNDS)[:, 0]
    out = np.empty(50)
    fast.jit_kernel(X, out, fast.jit_data)
    assert np.allclose(out, problem.sse(X), rtol=1e-12, atol=0)
    # calling the objective runs the same compiled kernel (what every method of the study gets)
    assert np.array_equal(fast(X), out)


def test_equal_budget_rows_come_first_and_share_the_budget() -> None:
    specs = study.method_specs(quick=True)
    groups = [s.group for s in specs]
    assert groups == sorted(groups, key=study.GROUPS.index)
    assert groups[0] == "equal budget" and specs[0].label == "RWSAVSBAS"
    # RWSAVSBAS's row runs its algorithm in Python, like every other method
    assert specs[0].options.get("jit") is False
    n_rws = 1 + 100 * 301
    for spec in specs[1:]:
        if spec.group == "equal budget":
            assert spec.max_evals == n_rws


def test_headline_is_computed_from_the_table() -> None:
    import pandas as pd

    table = pd.DataFrame(
        {
            "group": ["equal budget"] * 3 + ["paper budget"],
            "found": [8, 8, 3, 0],
            "runs": [8, 8, 8, 8],
            "evals": [301001, 301000, 301000, 3001],
        },
        index=["RWSAVSBAS", "VSBAS (equal evals)", "IBAS (equal evals)", "VSBAS"],
    )
    from types import SimpleNamespace

    text = render.headline(SimpleNamespace(table=table))
    assert text.startswith("at 301001 evaluations per run")
    assert "every run: RWSAVSBAS, VSBAS (equal evals);" in text
    assert "IBAS (equal evals) 3/8" in text and "is its budget" in text
    table.loc["VSBAS (equal evals)", "found"] = 7
    text = render.headline(SimpleNamespace(table=table))
    assert "VSBAS (equal evals) 7/8" in text and "is its budget" not in text


@pytest.mark.slow
def test_study_runs_and_writes_its_outputs(tmp_path) -> None:
    result = study.run_study(runs=1, quick=True, time_numpy=False, repeats=1)
    assert {"VSBAS", "IBAS", "RWSAVSBAS", "BAS", "GA (equal evals)", "CMA-ES (cma)"} <= set(
        result.table.index
    )
    assert result.table["objective"].nunique() == 1  # one objective code for every method
    assert result.table["group"].iloc[0] == "equal budget"
    assert result.table.loc["RWSAVSBAS", "max_ratio"] < 1.001
    assert result.table.loc["VSBAS", "paper_mean"] == 0.60
    assert bool(result.hybrid["bas+lm_found"].all())
    text = render.report_text(result)
    assert "RWSAVSBAS" in text and "ratio" in text
    assert text.index("the headline") < text.index("[R]'s methods at [R]'s budgets")
    paths = render.write_outputs(result, tmp_path / "out")
    assert all(p.exists() and p.stat().st_size > 0 for p in paths)
    assert paths[-1].read_bytes()[:4] == b"\x89PNG"


def test_cli_rejects_bad_runs() -> None:
    from typer.testing import CliRunner

    from fricid.cli import app

    res = CliRunner().invoke(app, ["bench", "stribeck", "--runs", "0"])
    assert res.exit_code == 2


def test_fig6_draws_both_references_and_says_when_they_coincide() -> None:
    from fricid.report.studies._fig6 import coincide, fig6_convergence

    assert coincide(1.30e-4, 1.302e-4) and not coincide(1.3e-4, 2.0e-4)
    runs = [np.array([[1.0, 1.0], [10.0, 1e-3], [100.0, 1.3e-4]])] * 2
    alone = fig6_convergence({"RWSAVSBAS": runs}, title="t", optimum=1.302e-4)
    both = fig6_convergence(
        {"RWSAVSBAS": runs}, title="t", optimum=1.302e-4, paper=("paper", 1.3e-4)
    )
    assert alone[:4] == both[:4] == b"\x89PNG" and alone != both
