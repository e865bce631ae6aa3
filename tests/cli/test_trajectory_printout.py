"""The printout of a trajectory fit: a rate bias larger than its estimate is given in the
parameter's unit (not as 8.4e29 %), a corrected value outside the search box is said to be
unusable, and an infinite passivity margin is a sentence, not "margin undefined"."""

from __future__ import annotations

import dataclasses

from _trajectory import truth_model
from fricid.cli.trajectory import trajectory_text


def fitted_with(rate_bias: dict, passivity: dict):
    fitted = truth_model(sigma_1=0.001)
    fitted.provenance["trajectory"].update(
        derivative={"method": "savgol", "source": "position"},
        rate_bias={"log_rate": 1000.0, "internal_rate": 16000.0, **rate_bias},
        passivity=passivity,
    )
    return fitted


CONDITION = "sigma_1 <= 4 sigma_2 tau_c / (tau_s - tau_c) (Barabanov and Ortega 2000)"


def test_a_huge_rate_bias_is_absolute_and_an_infinite_margin_a_sentence():
    b = 27.92
    text = trajectory_text(
        fitted_with(
            {
                "sigma_0": {"log10_bias": -0.009, "relative": 10**-0.009 - 1, "corrected": 1.4e8},
                "sigma_1": {"log10_bias": b, "relative": 10**b - 1, "corrected": 0.001 * 10**-b},
            },
            {"margin": None, "passive": True, "passive_across_ci95": None, "condition": CONDITION},
        )
    )
    line = next(x for x in text.splitlines() if "rate bias" in x)
    assert "e+29 %" not in line and "e+27 %" not in line
    assert "sigma_0 -2.1 % (corrected 1.4e+08, outside the search box [100, 1e+07]" in line
    assert "sigma_1 +0.001 N m s/rad (a factor 8.32e+27" in line
    assert line.count("not a usable value") == 2
    line = next(x for x in text.splitlines() if "passivity" in x)
    assert "undefined" not in line
    assert "passive for any sigma_1 (tau_s <= tau_c: no Stribeck peak" in line
    assert "across the 95 % intervals: no intervals" in line


def test_an_ordinary_rate_bias_stays_relative_and_the_box_edge_is_inside():
    text = trajectory_text(
        fitted_with(
            {
                "sigma_0": {"log10_bias": -0.0091, "relative": -0.0207, "corrected": 12156.7},
                "sigma_1": {
                    "log10_bias": 4e-10,
                    "relative": 9.7e-10,
                    "corrected": 0.000999999999030818,
                },
            },
            {"margin": 1.39, "passive": True, "passive_across_ci95": False, "condition": CONDITION},
        )
    )
    line = next(x for x in text.splitlines() if "rate bias" in x)
    assert "sigma_0 -2.1 % (corrected 1.216e+04)" in line and "usable" not in line
    assert "passive (margin 1.39 N m s/rad; across the 95 % intervals: not guaranteed)" in text


def test_an_undetermined_parameter_gets_no_corrected_value_and_passivity_says_what_it_rests_on():
    """sigma_1 at the search box's edge, flagged not determined: no corrected value is
    offered for it, and the passivity line says it rests on it (a new user's trial found
    both printed as if sigma_1 were known)."""
    fitted = fitted_with(
        {
            "sigma_0": {"log10_bias": -0.0091, "relative": -0.0207, "corrected": 12156.7},
            "sigma_1": {"log10_bias": 0.2, "relative": 0.58, "corrected": 0.00158},
        },
        {"margin": 1.39, "passive": True, "passive_across_ci95": False, "condition": CONDITION},
    )
    par = fitted.parameters["sigma_1"]
    fitted.parameters["sigma_1"] = dataclasses.replace(par, not_determined=True)
    text = trajectory_text(fitted)
    line = next(x for x in text.splitlines() if "rate bias" in x)
    # the move is given, as the rate-bias warning gives it (a new user read the two as
    # contradicting each other), but no corrected value
    assert "sigma_1 not determined (the simulation at the estimate moved it +58 %; " in line
    assert "no corrected value to give)" in line and "corrected 0.00158" not in line
    assert "sigma_0 -2.1 % (corrected 1.216e+04)" in line
    line = next(x for x in text.splitlines() if "passivity" in x)
    assert line.endswith("(it rests on sigma_1, not determined)")


def test_the_joints_parameters_carry_their_units():
    """A new user read "inertia: 0.0201348 +/- 0.00018" without a unit."""
    fitted = fitted_with(
        {"skipped": "off"}, {"margin": 1.0, "passive": True, "condition": CONDITION}
    )
    fitted.provenance["trajectory"]["joint"] = {
        n: {"value": v, "stderr": 0.1, "ci95_low": v - 0.2, "ci95_high": v + 0.2}
        for n, v in (("inertia", 0.02), ("p_x", -0.5), ("p_y", 1.5))
    }
    text = trajectory_text(fitted)
    assert "    inertia: 0.02 kg m^2 +/- 0.1 (95 % CI [-0.18, 0.22])" in text
    assert "    p_x: -0.5 N m +/- 0.1" in text and "    p_y: 1.5 N m +/- 0.1" in text


def test_the_intervals_line_says_which_widening_the_log_took():
    fitted = fitted_with(
        {"skipped": "off"}, {"margin": 1.0, "passive": True, "condition": CONDITION}
    )
    fitted.provenance["trajectory"]["calibration"] = {
        "factors": {"sigma_0": 2.94},
        "rest_share": 0.43,
        "resting": True,
    }
    line = next(x for x in trajectory_text(fitted).splitlines() if "intervals:" in x)
    assert "(sigma_0 x2.94; sigma_0 on a log scale; the log rests 43 % of its time: the " in line
    assert "factors of logs that rest;" in line
