"""The operating range with its gaps: the model file records the measured speeds per direction
and the gaps between them; `predict`, `export --clamp`, `compensate` and the trust text say
where a speed is below the slowest measured one or inside a gap, for two-direction models too."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.control import compensation_study, default_config
from fricid.fitted import FittedModel
from fricid.identify import fit
from fricid.identify._diagnostics import range_text
from fricid.models._range import speed_coverage
from fricid.samples import FrictionSamples

runner = CliRunner()

#: Speeds measured from 0.217 rad/s, with nothing between 2 and 5 rad/s.
SPEEDS = np.array([0.217, 0.4, 0.7, 1.2, 2.0, 5.0, 8.0, 13.0, 20.84])


def two_way() -> FittedModel:
    v = np.r_[SPEEDS, -SPEEDS]
    y = np.sign(v) * (1.0 + 0.1 * np.abs(v)) + 0.01 * np.random.default_rng(0).normal(size=v.size)
    samples = FrictionSamples(
        velocity=v, load=np.zeros(v.size), temperature=np.full(v.size, 25.0), friction=y
    )
    return fit(samples, "coulomb_viscous")


@pytest.fixture(scope="module")
def model() -> FittedModel:
    return two_way()


def test_speed_coverage_finds_the_gap_and_not_a_linear_step():
    cov = speed_coverage(np.r_[SPEEDS, -SPEEDS[:-1]], [1, -1])
    assert cov["pos"] == {"range": [0.217, 20.84], "gaps": [[2.0, 5.0]]}
    assert cov["neg"]["range"] == [0.217, 13.0]
    linear = speed_coverage(np.arange(0.5, 20.01, 0.5), [0])
    assert linear == {"both": {"range": [0.5, 20.0], "gaps": []}}
    from_slow = speed_coverage(np.r_[0.2172, 1.047 * np.arange(1, 8)], [1])  # EPOS-like
    assert from_slow["pos"]["gaps"] == []
    hole = speed_coverage(np.r_[np.linspace(0.1, 1.0, 8), np.linspace(4.0, 6.0, 5)], [1])
    assert hole["pos"]["gaps"] == [[1.0, 4.0]]
    geometric = speed_coverage(np.geomspace(0.1, 10, 15), [1])
    assert geometric["pos"]["gaps"] == []


def test_two_direction_model_reports_below_and_gap(model):
    assert model.provenance["speeds"]["pos"]["gaps"] == [[2.0, 5.0]]
    found = {b.kind: b for b in model.range_check(np.array([[0.001, 0, 25], [-3.0, 0, 25]]))}
    assert set(found) == {"below", "gap"}
    assert "below the smallest identified speed 0.217 rad/s" in found["below"].message
    assert "nothing between 2 and 5 rad/s" in found["gap"].message
    assert "for v < 0" in found["gap"].message
    assert not model.range_check(np.array([[1.0, 0, 25], [-10.0, 0, 25]]))


def test_outside_range_marks_each_row_from_one_check(model, monkeypatch):
    """Rows below, above, in a gap and inside, marked as row-by-row checks would, with the
    range checked once for all the rows (it had been once per row when any row was out)."""
    X = np.array([[0.001, 0, 25], [-3.0, 0, 25], [1.0, 0, 25], [40.0, 0, 25], [-0.05, 0, 25]])
    one_by_one = [any(b.kind != "gap" for b in model.range_check(x[None])) for x in X]
    calls = []
    check = type(model).range_check
    monkeypatch.setattr(type(model), "range_check", lambda m, X: calls.append(1) or check(m, X))
    assert model.outside_range(X).tolist() == one_by_one == [True, False, False, True, True]
    assert len(calls) == 1


def test_range_survives_the_model_file(model, tmp_path):
    loaded = FittedModel.load(model.save(tmp_path / "m.json"))
    assert loaded.provenance["speeds"] == model.provenance["speeds"]
    assert [b.kind for b in loaded.range_check(np.array([[0.001, 0, 25]]))] == ["below"]


def test_cli_predict_warns_below_and_in_a_gap(model, tmp_path):
    path = model.save(tmp_path / "m.json")
    res = runner.invoke(app, ["predict", str(path), "-v", "0.001", "-v", "3", "-v", "10"])
    assert res.exit_code == 0, res.output
    lines = [ln for ln in res.stderr.splitlines() if ln.startswith("warning:")]
    assert len(lines) == 2, res.stderr
    assert "0.001 rad/s is below the smallest identified speed 0.217 rad/s" in lines[0]
    assert "measured 0.217 to 20.84 rad/s for v > 0" in lines[0]
    assert "gap" in lines[1] and "nothing between 2 and 5 rad/s" in lines[1]


def test_export_clamp_says_what_it_cannot_hold(model, tmp_path):
    path = model.save(tmp_path / "m.json")
    res = runner.invoke(
        app, ["export", str(path), "--to", "c", "--clamp", "--out", str(tmp_path / "c")]
    )
    assert res.exit_code == 0, res.output
    lines = [ln for ln in res.stderr.splitlines() if ln.startswith("warning:")]
    # the clamp's warning, then the trust line's (this file records no verdict)
    assert len(lines) == 2 and "nothing between 2 and 5" in lines[0], res.stderr
    assert "trust verdict: not recorded" in lines[1]
    header = (tmp_path / "c" / "fricid_friction.h").read_text()
    assert "not held: v > 0: measured 0.217 to 20.84 rad/s (nothing between 2 and 5)" in header


def test_trust_text_and_compensate_use_the_per_direction_range(model):
    text = range_text(model)
    assert "v > 0: measured 0.217 to 20.84 rad/s (nothing between 2 and 5)" in text
    config = default_config(model, peak_velocity=10.0, periods=1.0, dt=1e-3)
    notes = compensation_study(model, config).notes
    assert any("below the identified speeds (|v| < 0.217 rad/s)" in n for n in notes), notes
    assert any("crosses a gap of the measured speeds" in n for n in notes), notes


def test_one_speed_on_a_side_has_a_range_and_no_gap():
    # one measured speed in one direction (a held-out fold of few levels): no step to compare
    got = speed_coverage([0.2, 0.5, 1.0, -0.5], [1, 1, 1, -1])
    assert got["neg"] == {"range": [0.5, 0.5], "gaps": []}
    assert got["pos"]["range"] == [0.2, 1.0]
