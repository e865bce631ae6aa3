"""``fricid fit --model auto``: the candidate under way and its place in the list on stderr,
and, when no analytic family follows the data, the advice to try the learned ones."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import _estimate, _progress, app
from fricid.identify.static.select import _learned_advice

runner = CliRunner()


@pytest.fixture
def wavy_csv(tmp_path):
    """Friction no analytic family follows (a wave in log-speed), four speed levels, one
    direction: only coulomb_viscous can be validated, so the run is short."""
    v = np.geomspace(0.01, 1.0, 4)
    f = 0.1 + 0.05 * np.sin(12 * np.log(v)) + 1e-4 * np.random.default_rng(0).standard_normal(4)
    rows = "".join(f"{a!r},{b!r},1e-3,100\n" for a, b in zip(v.tolist(), f.tolist(), strict=True))
    path = tmp_path / "wavy.csv"
    path.write_text("velocity [rad/s],friction [N m],std [N m],count\n" + rows, encoding="utf-8")
    return path


@pytest.mark.slow  # 3 s measured under load (the fit, its validation and the trust record)
def test_auto_names_the_candidate_and_suggests_learned(wavy_csv, tmp_path, monkeypatch):
    monkeypatch.setattr(_progress, "GRACE_S", 0.0)
    monkeypatch.setattr(_progress, "MIN_GAP_S", 0.0)
    monkeypatch.setattr(_estimate, "MIN_SPAN_S", 0.0)
    out = tmp_path / "m.json"
    res = runner.invoke(app, ["fit", str(wavy_csv), "--model", "auto", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "auto: 1/1 coulomb_viscous" in res.stderr
    assert "auto: refitting coulomb_viscous on every sample" in res.stderr
    assert "advice: no analytic family follows these data" in res.stdout
    assert "--model auto --learned" in res.stdout


def test_learned_advice_only_when_the_best_misses_and_learned_were_not_tried():
    best = {"model": "stribeck", "ratio": 25.6}
    table = [best]
    assert "25.6x" in _learned_advice(best, table, learned=False)
    assert _learned_advice(best, table, learned=True) == ""
    assert _learned_advice({"model": "stribeck", "ratio": 1.2}, table, learned=False) == ""
    with_rbf = [best, {"model": "rbf", "ratio": 30.0}]
    assert _learned_advice(best, with_rbf, learned=False) == ""
