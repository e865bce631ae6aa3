"""Metrics against hand-computed values and their invariants."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from fricid import metrics as M


def test_hand_computed():
    y = np.array([1.0, 2.0, 4.0])
    y_hat = np.array([1.0, 3.0, 2.0])
    assert M.sse(y, y_hat) == 5.0
    assert M.rmse(y, y_hat) == pytest.approx(np.sqrt(5 / 3))
    sst = np.sum((y - y.mean()) ** 2)
    assert M.fitness(y, y_hat) == pytest.approx(1 - 5 / sst)
    assert M.rmspe(y, y_hat) == pytest.approx(np.sqrt((0 + 0.25 + 0.25) / 3))
    assert M.mae(y, y_hat) == pytest.approx(1.0)
    assert M.max_abs_error(y, y_hat) == 2.0


finite = st.floats(-1e3, 1e3, allow_nan=False)


@given(arrays(float, st.integers(2, 40), elements=finite))
def test_perfect_prediction(y):
    assert M.sse(y, y) == 0.0
    assert M.fitness(y, y) == 1.0


@given(arrays(float, st.integers(2, 40), elements=finite), st.floats(-10, 10))
def test_rmse_of_constant_offset(y, c):
    assert M.rmse(y, y + c) == pytest.approx(abs(c), rel=1e-9, abs=1e-9)


def test_shape_mismatch():
    with pytest.raises(ValueError, match="shapes differ"):
        M.sse([1, 2], [1, 2, 3])


def test_rmspe_says_when_near_zero_friction_dominates_it():
    """One sample whose measured friction is near zero (0.001 N m among 0.3) makes RMSPE huge
    for any model; the note says so and gives it without those samples."""
    y = np.array([0.30, 0.31, 0.29, 0.001, 0.32])
    y_hat = y + np.array([0.003, -0.003, 0.003, 0.003, -0.003])
    assert M.rmspe(y, y_hat) > 1.0  # 134 %: the near-zero sample alone
    note = M.rmspe_note(y, y_hat)
    assert note is not None and "1 of 5 samples" in note and "without them it is 0.986 %" in note
    assert M.rmspe_note(y[[0, 1, 2, 4]], y_hat[[0, 1, 2, 4]]) is None
    assert M.rmspe_note(np.full(3, 0.001), np.full(3, 0.002)) is None  # all near: no RMS to judge


def test_evaluate_prints_the_rmspe_note(tmp_path):
    from typer.testing import CliRunner

    from fricid.cli import app
    from fricid.identify import fit
    from fricid.samples import FrictionSamples

    v = np.r_[0.1, 0.2, 0.5, 1.0, 2.0]
    rng = np.random.default_rng(1)
    friction = 0.3 + 0.05 * v + 0.002 * rng.standard_normal(v.size)
    model = tmp_path / "m.json"
    samples = FrictionSamples(velocity=v, load=None, temperature=None, friction=friction)
    fit(samples, "coulomb_viscous").save(model)
    near = tmp_path / "near.csv"
    rows = "".join(f"{a},{b}\n" for a, b in zip(v, [*friction[:-1], 0.001], strict=True))
    near.write_text("velocity [rad/s],friction [N m]\n" + rows)
    res = CliRunner().invoke(app, ["evaluate", str(model), str(near)], terminal_width=200)
    assert res.exit_code == 0, res.output
    assert "RMSPE is dominated by 1 of 5 samples" in " ".join(res.output.split())
    from fricid.identify.trust import assess_trust
    from fricid.io import read_samples
    from fricid.report import model_report

    fitted, data = fit(samples, "coulomb_viscous"), read_samples(near)
    doc = model_report(fitted, data, trust=assess_trust(fitted, data, max_work=1))
    notes = [i.text for s in doc.sections for i in s.items if hasattr(i, "kind")]
    assert any("RMSPE is dominated by 1 of 5 samples" in n for n in notes)
