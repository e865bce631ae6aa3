"""A dynamic law's parameter whose 95 % interval reaches one end of its search range is not
determined (issue 26), and the printouts give no absurd percentages.

The log comes from the independent simulator of ``benchmarks/bench_lugre.py``
(``benchmarks/_lugre_truth.py``): Canudas de Wit 1995's joint, a PD-tracked trapezoid at
1 kHz through 2^20 counts/rev. Its fit put sigma_2 at 7e-7 N m s/rad in [0, 1.31] (truth 0.4)
and tau_c at 1.47 N m in [0, 3.7] (truth 1) with only an "at boundary" flag. Since the search
also starts from a falling Stribeck curve (``test_lugre_search.py``) those two are found
(0.4018 and 0.9985 in closed intervals; the start's levels from every sliding sample, since
beyond the rise the trapezoid's plateaus do not split them: ``_direction.start_levels``) and
w_s is a parameter the data bound on one side only (truth 1 mrad/s, interval from the box's
lower end to 5.2 mrad/s, widened).
"""

from __future__ import annotations

import re
import sys
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from tests._paths import REPO

from fricid.export._common import summary_lines
from fricid.fitted import Parameter
from fricid.identify import fit
from fricid.identify.dynamic._direction import _gravity_by_symmetry
from fricid.identify.dynamic._result import one_sided
from fricid.io import read_rawlog

sys.path.insert(0, str(REPO / "benchmarks"))
import _lugre_truth as lt


@pytest.mark.slow  # 19 s under the default run's load: a LuGre fit with its checks
def test_an_interval_open_at_one_end_leaves_a_dynamic_parameter_not_determined(tmp_path):
    truth = lt.TRUTHS["cdw95"]
    log = lt.simulate(truth, "trapezoid_pd", 10.0, 1000.0, 2**20, 0)
    raw = read_rawlog(lt.write_log(log, tmp_path / "cdw.csv", truth, {}))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(raw, "lugre", seed=0)
    for name in ("sigma_2", "tau_c"):  # the falling start's valley (from every sliding sample)
        p = fitted.parameters[name]
        assert not p.not_determined and p.ci95[0] <= truth.fricid_names()[name] <= p.ci95[1]
    one_end = {n: p for n, p in fitted.parameters.items() if p.low_open != p.high_open}
    assert "w_s" in one_end  # the fit this test is written for
    for name, p in one_end.items():
        assert p.not_determined, name
    w_s = fitted.parameters["w_s"]
    assert w_s.note.startswith("not determined"), w_s.note  # its own reason may come first
    assert w_s.ci95[0] == w_s.bounds[0] and w_s.ci95[1] > 0.001  # the one bound is kept
    note = fitted.provenance["trajectory"].get("gravity_note") or ""
    assert not re.search(r"\d{4,} %", note), note  # no 8e17 % of levels near zero
    lines = summary_lines(fitted)  # an export's comment, when told to export it anyway
    (said,) = [line for line in lines if line.startswith("NOT DETERMINED")]
    high = f"{w_s.ci95[1]:.4g}"
    assert f"w_s (the data: at most {high} rad/s)" in said, said
    (estimator,) = [line for line in lines if line.startswith("estimator:")]
    assert "more characters" not in estimator  # fricid's own name, whole


def test_a_static_law_keeps_an_open_end_as_a_flag():
    p = Parameter("tau_v", 1e-9, bounds=(0.0, 1.0), stderr=0.1, ci95=(0.0, 0.2), low_open=True)
    assert one_sided({"tau_v": p}, dynamic=False)["tau_v"] is p
    flagged = one_sided({"tau_v": p}, dynamic=True)["tau_v"]
    assert flagged.not_determined and "at most 0.2" in flagged.note


def test_levels_near_zero_are_given_in_newton_metres():
    def stage(se):
        return SimpleNamespace(names=["p_x"], stderr=np.array([se]), values=np.array([0.01]))

    text = _gravity_by_symmetry(stage(1.0), stage(0.01), 1e-15, 2.7, 1e-17, True)
    assert "+/- 5.3 N m against their mean 5e-18 N m" in text
    assert "% of their mean" not in text  # no share of a mean near zero
    # levels the regression did not determine: no mean at all (test_trajectory_direction.py)
    text = _gravity_by_symmetry(stage(1.0), stage(0.01), 1e-15, 2.7, 1e-17, False)
    assert "+/- 5.3 N m, the levels themselves not determined" in text
    assert "mean" not in text
    share = _gravity_by_symmetry(stage(1.0), stage(0.01), 0.1, 0.3, 2.0, True)
    assert "+/- 59 % of their mean" in share
