"""A symmetric law (stribeck, lugre) fitted to friction that differs by direction says so,
or says that the log cannot tell (:func:`fricid.identify.dynamic._outcome.direction_caveat`).

The logs come from the independent simulator of ``benchmarks/bench_lugre.py``
(``benchmarks/_lugre_truth.py``: its own RK4 joint and PD drive, a 2^20-count encoder), the
negative direction's Coulomb and break-away levels ``neg`` times the positive's. Before,
only ``coulomb_viscous`` was tested: a LuGre joint 30 % weaker backwards got p_x -0.776
[-0.778, -0.774] for -0.591, and nothing said why.
"""

from __future__ import annotations

import dataclasses
import re
import sys
import warnings
from pathlib import Path

import pytest
from tests._paths import REPO

from fricid.cli.trajectory import trajectory_text
from fricid.identify import fit
from fricid.identify.trust import assess_trust
from fricid.io import read_rawlog

sys.path.insert(0, str(REPO / "benchmarks"))
import _lugre_truth as lt


def fit_log(truth: str, kind: str, neg: float, seed: int, model: str, tmp_path):
    """(the fit, its trajectory provenance, the truth in fricid's names) of a 10 s log."""
    t = dataclasses.replace(lt.TRUTHS[truth], neg=neg)
    log = lt.simulate(t, kind, 10.0, 1000.0, 2**20, seed)
    path = lt.write_log(log, tmp_path / "a.csv", t, {})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(read_rawlog(path), model, seed=seed)
    return fitted, fitted.provenance["trajectory"], t.fricid_names()


def gravity_held(info: dict, truth: dict) -> bool:
    j = info["joint"]
    return all(j[n]["ci95_low"] <= truth[n] <= j[n]["ci95_high"] for n in ("p_x", "p_y"))


def test_a_stribeck_fit_of_a_joint_weaker_backwards_says_the_friction_differs(tmp_path):
    fitted, info, truth = fit_log("geared", "chirp_pd", 0.7, 3, "stribeck", tmp_path)
    assert not gravity_held(info, truth)  # the gravity took up the difference
    caveats = info.get("caveats", [])
    assert any(c.startswith("the friction differs by direction") for c in caveats), caveats
    assert any("fit stribeck_asym" in c for c in caveats)
    # each difference with its standard error: the test's p may come from either (a new
    # user's LuGre fit printed backwards-stronger levels, bare, the significance the viscous
    # difference's)
    assert any("their difference" in c and "+/- one standard error" in c for c in caveats)
    # the small motion cannot tell the gravity from the difference: said too (it was left
    # out where the difference showed)
    assert "rests on the friction being the same both ways" in info["gravity_note"]
    trust = assess_trust(fitted, None)  # as fit --trajectory
    assert trust.level == "with caveats"
    assert any(r.startswith("the friction differs by direction") for r in trust.reasons)


def test_a_symmetric_joint_on_a_small_range_gets_a_note_on_the_gravity_only(tmp_path):
    """The chirp moves 0.3 rad: cos q hardly changes, so the gravity's p_x is told from a
    difference by direction only by taking the friction symmetric. No caveat (the log shows
    no difference), a note that says what p_x rests on."""
    fitted, info, _ = fit_log("geared", "chirp_pd", 1.0, 3, "stribeck", tmp_path)
    assert not any("direction" in c for c in info.get("caveats", []))
    note = info["gravity_note"]
    assert "rests on the friction being the same both ways" in note and "p_x" in note
    assert "p_y" not in note  # sin q changes: p_y is told apart
    assert f"    gravity: {note}" in trajectory_text(fitted)


def test_a_symmetric_joint_over_its_range_gets_neither(tmp_path):
    _, info, _ = fit_log("geared", "trapezoid_pd", 1.0, 3, "stribeck", tmp_path)
    assert not any("direction" in c for c in info.get("caveats", []))
    assert "gravity_note" not in info


@pytest.mark.slow
def test_lugre_on_a_joint_weaker_backwards_says_so_and_what_it_takes_up(tmp_path):
    _, info, truth = fit_log("slow_stribeck", "trapezoid_pd", 0.8, 4, "lugre", tmp_path)
    caveats = info.get("caveats", [])
    assert any(c.startswith("the friction differs by direction") for c in caveats), caveats
    assert any("this LuGre has one Coulomb and break-away level" in c for c in caveats)
    assert any("fit lugre_asym" in c for c in caveats)
    # the bristles too (a new user's joint with a torque offset: sigma_0, sigma_1 9x and 3x
    # low inside closed intervals, the caveat naming the levels and gravity only)
    assert any("sigma_0, sigma_1 take up the misfit" in c for c in caveats)
    assert any("a torque sensor's offset looks the same" in c for c in caveats)
    assert not gravity_held(info, truth)


@pytest.mark.slow
def test_lugre_on_a_small_range_with_a_hint_of_a_difference_says_it_may_differ(tmp_path):
    """The case of the module notes: 30 % weaker backwards, a 0.3 rad chirp; the levels'
    difference about two standard errors from zero, the gravity unable to tell."""
    _, info, truth = fit_log("geared", "chirp_pd", 0.7, 3, "lugre", tmp_path)
    assert not gravity_held(info, truth)
    caveats = info.get("caveats", [])
    assert any(c.startswith("the friction may differ by direction") for c in caveats), caveats


def test_dahl_on_a_joint_weaker_backwards_says_so(tmp_path):
    _, info, _ = fit_log("slow_stribeck", "trapezoid_pd", 0.8, 4, "dahl", tmp_path)
    caveats = info.get("caveats", [])
    assert any(c.startswith("the friction differs by direction") for c in caveats), caveats
    assert any("fricid's Dahl has one Coulomb level" in c for c in caveats)


