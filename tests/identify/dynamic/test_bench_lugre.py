"""The independent LuGre simulator of ``benchmarks/bench_lugre.py`` and the benchmark's
counting: its logs are what a drive logs and what fricid reads, its integration agrees with
Radau, and open intervals and refused logs count as misses."""

from __future__ import annotations

import json
import math
import sys

import numpy as np
import pytest
from tests._paths import REPO

sys.path.insert(0, str(REPO / "benchmarks"))
import _lugre_truth as lt
import bench_lugre as bench
from fricid.io import read_rawlog


@pytest.mark.slow  # 2.9 s measured under load (numba compiles the right-hand side)
def test_rk4_agrees_with_radau():
    """The same applied torque sequence, integrated by scipy's Radau: the fixed-step RK4
    positions agree to 1e-9 rad (an encoder of 2^24 counts resolves 4e-7)."""
    truth = lt.TRUTHS["slow_stribeck"]
    assert lt.radau_check(truth, "torque_steps", 0.05, 200.0, 3) < 1e-9


@pytest.mark.slow  # 3.3 s measured under load (1.2 million RK4 steps, a CSV written and read)
def test_log_is_what_a_drive_logs_and_fricid_reads(tmp_path):
    truth, cpr, rate = lt.TRUTHS["geared"], 2**17, 200.0
    log = lt.simulate(truth, "trapezoid_pd", 6.0, rate, cpr, 4)
    counts = log["position"] / (2 * math.pi / cpr)
    assert np.allclose(counts, np.round(counts), atol=1e-6)  # on the encoder's grid
    assert np.max(np.abs(log["position"] - log["true_position"])) <= math.pi / cpr + 1e-12
    assert np.allclose(np.diff(log["position"]) * rate, log["velocity"][1:])
    assert np.allclose(np.diff(log["velocity"]) * rate, log["acceleration"][1:])
    assert 0.5 * truth.noise < np.std(log["torque"] - log["applied"]) < 1.5 * truth.noise
    plan = log["plan"]
    assert np.max(np.abs(log["true_position"] - plan.ref_q)) < 0.1  # tracked under PD
    assert np.any(np.diff(np.sign(plan.ref_v[plan.ref_v != 0])) != 0)  # reversals
    path = lt.write_log(log, tmp_path / "t.csv", truth, {"kind": "trapezoid_pd"})
    read = read_rawlog(path)
    assert np.allclose(read.position, log["position"], rtol=0, atol=1e-12)
    assert np.allclose(read.torque, log["torque"], rtol=1e-11)
    info = json.loads(path.with_suffix(".truth.json").read_text())
    assert info["fricid"]["p_y"] == pytest.approx(truth.mgl * math.cos(truth.phi))
    back = lt.from_fricid(truth.fricid_names())
    assert np.allclose(back.array(), truth.array())


def test_creep_stays_below_break_away():
    log = lt.simulate(lt.TRUTHS["geared"], "creep", 2.0, 1000.0, 2**20, 1)
    assert np.ptp(log["true_position"]) < 1e-3  # pre-sliding: well under a milliradian
    assert np.ptp(log["position"]) > 0  # but seen by a 2^20 encoder


def test_the_benchmark_counts_open_intervals_and_refusals_as_misses():
    truth = lt.TRUTHS["geared"].fricid_names()
    est = {
        n: {"value": v, "ci95": [v - 0.1 * abs(v) - 1e-9, v + 0.1 * abs(v) + 1e-9], "closed": True}
        for n, v in truth.items()
    }
    row = {"truth": "geared", "kind": "chirp_pd", "estimates": est}
    assert all(bench._covered(row, n) for n in bench.PARAMS)
    est["sigma_1"]["closed"] = False  # at a bound of the search box
    est["tau_s"]["ci95"] = [float("nan"), float("nan")]  # withheld
    assert not bench._covered(row, "sigma_1") and not bench._covered(row, "tau_s")
    assert not bench._covered({"truth": "geared", "refused": "no"}, "tau_c")
    assert bench._fmt_err(8.4e27, False) == "x8.4e+27" and bench._fmt_err(0.5, False) == "+50%"
