"""LuGre from a log that never slides (issue 26): the pre-sliding route on creep logs of the
independent simulator of ``benchmarks/bench_lugre.py`` (its own RK4 joint and drive, none of
fricid's simulation code): sigma_0 and sigma_1 inside their intervals, the sliding friction,
J and gravity reported not determined, an encoder too coarse refused or flagged with its
numbers."""

from __future__ import annotations

import math
import sys
import warnings

import numpy as np
import pytest
from tests._paths import REPO

from fricid.errors import DataError, DataQualityWarning, IdentifiabilityWarning
from fricid.identify import fit
from fricid.io import read_rawlog

sys.path.insert(0, str(REPO / "benchmarks"))
import _lugre_truth as lt
import bench_lugre as bench

#: The sliding parameters a creep log cannot tell.
SLIDING = ("sigma_2", "tau_c", "tau_s", "w_s", "delta")


def _creep(tmp_path, truth: str, cpr: int, seed: int, seconds: float = 10.0):
    log = lt.simulate(lt.TRUTHS[truth], "creep", seconds, 1000.0, cpr, seed)
    path = lt.write_log(log, tmp_path / f"creep_{truth}_{cpr}_{seed}.csv", lt.TRUTHS[truth], {})
    return read_rawlog(path)


def _fit(log):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fitted = fit(log, "lugre", seed=0)
    return fitted, caught


@pytest.fixture(scope="module")
def creep_fit(tmp_path_factory):
    """slow_stribeck's creep, 2^20 counts/rev, 10 s (3.5 s measured)."""
    return _fit(_creep(tmp_path_factory.mktemp("creep"), "slow_stribeck", 2**20, 3))


@pytest.mark.slow  # the fixture's fit: 3.5 s alone, 10 s under load with numba compiling
def test_creep_gives_sigma_0_and_sigma_1_within_their_intervals(creep_fit):
    fitted, _ = creep_fit
    truth = lt.TRUTHS["slow_stribeck"]
    assert fitted.converged and fitted.provenance["trajectory"]["route"] == "presliding"
    s0, s1 = fitted.parameters["sigma_0"], fitted.parameters["sigma_1"]
    assert not (s0.not_determined or s1.not_determined)
    assert s0.ci95[0] <= truth.sigma0 <= s0.ci95[1]
    assert s0.ci95[1] / s0.ci95[0] < 1.05  # a 2^20 encoder pins the stiffness
    assert s1.ci95[0] <= truth.sigma1 <= s1.ci95[1]  # the damping's interval is wide ...
    assert s1.ci95[0] <= truth.sigma1 + truth.sigma2 <= s1.ci95[1]  # ... and says what it is
    assert "sigma_1 + sigma_2" in s1.note


@pytest.mark.slow  # the fixture's fit (see above)
def test_what_a_creep_log_does_not_determine_is_said_and_not_given_an_interval(creep_fit):
    fitted, caught = creep_fit
    for name in SLIDING:
        p = fitted.parameters[name]
        assert p.not_determined and "never slides" in p.note
        assert not p.has_interval and math.isnan(p.stderr)
    info = fitted.provenance["trajectory"]
    assert info["joint"] == {}  # J, p_x, p_y: none claimed
    record = info["presliding"]
    assert record["determined"] == ["sigma_0", "sigma_1"]
    assert set(record["not_determined"]) == {*SLIDING, "inertia", "p_x", "p_y"}
    said = [str(w.message) for w in caught if w.category is IdentifiabilityWarning]
    assert said and "never slides" in said[0] and "tau_s" in said[0]
    from fricid.cli.trajectory import trajectory_text

    text = trajectory_text(fitted)
    assert "not determined: tau_c" in text and "derivatives" not in text
    report = fitted.report()
    assert "tau_c:" in report and "CI" not in report.split("tau_c:")[1].splitlines()[0]


@pytest.mark.slow  # 2.2 s, quiet machine (default run kept short)
def test_an_encoder_that_cannot_see_the_bristles_is_refused_with_its_numbers(tmp_path):
    """cdw95's creep (sigma_0 1e5 N m/rad) at 2^17 counts/rev: the position takes two values."""
    log = _creep(tmp_path, "cdw95", 2**17, 0, seconds=20.0)
    with pytest.raises(DataError, match=r"2 distinct values .*4\.79e-05 rad.*does not resolve"):
        fit(log, "lugre")
    still = _creep(tmp_path, "cdw95", 2**17, 0, seconds=2.0)
    with pytest.raises(DataError, match=r"never changes .*does not resolve"):
        fit(still, "lugre")


