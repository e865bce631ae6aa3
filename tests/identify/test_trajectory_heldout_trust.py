"""A trajectory model graded on a second log: the held-out error where it slides over the
torque's own scatter (fricid.identify.trajectory_check.heldout_trust)."""

from __future__ import annotations

import dataclasses
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from _trajectory import JOINT, TRUTH, multisine_log, truth_model
from fricid.fitted import FittedModel
from fricid.identify import fit
from fricid.identify.trajectory_check import (
    PRESLIDING_UNGRADED,
    heldout_grading,
    heldout_trust,
    predict_trajectory,
    torque_scatter,
)
from fricid.identify.trust import SECOND_LOG, Trust, assess_trust
from fricid.sim import trajectory as tr
from fricid.sim.trajectory import TRAJECTORY_NOISE


@pytest.fixture(scope="module")
def static_fit():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(multisine_log(1, 6.0), "stribeck")
    fitted.trust = assess_trust(fitted, None).to_dict()  # as fit --trajectory
    return fitted


def test_the_scatter_is_the_torque_noise():
    """Second differences of the sliding samples recover the noise the log was given: the
    same run without sensor noise (the current's noise does not feed back) tells it."""
    run = tr.multisine(duration=6.0, seed=3)
    noisy = tr.simulate_trajectory(run, TRUTH, JOINT, seed=3)
    quiet = dataclasses.replace(TRAJECTORY_NOISE, current_std=0.0, current_lsb=0.0)
    clean = tr.simulate_trajectory(run, TRUTH, JOINT, seed=3, noise=quiet)
    pred, ideal = (predict_trajectory(truth_model(), log) for log in (noisy, clean))
    noise = np.std(pred.torque - ideal.torque)
    assert noise > 0
    assert torque_scatter(pred) == pytest.approx(noise, rel=0.15)


def test_a_right_static_model_is_trusted_on_a_second_log(static_fit):
    assert static_fit.trust["level"] == "with caveats"  # nothing to grade it with yet
    graded = heldout_trust(static_fit, predict_trajectory(static_fit, multisine_log(2, 6.0)))
    assert graded.heldout_source == SECOND_LOG and graded.held_out
    assert graded.heldout_ratio < 1.2
    assert graded.level == "yes", graded.reasons


def test_a_second_log_of_another_joint_is_not_passed(static_fit):
    """The same motion on a joint whose Coulomb level is 20 % higher: the model misses it."""
    theta = TRUTH.theta.copy()
    theta[3] *= 1.2
    other = tr.simulate_trajectory(
        tr.multisine(duration=6.0, seed=2), tr.LuGreTruth(theta), JOINT, seed=2
    )
    graded = heldout_trust(static_fit, predict_trajectory(static_fit, other))
    assert graded.heldout_ratio > 3.0
    assert graded.level == "no"
    assert "misses" in graded.reasons[0]


def test_a_dynamic_law_is_graded_where_it_slides_with_a_caveat():
    model = truth_model()
    assert heldout_trust(model, predict_trajectory(model, multisine_log(2))) is None  # no record
    model.trust = Trust("with caveats", ["x"], converged=True, convergence="").to_dict()
    graded = heldout_trust(model, predict_trajectory(model, multisine_log(2)))
    assert graded.heldout_ratio < 1.2
    assert graded.level == "with caveats" and PRESLIDING_UNGRADED in graded.reasons


FOREIGN = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "foreign" / "lugre"


def _foreign_truth(**changes) -> FittedModel:
    """The independent simulator's law at steady state (``stribeck``: tau_v = sigma_2) with
    its joint in fricid's convention (``u = J qdd + f + mgl sin q``: p_x 0, p_y mgl)."""
    t = json.loads((FOREIGN / "truth.json").read_text())
    values = {k: t[k] for k in ("tau_c", "tau_s", "w_s", "delta")} | {"tau_v": t["sigma_2"]}
    fitted = FittedModel.from_values("stribeck", {**values, **changes})
    fitted.provenance["trajectory"] = {
        **truth_model().provenance["trajectory"],
        "joint": {
            "inertia": {"value": t["inertia"]},
            "p_x": {"value": 0.0},
            "p_y": {"value": t["mgl"]},
        },
    }
    fitted.trust = Trust("with caveats", ["x"], converged=True, convergence="").to_dict()
    return fitted


def test_on_another_simulator_s_log_the_truth_passes_and_a_wrong_law_does_not():
    """A second opinion: the independent simulator's PD-tracked chirp (2^20 counts/rev). Its
    torque scatters by the drive's own reaction to the encoder (0.043 N m against 0.01 of
    logged noise), which no friction law predicts sample by sample; the truth's law is within
    it, the law with a Coulomb level 30 % high is not."""
    if not FOREIGN.is_dir():
        pytest.skip(f"foreign logs not found at {FOREIGN}")
    from fricid.cli.trajectory import read_trajectory_log

    log = read_trajectory_log(FOREIGN / "chirp_pd_1000Hz_1048576cpr.csv")
    good = heldout_trust(_foreign_truth(), predict_trajectory(_foreign_truth(), log))
    assert good.heldout_ratio < 1.2 and "graded where it slides" in good.heldout_scheme
    high = _foreign_truth(tau_c=0.78)
    bad = heldout_trust(high, predict_trajectory(high, log))
    assert bad.heldout_ratio > 3.0 and bad.level == "no"


def test_a_second_log_that_hardly_slides_is_not_graded_or_says_how_little_was(static_fit):
    """A log that never slides (pre-sliding only, a joint at rest) grades nothing, and says
    so, rather than keeping the fit's reason; one that slides on a fifth of its samples is
    graded there with a caveat naming the share."""
    pred = predict_trajectory(static_fit, multisine_log(2, 6.0))
    still = dataclasses.replace(pred, sliding=np.zeros_like(pred.sliding))
    graded, why = heldout_grading(static_fit, still)
    assert graded is None and why.startswith("not graded: 0 of its")
    few = pred.sliding & (np.arange(pred.sliding.size) < 0.25 * pred.sliding.size)
    graded, scope = heldout_grading(static_fit, dataclasses.replace(pred, sliding=few))
    assert graded.level == "with caveats" and "graded where it slides" in scope
    assert any(r.startswith("the second log grades it on") for r in graded.reasons)


def test_a_torque_low_passed_before_it_was_logged_is_not_graded(static_fit):
    """Its second differences measure the filter, not the noise (a 1,550-fold "miss")."""
    from scipy import signal

    pred = predict_trajectory(static_fit, multisine_log(2, 6.0))
    sos = signal.butter(4, 5.0 * 2 * 1e-3, output="sos")
    smooth = dataclasses.replace(pred, torque=signal.sosfiltfilt(sos, pred.torque))
    graded, why = heldout_grading(static_fit, smooth)
    assert graded is None and "smooth from one sample to the next" in why
