"""The verdict-calibration benchmark (``benchmarks/bench_verdicts.py``): its generators are its
own (no fricid law or simulator), its cases have the shapes they claim, its truth scores are
right on known answers, and it runs end to end."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCH))

import _verdict_cases as vc  # noqa: E402
import _verdict_eval as ve  # noqa: E402
import bench_verdicts as bv  # noqa: E402


def _fricid_imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
        elif isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
    return {n for n in names if n.startswith("fricid")}


def test_generators_use_no_fricid_law_or_simulator():
    assert _fricid_imports(BENCH / "_verdict_cases.py") == {"fricid.samples"}
    code = (
        f"import sys; sys.path.insert(0, {str(BENCH)!r}); import _verdict_cases as vc; "
        "[vc.make_case(i, k, 1000 + i) for i, k in enumerate(vc.CLASSES)]; "
        "print(sorted(m for m in sys.modules if m.startswith(('fricid.sim', 'fricid.models'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize("name", vc.LAWS)
def test_every_law_opposes_motion_and_is_finite(name):
    rng = np.random.default_rng(3)
    law = vc.make_law(name, rng)
    v = np.r_[-np.geomspace(1e-3, 5, 50), np.geomspace(1e-3, 5, 50)]
    lo, t = np.full(v.size, 10.0), np.full(v.size, 40.0)
    f = law(v, lo, t)
    assert np.all(np.isfinite(f)) and np.all(f * v > 0)


def _steps(speeds: np.ndarray) -> np.ndarray:
    s = np.unique(np.abs(speeds))
    return s[1:] / s[:-1] - 1


def test_case_classes_have_their_shapes():
    cases = {k: vc.make_case(i, k, 1000 + i) for i, k in enumerate(vc.CLASSES)}
    close = cases["close"].samples.velocity
    assert 30 <= np.sum(close > 0) <= 40
    assert np.all((_steps(close[close > 0]) > 0.029) & (_steps(close[close > 0]) < 0.051))
    assert 5 <= cases["few"].spec["levels_pos"] <= 6
    assert len(cases["tiny"].samples) == 12
    lop = cases["lopsided"].spec
    assert lop["levels_pos"] > 2 * lop["levels_neg"]
    assert np.all(cases["unknown"].samples.std == 0)
    assert np.all(cases["regular"].samples.std > 0)
    rep = cases["repeats"].samples
    assert len(rep) == 3 * (cases["repeats"].spec["levels_pos"] * 2)
    lt = cases["loadtemp"].samples
    assert np.unique(lt.temperature).size == 3 and np.unique(np.abs(lt.load)).size == 3
    gaps = cases["gaps"].samples.velocity
    assert _steps(gaps[gaps > 0]).max() > 0.5  # a band of the range is missing


def test_gravity_left_in_moves_samples_off_the_truth_by_more_than_noise():
    case = vc.make_case(11, "gravity", 1011)
    s = case.samples
    resid = s.friction - case.law(s.velocity, np.zeros(len(s)), np.full(len(s), 25.0))
    sigma = case.sigma(s.velocity, 0, 0)
    assert np.sqrt(np.mean(resid**2)) > 3 * np.sqrt(np.mean(sigma**2))


def test_truth_scores_on_known_answers():
    truth = np.linspace(1, 2, 500)
    sigma = np.full(500, 0.1)
    perfect = ve.true_scores(truth, truth, sigma, (truth - 1.96 * 0.1, truth + 1.96 * 0.1))
    assert perfect["true_ratio"] == pytest.approx(1.0)
    assert perfect["model_ratio"] == pytest.approx(0.0)
    assert perfect["coverage"] == pytest.approx(0.95, abs=1e-3)
    biased = ve.true_scores(truth + 0.2, truth, sigma, None)  # bias 2 sigma
    assert biased["true_ratio"] == pytest.approx(np.sqrt(5.0))
    assert biased["coverage"] is None
    assert bv.truth_class(1.19) == "<1.2" and bv.truth_class(1.5) == "1.2-1.5"
    assert bv.truth_class(1.51) == ">1.5"


def test_gravity_coverage_counts_the_offset_a_fresh_sample_carries():
    """A fresh sample of a gravity case is ``F + a sin(phi) + sigma z``: an interval of
    +-a sin(phi0) about the truth, noise negligible, covers ``P(|sin phi| <= sin phi0) =
    2 phi0 / pi``; the gravity-free measure gave 1.0 for it."""
    truth, sigma = np.linspace(1.0, 2.0, 50), np.full(50, 1e-6)
    a, phi0 = 0.3, np.pi / 6
    band = (truth - a * np.sin(phi0), truth + a * np.sin(phi0))
    got = ve.true_scores(truth, truth, sigma, band, offset_amp=a)
    assert got["coverage"] == pytest.approx(2 * phi0 / np.pi, abs=0.01)
    assert got["true_ratio"] == pytest.approx(1.0)  # the verdict's truth: friction only
    assert ve.true_scores(truth, truth, sigma, band)["coverage"] == pytest.approx(1.0)
    case = vc.make_case(11, "gravity", 1011)
    assert case.spec["gravity_amp"] > 0
    assert vc.make_case(0, "regular", 1000).spec["gravity_amp"] == 0.0


class _Stub:
    """A fitted model with an interval method, as an interval API added later might be."""

    model, kind = "stribeck", "analytic"

    def predict(self, X, *, warn=True):
        return np.asarray(X)[:, 0] * 0 + 1.0

    def predict_interval(self, X, level=0.95):
        n = np.asarray(X).shape[0]
        return {"low": np.full(n, 0.5), "high": np.full(n, 1.5 + level)}


def test_prediction_interval_is_picked_up_generically():
    X = np.zeros((4, 3))
    (lo, hi), source = ve.prediction_interval(_Stub(), X)
    assert source == "predict_interval"
    assert np.allclose(lo, 0.5) and np.allclose(hi, 2.45)

    class Bare(_Stub):
        predict_interval = None

    assert ve.prediction_interval(Bare(), X) is None


def test_one_tiny_case_scores_and_tabulates(tmp_path, capsys):
    rows = bv.run_case((6, "tiny", 1006, ("coulomb_viscous",)))
    (row,) = rows
    assert row["level"] in ("yes", "with caveats", "no")
    assert row["true_ratio"] >= 1.0 and row["truth"] == bv.truth_class(row["true_ratio"])
    summ = bv.summary(rows)
    assert sum(summ["confusion"][row["level"]].values()) == 1
    assert summ["rates"]["n"] == 1
    lines = tmp_path / "rows.jsonl"  # --rows output, re-tabulated by --tables-from
    lines.write_text(json.dumps(rows[0]) + "\n" + json.dumps({**rows[0], "case": 19}) + "\n")
    again = bv.main(["--tables-from", str(lines), "--seed-split", "0"])
    assert again["report"]["rates"]["n"] == 2
    assert "2 fits read from rows.jsonl" in capsys.readouterr().out


@pytest.mark.slow
def test_bench_runs_end_to_end_with_json(tmp_path, capsys):
    out = tmp_path / "v.json"
    argv = ["--cases", "3", "--models", "coulomb_viscous", "--learned-every", "0"]
    argv += ["--auto-every", "0"]
    result = bv.main([*argv, "--seed-split", "3", "--json", str(out)])
    text = capsys.readouterr().out
    assert "Verdict against the true held-out ratio" in text and "Coverage" in text
    data = json.loads(out.read_text())
    assert data["tuning_seeds"] == [1002] and len(data["rows"]) == 3
    assert data["report"]["rates"]["n"] == 2 == result["report"]["rates"]["n"]


def test_classes_option_keeps_the_ids_and_seeds_of_the_full_run():
    args = bv.parse(["--cases", "40", "--classes", "gravity,regular", "--auto-every", "0"])
    tasks = bv._tasks(args)
    assert [(t[0], t[1], t[2]) for t in tasks] == [
        (c, k, s) for c, k, s in bv.case_plan(40) if k in ("gravity", "regular")
    ]
    assert [t[0] for t in tasks] == [0, 11, 13, 24, 26, 37, 39]
    with pytest.raises(SystemExit):
        bv.parse(["--classes", "gravitee"])


def test_gravity_cases_get_the_gravity_caveat():
    """Every gravity case's samples carry the signature (runs differing far beyond their
    std/sqrt(count)); the repeats class, whose runs differ by noise, never does."""
    from fricid.identify._diagnostics import gravity_caveat

    for i in (11, 24, 37):
        assert gravity_caveat(vc.make_case(i, "gravity", 1000 + i).samples)
    for i in (7, 20, 33):
        assert gravity_caveat(vc.make_case(i, "repeats", 1000 + i).samples) == []
