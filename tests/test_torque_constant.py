"""The torque constant K of eq. 13 (issue 13): from a joint torque sensor beside the motor
current (with the gear efficiency when both power flows were logged), or from a known gravity
load; on the virtual joint with a current channel of known K and efficiency."""

from __future__ import annotations

import re

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import DataError
from fricid.extract import extract
from fricid.extract.torque_constant import fit_torque_constant, torque_constant_from_gravity
from fricid.io import write_rawlog
from fricid.samples import RawLog
from fricid.sim import preset, simulate_log, true_gravity

K, ETA = 0.08, 0.9  # N m/A and the gear efficiency of the added current channel
Z = 5.0


@pytest.fixture(scope="module")
def sensor_log():
    """The paper1 virtual joint (gravity makes both power flows occur) with its torque as a
    joint torque sensor would log it and a motor current of known K and efficiency."""
    s = preset("paper1", "quick")
    log = simulate_log(s, seed=3)
    rng = np.random.default_rng(0)
    tau = log.current * log.torque_constant
    motoring = tau * log.velocity > 0
    current = np.where(motoring, tau / (ETA * K), ETA * tau / K) + rng.normal(0, 0.02, len(log))
    return RawLog(
        time=log.time,
        position=log.position,
        velocity=log.velocity,
        temperature=log.temperature,
        torque=tau + rng.normal(0, 0.002, len(log)),
        current=current,
        source="sensor-log",
    )


def test_k_and_efficiency_from_a_torque_sensor(sensor_log):
    fit = fit_torque_constant(sensor_log)
    assert abs(fit.K - K) <= Z * fit.K_se and fit.K_se < 1e-3
    lo, hi = fit.ci95
    assert lo < fit.K < hi and hi - lo < 4.5 * fit.K_se
    assert abs(fit.efficiency - ETA) <= Z * fit.efficiency_se
    assert abs(fit.K_motoring - ETA * K) <= Z * fit.K_motoring_se
    assert "gear efficiency" in fit.summary()


def test_streamed_chunks_give_the_same_answer(sensor_log):
    whole = fit_torque_constant(sensor_log, block_rows=5000)
    chunks = [sensor_log.slice(a, a + 7001) for a in range(0, len(sensor_log), 7001)]
    streamed = fit_torque_constant(iter(chunks), block_rows=5000)
    assert pytest.approx(whole.K, rel=1e-12) == streamed.K
    assert streamed.K_se == pytest.approx(whole.K_se, rel=1e-9)


def test_one_power_flow_gives_k_without_efficiency(sensor_log):
    keep = np.flatnonzero(sensor_log.torque * sensor_log.velocity >= 0)
    one = sensor_log.slice(0, len(sensor_log))
    one = RawLog(
        time=one.time[keep],
        position=one.position[keep],
        velocity=one.velocity[keep],
        temperature=one.temperature[keep],
        torque=one.torque[keep],
        current=one.current[keep],
    )
    fit = fit_torque_constant(one)
    assert fit.efficiency is None
    assert abs(fit.K - ETA * K) < 0.02 * K  # the motoring slope: eta K


def test_needs_current_and_torque(sensor_log):
    no_current = RawLog(
        time=sensor_log.time,
        position=sensor_log.position,
        velocity=sensor_log.velocity,
        temperature=25.0,
        torque=sensor_log.torque,
        source="x.csv",
    )
    with pytest.raises(DataError, match=r"x\.csv: .*needs both the motor current and a joint"):
        fit_torque_constant(no_current)


def test_k_from_a_known_gravity_load():
    """Extraction with K = 1 gives eq. 7 in amperes; the link's known p_x, p_y give K."""
    s = preset("paper1", "quick")
    log = simulate_log(s, seed=7)
    k_true = float(log.torque_constant)
    amps = RawLog(
        time=log.time,
        position=log.position,
        velocity=log.velocity,
        temperature=log.temperature,
        current=log.current,
        torque_constant=1.0,
    )
    g = extract(amps, **s.extract_options()).gravity
    fit = torque_constant_from_gravity(
        (g.p_x, g.p_y), (g.p_x_se, g.p_y_se), true_gravity(s), source="x"
    )
    assert abs(fit.K - k_true) <= Z * fit.K_se and fit.method == "gravity load"


def test_cli_identify_torque_constant(sensor_log, tmp_path):
    path = write_rawlog(sensor_log, tmp_path / "log.parquet")
    out = tmp_path / "s.csv"
    res = CliRunner().invoke(
        app,
        [
            "extract",
            str(path),
            "-o",
            str(out),
            "--positions",
            "-60:-20:10",
            "--bin-halfwidth",
            "1",
            "--identify-torque-constant",
        ],
    )
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    m = re.search(r"torque constant \(eq. 13, from the torque sensor\): K = (\S+) \+- (\S+)", text)
    assert m, text
    assert abs(float(m.group(1)) - K) <= Z * float(m.group(2))
    assert "gear efficiency eta = 0.90" in text