@pytest.mark.slow  # one fit, 4.2 s measured
def test_a_deflection_of_about_one_count_is_flagged_and_sigma_1_not_claimed(tmp_path):
    """geared's creep at 2^17 counts/rev: the deflection spans about a count (4.2 s measured)."""
    fitted, caught = _fit(_creep(tmp_path, "geared", 2**17, 1))
    flagged = [str(w.message) for w in caught if w.category is DataQualityWarning]
    assert flagged and "131072 counts/rev" in flagged[0] and "resolved from 10" in flagged[0]
    record = fitted.provenance["trajectory"]["presliding"]
    assert record["deflection_counts"] < 2
    s0 = fitted.parameters["sigma_0"]
    assert s0.ci95[0] <= lt.TRUTHS["geared"].sigma0 <= s0.ci95[1]
    assert fitted.parameters["sigma_1"].not_determined  # a lag of 0.17 ms under one count
    # and the record, the printout and the warning say so too, not "determines sigma_1"
    assert record["determined"] == ["sigma_0"] and "sigma_1" in record["not_determined"]
    assert not record["not_determined"]["sigma_1"].startswith("not determined")


def test_a_log_that_slides_is_refused_by_the_presliding_route(tmp_path):
    from fricid.identify.dynamic.trajectory import fit_trajectory

    log = lt.simulate(lt.TRUTHS["geared"], "chirp_pd", 3.0, 1000.0, 2**20, 0)
    path = lt.write_log(log, tmp_path / "chirp.csv", lt.TRUTHS["geared"], {})
    with pytest.raises(DataError, match="pre-sliding route is for logs that never slide"):
        fit_trajectory(read_rawlog(path), "lugre", route="presliding")


def test_the_benchmark_counts_not_determined_apart_from_claims():
    truth = lt.TRUTHS["geared"].fricid_names()
    est = {n: {"value": v, "ci95": [v, v], "closed": True, "nd": False} for n, v in truth.items()}
    est["tau_c"] = {"value": 1.0, "ci95": [np.nan, np.nan], "closed": False, "nd": True}
    row = {"truth": "geared", "kind": "creep", "estimates": est, "seconds": 1.0, "n": 1000}
    row["converged"] = True
    assert bench._nd(row, "tau_c") and not bench._covered(row, "tau_c")
    assert bench._covered(row, "sigma_0") and not bench._nd(row, "sigma_0")
    lines = bench.coverage_lines([row], lambda r: r["kind"])
    assert "0/0+1nd" in lines[1] and "1/1" in lines[1]


@pytest.mark.slow  # one fit, 4 s measured
def test_sweeps_give_the_sliding_part_and_sigma_2_is_subtracted(tmp_path):
    """static= (a stribeck fit from sweeps, here the truth's with 1 % errors): the sliding part
    is taken from it, sigma_1 is the pre-sliding damping less its sigma_2."""
    from fricid.fitted import FittedModel, Parameter
    from fricid.identify.dynamic.trajectory import fit_trajectory

    t = lt.TRUTHS["slow_stribeck"]
    levels = dict(tau_c=t.Fc, tau_s=t.Fs, w_s=t.vs, tau_v=t.sigma2, delta=t.delta)
    static = FittedModel(
        model="stribeck",
        parameters={
            n: Parameter(n, v, stderr=0.01 * v, ci95=(0.98 * v, 1.02 * v), bounds=(0.0, 10 * v))
            for n, v in levels.items()
        },
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit_trajectory(_creep(tmp_path, "slow_stribeck", 2**20, 3), "lugre", static=static)
    damping = fitted.provenance["trajectory"]["presliding"]["damping"]
    s1 = fitted.parameters["sigma_1"]
    assert s1.value == pytest.approx(damping["value"] - t.sigma2)
    assert s1.ci95[0] <= t.sigma1 <= s1.ci95[1] and "less the sweeps' sigma_2" in s1.note
    assert (
        fitted.parameters["tau_s"].value == t.Fs and not fitted.parameters["tau_s"].not_determined
    )
    assert set(fitted.provenance["trajectory"]["presliding"]["not_determined"]) == {
        "inertia",
        "p_x",
        "p_y",
    }


@pytest.mark.slow  # the fixture's fit (see above)
def test_no_torque_is_predicted_from_a_presliding_model(creep_fit, tmp_path):
    """The report's torque along a log needs J and the gravity: refused, not made up."""
    from fricid.identify.trajectory_check import predict_trajectory

    fitted, _ = creep_fit
    with pytest.raises(DataError, match=r"pre-sliding route .* no torque along a log"):
        predict_trajectory(fitted, _creep(tmp_path, "slow_stribeck", 2**20, 4, seconds=2.0))
