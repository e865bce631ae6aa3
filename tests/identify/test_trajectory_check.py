"""A trajectory model run along a log (fricid.identify.trajectory_check): the true model on
its own log predicts the torque to the noise, a wrong one does not, the low-passed residual at
a fit's estimate is the route's own, and a model without a joint is refused."""

from __future__ import annotations

import numpy as np
import pytest

from _trajectory import TRUTH, multisine_log, truth_model
from fricid.errors import DataError
from fricid.fitted import FittedModel
from fricid.identify.trajectory_check import is_trajectory_model, predict_trajectory


@pytest.fixture
def log():
    return multisine_log(5)


def test_the_truth_predicts_its_own_log(log):
    pred = predict_trajectory(truth_model(), log)
    m = pred.metrics()
    assert m["n"] == log.time.size - 1
    # the low-passed residual (what the identification minimises) is at the noise: well
    # under 1 % of the torque; the raw residual's median too, its RMS held up by the
    # break-aways (the derivative filter's smoothing of the acceleration's jump)
    assert m["rmse_filtered"] < 0.005 * m["signal_rms"]
    assert m["median_abs_error"] < 0.02 * m["signal_rms"]
    assert m["rmse"] > 3 * m["median_abs_error"]
    assert np.isnan(pred.torque_filtered[:100]).all()  # the filter's start-up, trimmed
    # the measured friction is the torque less inertia and gravity
    np.testing.assert_allclose(
        pred.friction - pred.friction_predicted, pred.residual, rtol=0, atol=1e-12
    )
    windows = pred.reversals()
    assert len(windows) >= 5
    for idx in windows:
        v = pred.velocity[idx]
        assert (v.min() < 0 < v.max()) and np.all(np.abs(v) < 0.1 * np.abs(pred.velocity).max())


def test_a_wrong_model_misses(log):
    good = predict_trajectory(truth_model(), log).metrics()["rmse_filtered"]
    for changes in ({"sigma_0": 1e3}, {"tau_s": 0.6}, {"sigma_2": 0.1}):
        bad = predict_trajectory(truth_model(**changes), log).metrics()["rmse_filtered"]
        assert bad > 3 * good, changes


def test_a_model_without_a_joint_is_refused(log):
    plain = FittedModel.from_values("lugre", TRUTH.params())
    assert not is_trajectory_model(plain) and is_trajectory_model(truth_model())
    with pytest.raises(DataError, match="not identified from a trajectory"):
        predict_trajectory(plain, log)


@pytest.mark.slow  # a trajectory fit: 1-6 s under load
@pytest.mark.filterwarnings("ignore::fricid.identify.dynamic.trajectory.PassivityWarning")
def test_the_low_passed_residual_is_the_routes(log):
    from fricid.identify import fit

    fitted = fit(log, "lugre", seed=0)
    route = fitted.provenance["trajectory"]["routes"]["filtered"]["rms"]["torque_filtered"]
    mine = predict_trajectory(fitted, log).metrics()["rmse_filtered"]
    # the route's RMS is over the decimated samples, this one over every sample
    assert mine == pytest.approx(route, rel=0.05)


def test_a_coarse_encoders_static_fit_is_judged_by_the_fits_acceleration():
    """The acceleration was the difference over a period of the filtered velocity, which
    passes the encoder's steps: a 4096-count log whose static fit held the truth (residual
    0.030 N m where it slides, noise 5 mN m) was reported at 0.196 N m, 37 % of the torque.
    The logs come from the derivative-window benchmark's own
    generator (``benchmarks/_encoder_truth.py``), a second seed held out."""
    import sys

    from tests._paths import REPO

    from fricid.identify.dynamic.trajectory import fit_trajectory

    sys.path.insert(0, str(REPO / "benchmarks"))
    from _encoder_truth import encoder_log

    fitted = fit_trajectory(encoder_log(0, 4096), "coulomb_viscous")
    regression = fitted.provenance["trajectory"]["routes"]["regression"]["rms"]
    own = predict_trajectory(fitted, encoder_log(0, 4096)).metrics()
    held = predict_trajectory(fitted, encoder_log(1, 4096)).metrics()
    fit_rms = next(iter(regression.values()))
    # where it slides, the report's error is the fit's own residual (same samples, same
    # derivatives) and the held-out log's is no larger than noise and encoder allow
    assert own["rmse_sliding"] == pytest.approx(fit_rms, rel=0.1)
    assert held["rmse_sliding"] < 1.3 * fit_rms
    assert own["n_sliding"] > 0.5 * own["n"]
    # the raw error is no longer the encoder's (before, the sliding samples' RMS was 3.5
    # times the fit's here); the reversals, where a static law has no break-away, keep the
    # raw RMS up, not the median
    assert own["median_abs_error"] < fit_rms and held["median_abs_error"] < fit_rms


@pytest.mark.parametrize(
    ("column", "factor", "said"),
    [("velocity", np.pi / 180, "degrees against radians"), ("time", 1e-3, "the time column")],
)
def test_a_log_with_a_wrong_unit_is_refused_as_the_fit_refuses_it(log, column, factor, said):
    """A new user's trial: ``fricid report`` scored a log whose velocity header said deg/s on
    rad/s data better than the right log, where ``fit`` refused it."""
    from dataclasses import replace

    bad = replace(log, **{column: getattr(log, column) * factor})
    with pytest.raises(DataError, match=said):
        predict_trajectory(truth_model(), bad)
