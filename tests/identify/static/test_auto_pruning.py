"""``auto`` leaves out of validation the candidates its bound shows cannot be chosen."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from fricid.identify import fit
from fricid.identify.static import select as select_module
from fricid.identify.validate import measurement_scatter
from fricid.metrics import NOISE_RATIO
from fricid.samples import FrictionSamples


def _stribeck(seed: int = 3) -> FrictionSamples:
    """A per-direction Stribeck law, 12 speeds a direction, noise 0.01 N m: the symmetric and
    the Coulomb-viscous families miss it by far more than the noise."""
    s = np.geomspace(0.02, 2.0, 12)
    v = np.r_[s, -s]
    tau_c = np.where(v > 0, 0.5, 0.35)
    law = np.sign(v) * (tau_c + 0.4 * np.exp(-((np.abs(v) / 0.1) ** 2)) + 0.3 * np.abs(v))
    y = law + np.random.default_rng(seed).normal(0.0, 0.01, v.size)
    return FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=y, std=0.01, count=1)


def _auto(samples, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(samples, "auto", **options)


def test_a_pruned_candidate_could_not_have_been_chosen(monkeypatch):
    samples = _stribeck()
    fitted = _auto(samples)
    table = {r["model"]: r for r in fitted.selection["table"]}
    pruned = [m for m, r in table.items() if r["note"].startswith("not validated")]
    assert "coulomb_viscous" in pruned
    # the same choice, model and numbers with nothing pruned ...
    monkeypatch.setattr(select_module, "PRUNE_MARGIN", np.inf)
    full = _auto(samples)
    assert full.selection["chosen"] == fitted.selection["chosen"]
    np.testing.assert_array_equal(full.theta(), fitted.theta())
    every = {r["model"]: r for r in full.selection["table"]}
    assert not any(r["note"].startswith("not validated") for r in every.values())
    for m, r in table.items():
        if m not in pruned:
            assert r["heldout_rmse"] == every[m]["heldout_rmse"]
    # ... and every pruned candidate's held-out error is above what a choice may have
    best = min(r["heldout_rmse"] for r in every.values() if r["heldout_rmse"] is not None)
    scatter = measurement_scatter(samples).value
    bar = max(best * (1.0 + select_module.PREFER_SIMPLER), NOISE_RATIO * scatter)
    assert all(every[m]["heldout_rmse"] > bar for m in pruned)


@pytest.mark.slow  # 3 s per option (the default suite's slowest)
@pytest.mark.parametrize("options", [{"loss": "soft_l1"}, {"weights": "std"}])
def test_no_pruning_where_the_fit_does_not_minimise_the_plain_squared_error(options):
    fitted = _auto(_stribeck(), **options)
    notes = [r["note"] for r in fitted.selection["table"]]
    assert not any(n.startswith("not validated") for n in notes)
