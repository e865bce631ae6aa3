"""Every held-out ratio ``fricid fit`` prints is the RMSE it prints over the scatter it prints,
or says which other figure it is: ``auto``'s reason, its table and ``[[Validation]]`` name the
pooled leave-one-velocity-out figure ("lovo, every level"), the trust verdict its own."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from fricid.cli.fit import goodness_text
from fricid.identify import fit, validate
from fricid.identify._scatter import Scatter
from fricid.identify.static.select import _reason
from fricid.identify.trust import assess_trust
from fricid.metrics import NOISE_RATIO
from fricid.samples import FrictionSamples

NOISE = 0.05

#: How the pooled leave-one-velocity-out figure is named where it is printed.
LOVO_EVERY = "lovo, every level"


def _samples(seed: int = 0, levels: int = 8, sign: tuple[int, ...] = (-1, 1)) -> FrictionSamples:
    rng = np.random.default_rng(seed)
    s = np.geomspace(0.05, 2.0, levels)
    v = np.concatenate([d * s for d in sign])
    f = 0.8 + 0.5 * np.exp(-((np.abs(v) / 0.3) ** 2)) + 0.4 * np.abs(v)
    y = np.sign(v) * f + rng.normal(0.0, NOISE, v.size)
    return FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=y, std=NOISE, count=1)


def _ratios(text: str) -> list[tuple[float, float, float]]:
    """(ratio, RMSE, scatter) of each "held-out RMSE (...) R N m, ... Q.QQx the scatter S"."""
    pat = r"held-out RMSE \([^)]*\) ([\d.e+-]+) N m, [^(]*\(([\d.]+)x the scatter ([\d.e+-]+)"
    return [(float(q), float(r), float(s)) for r, q, s in re.findall(pat, text)]


def test_the_reason_prints_the_chosen_ratio_not_the_noise_bar():
    sc = Scatter(value=6.03e-05, per_sample=np.full(16, 6.03e-05), method="given", caveat="")
    chosen = {"model": "stribeck (delta=1)", "n_params": 4, "heldout_rmse": 3.95e-05}
    best = {"model": "stribeck", "n_params": 5, "heldout_rmse": 3.13e-05}
    text = _reason(chosen, best, sc, "lovo", NOISE_RATIO * sc.value, 16)
    found = _ratios(text)
    assert found, text
    for ratio, err, scatter in found:
        assert ratio == pytest.approx(err / scatter, abs=0.01), text
    assert f"({LOVO_EVERY})" in text
    assert f"up to {NOISE_RATIO:g}x" in text  # the bar is named as the bar


def test_pooled_and_graded_figures_say_which_they_are():
    s = _samples(1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(s, "stribeck", fixed={"delta": 2.0})
        val = validate(s, "stribeck", "lovo", fixed={"delta": 2.0})
    fitted.validation = val.to_dict()
    row = {"model": "stribeck", "n_params": 4, "heldout_rmse": val.rmse, "ratio": val.ratio}
    fitted.selection = {
        "scheme": "lovo",
        "chosen": "stribeck",
        "reason": "stribeck: the lowest",
        "table": [{**row, "note": val.verdict}],
    }
    text = goodness_text(fitted)
    held = [ln for ln in text.splitlines() if "held-out RMSE" in ln]
    assert held and all(LOVO_EVERY in ln for ln in held), text
    table = text.split("[[Model selection]]")[1]
    assert f"scatter {val.scatter.value:.3g} N m" in table  # what the table's ratios are over


def test_a_verdict_on_random_folds_says_so():
    s = _samples(2, levels=10)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(s, "stribeck", fixed={"delta": 2.0})
        fitted.validation = validate(s, "stribeck", "kfold:5", fixed={"delta": 2.0}).to_dict()
        trust = assess_trust(fitted, s)
    assert trust.heldout_scheme == "kfold:5"
    assert trust.level == "yes", trust.line()
    assert "random folds, kfold:5" in trust.line()
