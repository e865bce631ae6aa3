"""The BAS-RBFNN study (Tables 1, 3, 4, Fig. 9, 10) at a tiny size, and ``fricid bench rbfnn``."""

from __future__ import annotations

import math

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.errors import ConfigError
from fricid.experiments.rbfnn_study import (
    PAPER,
    paper1_data,
    run_study,
    study_config,
    unseen_region,
)
from fricid.report.studies.rbfnn import summary_markdown, write_outputs

DEG = math.pi / 180.0


def tiny(**changes):
    """The quick study cut further: oracle data, 2 folds, 2 seeds, 8 epochs."""
    return study_config(
        quick=True,
        data="oracle",
        folds=2,
        seeds=2,
        max_epochs=8,
        timing_repeats=1,
        gp_subset=150,
        **changes,
    )


@pytest.fixture(scope="module")
def result():
    return run_study(tiny())


def test_unseen_region_is_the_papers():
    u = unseen_region()
    assert len(u) == 5 * 7 * 6
    np.testing.assert_allclose(np.unique(u.velocity) / DEG, np.arange(52.0, 61.0, 2.0))
    np.testing.assert_allclose(np.unique(u.temperature), np.arange(45.0, 56.0, 2.0))
    # loads are the gravity torques (eq. 7, 12) at -22..-10 deg: near the top of the curve
    assert np.unique(u.load).size == 7 and 0.2 < u.load.min() < u.load.max() < 0.2105
    assert (u.y > 0).all()


def test_paper1_oracle_data():
    samples, truth, floor = paper1_data("reduced", seed=1, data="oracle")
    assert len(samples) == 330 and truth.shape == (330,)
    assert 3e-4 < floor < 2e-3
    assert 0.5 * floor < np.sqrt(np.mean((samples.y - truth) ** 2)) < 2 * floor
    with pytest.raises(ConfigError, match="'simulate' or 'oracle'"):
        paper1_data("reduced", data="csv")


def test_tables_have_every_row_and_the_papers_numbers(result):
    t = result.tables
    assert set(t) >= {
        "data",
        "table1",
        "table3",
        "table4",
        "table4_runs",
        "fig10",
        "timing",
        "targets",
    }
    assert list(t["table1"]["registry"]) == ["stribeck", "msk", "vlt"]
    assert t["table1"]["paper_fitness"].tolist() == [0.8732, 0.9418, 0.9783]
    # fitness grows as load and temperature are added (the paper's Table 1 ordering)
    assert t["table1"]["fitness"].is_monotonic_increasing
    t3 = t["table3"].set_index("model")
    assert list(t3.index) == [
        "RBFNN",
        "BAS-RBFNN",
        "RBFNN-60",
        "RBFNN, plain inputs",
        "VLT model",
        "MLP",
        "GP",
    ]
    assert t3.loc["BAS-RBFNN", "paper_mean_mNm"] == pytest.approx(1.1)
    assert t3.loc["VLT model", "paper_max_mNm"] == pytest.approx(14.2)
    for col in (
        "all_mean_mNm",
        "all_max_mNm",
        "cv_mean_mNm",
        "cv_max_mNm",
        "cv_rmse_mNm",
        "cv_rmse_truth_mNm",
    ):
        assert np.isfinite(t3[col]).all(), col
    assert (t3["all_max_mNm"] >= t3["all_mean_mNm"]).all()
    # the networks beat the analytic model; BAS never ends worse than its lsq start
    assert t3.loc["RBFNN", "all_rmse_mNm"] < t3.loc["VLT model", "all_rmse_mNm"]
    assert t3.loc["BAS-RBFNN", "all_rmse_mNm"] <= t3.loc["RBFNN", "all_rmse_mNm"] + 1e-9
    t4 = t["table4"].set_index("model")
    assert list(t4.index) == ["GA-RBFNN", "BAS-RBFNN"]
    assert t4.loc["GA-RBFNN", "paper_epochs"] == 356
    assert t4.loc["BAS-RBFNN", "paper_epochs"] == 257
    assert (t4["runs"] == 2).all()
    runs = t["table4_runs"]
    assert len(runs) == 4 and (runs["evaluations"] <= 8 * 30).all()
    f10 = t["fig10"].set_index("model")
    assert f10.loc["BAS-RBFNN", "paper_max_mNm"] == pytest.approx(6.3)
    assert len(t["targets"]) == 6 and t["targets"]["met"].dtype == bool
    assert set(t["timing_all_threads"]["threads"]) == {"all"}
    assert PAPER["target_mse"] == 1e-4


def test_curves_and_predictions(result):
    for label in ("GA-RBFNN", "BAS-RBFNN"):
        curves = result.curves[label]
        assert len(curves) == 2
        for c in curves:
            assert 2 <= len(c) <= 9 and np.all(np.diff(c) <= 0)
    assert result.unseen["BAS-RBFNN"].shape == (210,)
    assert result.predictions["RBFNN"].shape == result.predictions["measured"].shape


def test_outputs_written(result, tmp_path):
    paths = write_outputs(result, tmp_path / "out")
    names = {p.name for p in paths}
    assert {
        "table1.csv",
        "table3.csv",
        "table4.csv",
        "fig9_mse.png",
        "fig10_unseen.png",
        "summary.md",
    } <= names
    for p in paths:
        assert p.stat().st_size > 0
    assert (tmp_path / "out" / "fig9_mse.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = summary_markdown(result)
    assert "## Table 4 and Fig. 9" in text and "Performance targets" in text


def test_given_data_is_used_and_checked():
    data = paper1_data("reduced", seed=2, data="oracle")
    with pytest.raises(ConfigError, match="true friction has shape"):
        run_study(tiny(), data=(data[0], data[1][:-1], data[2]))


def test_cli_bench_rbfnn(tmp_path):
    from fricid.cli import app

    runner = CliRunner()
    res = runner.invoke(
        app,
        [
            "bench",
            "rbfnn",
            "--quick",
            "--seeds",
            "2",
            "--folds",
            "2",
            "--epochs",
            "4",
            "--out",
            str(tmp_path / "bench"),
        ],
    )
    assert res.exit_code == 0, res.output
    assert "Table 3" in res.output and "BAS-RBFNN" in res.output
    assert (tmp_path / "bench" / "table3.csv").exists()
    bad = runner.invoke(app, ["bench", "rbfnn", "--folds", "1"])
    assert bad.exit_code == 2