#: The shared foreign logs: another simulator's symmetric LuGre joint (their README).
FOREIGN = Path(__file__).resolve().parents[3].parent / "shared" / "data" / "foreign" / "lugre"


@pytest.mark.slow  # 4-5 s a log: 20 s at 1 kHz
@pytest.mark.parametrize(
    "name",
    [
        f"{kind}_1000Hz_{cpr}cpr"
        for kind in ("chirp_pd", "trapezoid_pd")
        for cpr in (131072, 1048576)
    ],
)
def test_no_false_alarm_on_another_simulators_symmetric_joint(name):
    """A second opinion on the false alarms: the foreign logs' joint has one level both ways."""
    from fricid.identify.dynamic.trajectory import fit_trajectory

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit_trajectory(read_rawlog(FOREIGN / f"{name}.csv"), "stribeck")
    caveats = fitted.provenance["trajectory"].get("caveats", [])
    assert not any("by direction" in c for c in caveats), caveats


@pytest.mark.slow  # 11 s under the default run's load: two LuGre fits
def test_the_mirrored_log_swaps_the_levels(tmp_path):
    """Mirroring the joint (q, v, torque -> -q, -v, -torque) swaps the directions: the
    per-direction levels come out swapped, the difference of opposite sign, the same test."""
    from fricid.identify.dynamic.trajectory import fit_trajectory
    from fricid.samples import RawLog

    t = dataclasses.replace(lt.TRUTHS["slow_stribeck"], neg=0.8)
    log = read_rawlog(lt.write_log(lt.simulate(t, "trapezoid_pd", 10.0, 1000.0, 2**20, 4),
                                   tmp_path / "a.csv", t, {}))  # fmt: skip
    mirror = RawLog(
        time=log.time,
        position=-log.position,
        velocity=-log.velocity,
        torque=-log.motor_torque,
        temperature=log.temperature,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        texts = [
            fit_trajectory(x, "stribeck").provenance["trajectory"]["caveats"][0]
            for x in (log, mirror)
        ]
    levels = [re.search(r"Coulomb ([\d.]+) / ([\d.]+) N m", c).groups() for c in texts]
    assert texts[0].startswith("the friction differs by direction")
    assert texts[1].startswith("the friction differs by direction")
    (a, b), (c, d) = ((float(x), float(y)) for x, y in levels)
    assert a > b and c == pytest.approx(b, rel=1e-3) and d == pytest.approx(a, rel=1e-3)


def _stage(values: dict[str, float], stderr: dict[str, float]):
    """A regression's estimate (:class:`fricid.identify.dynamic._routes._Stage`) with
    independent parameters of the given standard errors."""
    import numpy as np

    from fricid.identify.dynamic._routes import _Stage

    names = list(values)
    v = np.array([values[n] for n in names])
    s = np.array([stderr[n] for n in names])
    return _Stage(names, v, s, v - 1.96 * s, v + 1.96 * s, np.diag(s**2), None, 0.0, 20, {}, None)


def test_the_gravity_note_does_not_quote_levels_the_regression_left_undetermined():
    """Beyond a Stribeck rise a trapezoid slides at its plateaus' speeds only, where the
    Coulomb levels and the viscous terms are one number each: the cdw95 trapezoid (1 kHz, 2^20
    counts/rev, seed 0) put both levels at 3.4e-13 N m with a standard error of 2.7, and the
    note read "its 95 % interval +/- 5.2 N m against their mean 3.4e-13 N m". The note holds
    (the gravity rests on the symmetry), without a mean that means nothing."""
    from fricid.identify.dynamic._direction import direction_caveat

    se = {"f_c_pos": 1.9, "beta_pos": 0.5, "f_c_neg": 1.9, "beta_neg": 0.5, "p_x": 0.094}
    asym = _stage(
        {"f_c_pos": 3.4e-13, "beta_pos": 1.4, "f_c_neg": 3.4e-13, "beta_neg": 1.4, "p_x": -0.04},
        se,
    )
    symmetric = _stage(
        {"f_c": 1.1, "beta": 0.3, "p_x": -0.04}, {"f_c": 0.01, "beta": 0.01, "p_x": 0.0041}
    )
    caveat, note = direction_caveat(asym, "lugre", symmetric)
    assert caveat == ""
    assert "does not tell the gravity" in note and "p_x -0.04 +/- 0.094" in note
    assert "e-13" not in note and "mean" not in note, note
    assert "too few speeds" in note, note
    assert "difference is 0 N m with a standard error of 1.9" not in note  # 2.7 = 1.9 sqrt 2
    assert "difference is 0 N m with a standard error of 2.7" in note, note
    # where the levels are determined, their mean is the yardstick the note gives
    se = {**se, "f_c_pos": 0.2, "f_c_neg": 0.2}
    asym = _stage(
        {"f_c_pos": 1.0, "beta_pos": 0.4, "f_c_neg": 1.05, "beta_neg": 0.4, "p_x": -0.04}, se
    )
    _, note = direction_caveat(asym, "lugre", symmetric)
    assert "its 95 % interval +/- 54 % of their mean" in note, note


def test_the_direction_test_weighs_its_few_clusters():
    """With fewer than MIN_CLUSTERS clusters the test says the friction may differ, not that it
    does: four clusters (a 2 s log) had called a symmetric virtual joint's friction different
    by direction at p = 9e-9."""
    from fricid.cli.simulate import _trajectory_log

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(_trajectory_log("multisine", 2.0, 0), "lugre")  # simulate's own log
    caveats = " ".join(fitted.provenance["trajectory"].get("caveats", []))
    assert "friction differs by direction" not in caveats
    assert "independent stretches of the log, too few to settle it" in caveats
