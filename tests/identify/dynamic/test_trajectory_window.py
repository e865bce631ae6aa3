"""The derivative window from the encoder (:mod:`fricid.identify.dynamic._window`).

A coarse encoder's steps are noise in the acceleration the regression of a static model
takes, and noise in a regressor biases least squares: a new user's log through 4096
counts/rev gave J = 0.00108 [0.00084, 0.0013] for a truth of 0.01, with f_c, beta and p_y
outside their intervals too. The logs here come from this module's own generator (a
prescribed multi-sine of random frequencies, the torque by inverse dynamics, the encoder
counting by floor, the velocity logged as backward differences), not the virtual joint's.
"""

from __future__ import annotations

import sys
import warnings

import pytest
from tests._paths import REPO

from fricid.errors import ConfigError
from fricid.identify.dynamic.trajectory import (
    DerivativeBiasWarning,
    DerivativeFilter,
    fit_trajectory,
)
from fricid.identify.trust import assess_trust

sys.path.insert(0, str(REPO / "benchmarks"))
from _encoder_truth import TRUTH, encoder_log


def estimates(fitted) -> dict[str, tuple[float, float, float]]:
    """Every parameter's value and 95 % interval."""
    out = {n: (p.value, *p.ci95) for n, p in fitted.parameters.items()}
    joint = fitted.provenance["trajectory"]["joint"]
    out.update({n: (r["value"], r["ci95_low"], r["ci95_high"]) for n, r in joint.items()})
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_coarse_encoder_gets_a_wider_window_and_intervals_that_cover(seed):
    with warnings.catch_warnings():
        warnings.simplefilter("error", DerivativeBiasWarning)
        fitted = fit_trajectory(encoder_log(seed, 4096), "coulomb_viscous")
    d = fitted.provenance["trajectory"]["derivative"]
    assert d["window"] > 0.04 and d["bias"]["widened_from"] == pytest.approx(0.021)
    got = estimates(fitted)
    low, high = got["inertia"][1:]
    assert low <= TRUTH["inertia"] <= high and abs(got["inertia"][0] / TRUTH["inertia"] - 1) < 0.03
    z = {n: (v - TRUTH[n]) / ((hi - lo) / 3.92) for n, (v, lo, hi) in got.items()}
    assert all(abs(x) < 3.0 for x in z.values()), z  # before: J's z about -70
    caveats = fitted.provenance["trajectory"].get("caveats", [])
    assert not any("differs by direction" in c for c in caveats), caveats


def test_a_given_window_is_kept_corrected_and_warned_about():
    log = encoder_log(0, 4096)
    with pytest.warns(DerivativeBiasWarning, match="inertia"):
        fitted = fit_trajectory(log, "coulomb_viscous", derivative=DerivativeFilter())
    bias = fitted.provenance["trajectory"]["derivative"]["bias"]
    assert fitted.provenance["trajectory"]["derivative"]["window"] == pytest.approx(0.021)
    assert bias["noise_share"] > 0.5 and bias["applied"] and "widened_from" not in bias
    _, low, high = estimates(fitted)["inertia"]
    assert low <= TRUTH["inertia"] <= high  # before: 0.0027 [0.0018, 0.0035], no warning
    assert high - low > 0.2 * TRUTH["inertia"]  # the correction's own error is carried
    trust = assess_trust(fitted)
    assert trust.level != "yes"
    assert any("derivative window (21 ms)" in r for r in trust.reasons), trust.reasons


def test_a_fine_encoder_keeps_the_default_window():
    with warnings.catch_warnings():
        warnings.simplefilter("error", DerivativeBiasWarning)
        fitted = fit_trajectory(encoder_log(0, 2.0**20), "coulomb_viscous")
    d = fitted.provenance["trajectory"]["derivative"]
    assert d["window"] == pytest.approx(0.021) and "widened_from" not in d["bias"]
    got = estimates(fitted)
    assert all(lo <= TRUTH[n] <= hi for n, (_, lo, hi) in got.items()), got


@pytest.mark.parametrize("seed", [0, 1])
def test_a_fast_small_oscillation_keeps_its_samples(seed):
    """2-5 Hz through about 50 counts of 4096: the joint slows down every 0.1 s, and the 0.2 s
    guard after each slow stretch had left 365-886 of 20000 samples (J 0.0015-0.0047 for
    0.02); the guard is now a quarter of the median sliding stretch at most."""
    log = encoder_log(seed, 4096, band=(2.0, 5.0), amplitudes=(0.02, 0.012, 0.008))
    fitted = fit_trajectory(log, "coulomb_viscous")
    assert fitted.statistics["ndata"] > 0.4 * log.time.size
    got = estimates(fitted)
    assert abs(got["inertia"][0] / TRUTH["inertia"] - 1) < 0.05
    assert abs(got["f_c"][0] / TRUTH["f_c"] - 1) < 0.02


@pytest.mark.slow  # 6 s under the default run's load
def test_stribeck_without_a_rise_keeps_every_interval_around_its_value():
    """A correction is not applied where the interval reaches the search box: a delta with a
    standard error of 25 in [0.2, 4] had been moved to the far bound, its interval [0.2,
    0.2]."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit_trajectory(encoder_log(0, 4096), "stribeck")
    for name, p in fitted.parameters.items():
        if p.stderr is not None and p.stderr > 0 and p.ci95[0] is not None:
            assert p.ci95[0] < p.ci95[1] and p.ci95[0] <= p.value <= p.ci95[1], (name, p)
    bias = fitted.provenance["trajectory"]["derivative"]["bias"]
    assert "delta" in bias["not_applied"]
    low, high = fitted.parameters["tau_c"].ci95
    assert low <= TRUTH["f_c"] <= high


def test_counts_coarser_than_the_position_are_refused():
    """A 4096-count log given as 1024 counts per revolution had been accepted silently."""
    log = encoder_log(0, 4096)
    with pytest.raises(ConfigError, match=r"steps of 0\.001534 rad"):
        fit_trajectory(log, "coulomb_viscous", encoder_counts=1024)
    fitted = fit_trajectory(log, "coulomb_viscous", encoder_counts=4096)
    assert fitted.provenance["trajectory"]["encoder"]["source"] == "option"


def test_a_noise_free_fast_log_gets_a_narrower_window():
    """Where the filter's bending outweighs the noise already, narrower windows are tried
    (the trial's noise-free logs had been warned about at 21 ms)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit_trajectory(encoder_log(0, 2.0**40, band=(1.0, 3.0)), "coulomb_viscous")
    d = fitted.provenance["trajectory"]["derivative"]
    assert d["window"] < 0.015 and d["bias"]["narrowed_from"] == pytest.approx(0.021)
    got = estimates(fitted)
    assert all(lo <= TRUTH[n] <= hi for n, (_, lo, hi) in got.items()), got
