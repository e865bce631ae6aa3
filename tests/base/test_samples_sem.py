"""Per-sample standard errors travel with the samples (``meta["sem"]``) and reach the CLI.

Issue 11, "Where it shows": the extraction stores the scatter of its passes, the steady-state
EPOS reader the autocorrelation-corrected standard error of each file's rows; both survive
``write_samples``/``read_samples`` and selection, and ``fricid fit`` prints how the scatter
was estimated.
"""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.extract import extract
from fricid.identify.validate import measurement_scatter
from fricid.io import epos_steady_samples, read_samples, write_samples
from fricid.metrics import sem_autocorrelated
from fricid.sim import preset, simulate


@pytest.fixture(scope="module")
def leadscrew(leadscrew_dir):
    return epos_steady_samples(leadscrew_dir)


def test_epos_steady_samples_carry_autocorrelated_sem(leadscrew, leadscrew_dir):
    from fricid.io import read_epos

    sem = np.asarray(leadscrew.meta["sem"], dtype=float)
    assert sem.shape == (len(leadscrew),) and np.all(sem > 0)
    first = leadscrew.meta["files"][0]
    log = read_epos(leadscrew_dir / first)
    assert sem[0] == pytest.approx(sem_autocorrelated(log.motor_torque))
    sc = measurement_scatter(leadscrew)
    assert "autocorrelation" in sc.method
    assert sc.value == pytest.approx(np.sqrt(np.mean(sem**2)))


@pytest.mark.parametrize("suffix", ["csv", "parquet"])
def test_sem_survives_write_and_read(leadscrew, tmp_path, suffix):
    back = read_samples(write_samples(leadscrew, tmp_path / f"s.{suffix}"))
    assert back.meta["sem"] == pytest.approx(leadscrew.meta["sem"])
    assert back.meta["sem_method"] == leadscrew.meta["sem_method"]
    assert measurement_scatter(back).method == measurement_scatter(leadscrew).method


def test_selection_keeps_each_rows_sem(leadscrew):
    pos = leadscrew.subset(leadscrew.direction > 0)
    full = np.asarray(leadscrew.meta["sem"], dtype=float)
    assert np.asarray(pos.meta["sem"], dtype=float) == pytest.approx(full[leadscrew.direction > 0])
    assert "autocorrelation" in measurement_scatter(pos).method


def test_extraction_stores_the_passes_sem():
    scenario = preset("paper1", "quick")
    result = extract(
        simulate(scenario, seed=3),
        positions=scenario.design.positions,
        bin_halfwidth=scenario.design.bin_halfwidth,
        gravity="fit",
    )
    for samples, sem in (
        (result.samples, result.sem),
        (result.by_direction, result.direction_sem),
    ):
        stored = np.asarray(samples.meta["sem"], dtype=float)
        assert stored == pytest.approx(sem, nan_ok=True)
        sc = measurement_scatter(samples)
        assert sc.method.startswith("between passes")
    assert "quality" in result.samples.meta


def test_cli_fit_prints_the_autocorrelation_scatter_of_epos_samples(leadscrew, tmp_path):
    path = write_samples(leadscrew, tmp_path / "samples.csv")
    res = CliRunner().invoke(
        app, ["fit", str(path), "--model", "stribeck_asym", "--out", str(tmp_path / "m.json")]
    )
    assert res.exit_code == 0, res.output
    line = next(ln for ln in res.output.splitlines() if ln.strip().startswith("scatter"))
    assert "within-run, autocorrelation-corrected" in line
