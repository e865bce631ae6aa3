"""A robot log whose channels disagree (a unit, a sign, a dead torque channel) gets no
"yes" from the whole-arm fit (``fricid.identify.dynamic.arm._channels``): each case is made
from a correct log of ``_arm_truth`` by the mistake a user makes."""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _arm_truth import CV_LAWS as LAWS
from _arm_truth import make_log

pytest.importorskip("pinocchio")

from fricid.errors import DataError
from fricid.identify.dynamic.arm import fit_arm
from fricid.identify.dynamic.arm._channels import channel_problems


@pytest.fixture(scope="module")
def log(pendulum):
    return make_log(pendulum, LAWS, duration=12.0, seed=7, noise=0.05)


def _only_first(log, array, factor):
    out = array.copy()
    out[:, 0] *= factor
    return out


def test_a_correct_log_has_no_problems(pendulum, log):
    assert channel_problems(log, pendulum) == {j: [] for j in pendulum.joints}


def test_radians_labelled_degrees_make_the_verdict_no(pendulum, log):
    # the reader multiplied a column of radians by pi/180: the position is 57x too small
    wrong = replace(log, position=_only_first(log, log.position, np.pi / 180))
    fit = fit_arm(wrong, pendulum, friction="coulomb_viscous_asym")
    first = fit.joints[0]
    assert fit.verdict(first) == "no"
    reasons = " ".join(fit.validation[first]["reasons"])
    assert "degrees against radians" in reasons and "0.0175x" in reasons


def test_degrees_labelled_radians_and_a_reversed_velocity_are_named(pendulum, log):
    degrees = replace(log, position=_only_first(log, log.position, 180 / np.pi))
    found = channel_problems(degrees, pendulum)[pendulum.joints[0]]
    assert any("degrees against radians" in f for f in found)
    reversed_ = replace(log, velocity=_only_first(log, log.velocity, -1.0))
    (text,) = channel_problems(reversed_, pendulum)[pendulum.joints[0]]
    assert "sign reversed" in text
    assert channel_problems(reversed_, pendulum)[pendulum.joints[1]] == []


def test_a_velocity_from_the_position_is_not_checked_against_it(pendulum, log):
    wrong = replace(log, velocity=_only_first(log, log.velocity, 3.0))
    assert channel_problems(wrong, pendulum)[pendulum.joints[0]]
    said = replace(wrong, meta={"velocity_from": "position (central difference)"})
    assert channel_problems(said, pendulum)[pendulum.joints[0]] == []


def test_a_position_past_the_urdf_limits_is_named(pendulum, log):
    # the example has no limits: give it the range the log moves in, then log degrees
    lo, hi = log.position.min(axis=0), log.position.max(axis=0)
    limited = replace(pendulum, lower=lo - 0.01, upper=hi + 0.01)
    assert channel_problems(log, limited) == {j: [] for j in pendulum.joints}
    degrees = log.position.copy()
    degrees[:, 1] *= 180 / np.pi
    said = {"velocity_from": "position (central difference)"}  # not the velocity check
    found = channel_problems(replace(log, position=degrees, meta=said), limited)
    limits, steps = sorted(found[pendulum.joints[1]])  # both say it
    assert "beyond the URDF's limits" in limits and "degrees labelled radians" in limits
    assert "131072-count encoder with the column in degrees" in steps, steps
    assert found[pendulum.joints[0]] == []
    # the encoder's steps tell it without limits, too
    unlimited = channel_problems(replace(log, position=degrees, meta=said), pendulum)
    (text,) = unlimited[pendulum.joints[1]]
    assert "in degrees labelled radians" in text


def test_a_torque_channel_never_logged_is_refused(pendulum, log):
    dead = log.torque.copy()
    dead[:, 1] = 0.0
    with pytest.raises(DataError, match="in every one of the") as err:
        fit_arm(replace(log, torque=dead), pendulum)
    assert err.value.column == f"{pendulum.joints[1]}.torque"


def test_a_log_too_short_names_the_part_and_the_file_length(pendulum, log):
    """The fit holds out the last quarter: a short log fails on a part, and says which."""
    short = log.slice(0, 40)
    with pytest.raises(DataError, match="of the log's 40 samples is too short") as err:
        fit_arm(short, pendulum, friction="coulomb_viscous_asym")
    assert "quarter" in str(err.value)


def test_a_coarse_encoder_is_not_read_as_motion(pendulum):
    """2^14 counts at 1 kHz: the differenced position's quantisation noise, rising to
    Nyquist, had put the motion's bandwidth at hundreds of Hz, the cut-off at 450 Hz and
    every joint under its velocity-noise threshold ("no joint moves"). Its expected
    periodogram is now taken out: the bandwidth is the motion's (harmonics up to 0.7 Hz)."""
    from fricid.identify.dynamic.arm._signals import choose_cutoff, encoder_step, torque_noise

    coarse = make_log(pendulum, LAWS, duration=12.0, seed=7, counts=2**14)
    step = encoder_step(coarse.position, None)
    _cut, bounds = choose_cutoff(
        coarse.position, 1000.0, step, torque_noise(coarse.torque), np.ones(2)
    )
    assert bounds["motion"] < 2.0, bounds
    fit = fit_arm(coarse, pendulum, friction="coulomb_viscous_asym")
    assert all(fit.friction[j]["parameters"]["f_c_pos"]["value"] is not None for j in fit.joints)


def test_motion_under_the_encoder_noise_says_what_to_do(pendulum):
    coarse = make_log(pendulum, LAWS, duration=12.0, seed=7, counts=2**14)
    with pytest.raises(DataError, match=r"velocity noise lets it be seen.*lower --cutoff"):
        fit_arm(coarse, pendulum, friction="coulomb_viscous_asym", cutoff=450.0)


def test_a_wrapped_angle_makes_the_joint_no(pendulum, log):
    turning = log.position.copy()
    turning[:, 0] += 4.0 * (log.time - log.time[0])
    velocity = log.velocity.copy()
    velocity[:, 0] += 4.0
    wrapped = turning.copy()
    wrapped[:, 0] = (turning[:, 0] + np.pi) % (2 * np.pi) - np.pi
    assert channel_problems(replace(log, position=turning, velocity=velocity), pendulum) == {
        j: [] for j in pendulum.joints
    }
    found = channel_problems(replace(log, position=wrapped, velocity=velocity), pendulum)
    (text,) = found[pendulum.joints[0]]
    assert "wrapped to one turn" in text


def test_a_failed_fit_names_the_channels_that_disagree(pendulum, log):
    short = log.slice(0, 40)
    wrong = replace(short, velocity=_only_first(short, short.velocity, 180 / np.pi))
    with pytest.raises(DataError, match="too short") as err:
        fit_arm(wrong, pendulum, friction="coulomb_viscous_asym")
    assert "channels also disagree, which may be why" in str(err.value)
    assert "degrees against radians" in str(err.value)
    with pytest.raises(DataError) as clean:
        fit_arm(short, pendulum, friction="coulomb_viscous_asym")
    assert "disagree" not in str(clean.value)
