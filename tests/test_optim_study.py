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
    fast = problem.objective(jit=True)
    # numba is a dependency: a fallback to the NumPy objective here means its import broke
    assert fast is not problem.sse, "the compiled objective is missing: does numba import?"
    X = study.BOUNDS[:, 0] + np.random.default_rng(0).random((50, 4)) * np.diff(study.BOUNDS)[:, 0]
    out = np.empty(50)
    fast.jit_kernel(X, out, fast.jit_data)
    assert np.allclose(out, problem.sse(X), rtol=1e-12, atol=0)


@pytest.mark.slow
def test_study_runs_and_writes_its_outputs(tmp_path) -> None:
    result = study.run_study(runs=1, quick=True, time_numpy=False, repeats=1)
    assert {"VSBAS", "IBAS", "RWSAVSBAS", "BAS", "GA", "CMA-ES (cma)"} <= set(result.table.index)
    assert result.table.loc["RWSAVSBAS", "max_ratio"] < 1.001
    assert result.table.loc["VSBAS", "paper_mean"] == 0.60
    assert bool(result.hybrid["bas+lm_found"].all())
    text = render.report_text(result)
    assert "RWSAVSBAS" in text and "ratio" in text
    paths = render.write_outputs(result, tmp_path / "out")
    assert all(p.exists() and p.stat().st_size > 0 for p in paths)
    assert paths[-1].read_bytes()[:4] == b"\x89PNG"


def test_cli_rejects_bad_runs() -> None:
    from typer.testing import CliRunner

    from fricid.cli import app

    res = CliRunner().invoke(app, ["bench", "stribeck", "--runs", "0"])
    assert res.exit_code == 2
