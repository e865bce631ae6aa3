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


def _urdf(tmp_path, p_x, p_y, mass=2.0):
    """A URDF of the virtual joint: one link on a y axis with eq. 7's p_x, p_y
    (fricid.io.urdf's conventions: x = p_x / (m g), z = -p_y / (m g))."""
    from fricid.io.urdf import STANDARD_GRAVITY as G

    path = tmp_path / "joint.urdf"
    path.write_text(
        f"""<robot name="virtual"><link name="base"/>
  <link name="arm"><inertial><origin xyz="{p_x / (mass * G)!r} 0 {-p_y / (mass * G)!r}"/>
    <mass value="{mass!r}"/></inertial></link>
  <joint name="elbow" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/></joint></robot>"""
    )
    return path


BINS = ["--positions", "-60:-20:10", "--bin-halfwidth", "1"]  # the quick design's bins


@pytest.fixture(scope="module")
def current_only_log(tmp_path_factory):
    """The paper1 virtual joint's log as simulated: current only, with known K = 0.5."""
    s = preset("paper1", "quick")
    log = simulate_log(s, seed=11)
    assert log.torque is None and log.current is not None
    path = write_rawlog(log, tmp_path_factory.mktemp("kurdf") / "log.parquet")
    return s, float(log.torque_constant), path


@pytest.mark.parametrize("gravity", [BINS, ["--gravity", "joint"]], ids=["fit", "joint"])
def test_cli_k_from_a_urdf(current_only_log, tmp_path, gravity):
    s, k_true, path = current_only_log
    urdf = _urdf(tmp_path, *true_gravity(s))
    out = tmp_path / "s.csv"
    args = ["extract", str(path), "-o", str(out), "--urdf", str(urdf), "--urdf-joint", "elbow"]
    res = CliRunner().invoke(app, [*args, *gravity])
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert (
        "gravity load of joint 'elbow' from the URDF (eq. 7): p_x = 0.2011, p_y = 0.06175" in text
    )
    m = re.search(
        r"from the gravity load\): K = (\S+) \+- (\S+) N m/A \(95 % CI (\S+) to (\S+);", text
    )
    assert m, text
    k, se, lo, hi = (float(x) for x in m.groups())
    assert lo <= k_true <= hi and abs(k - k_true) <= Z * se and se < 0.02 * k_true
    assert out.exists()


def test_cli_k_from_a_wrong_urdf_misses(current_only_log, tmp_path):
    """The interval is not so wide that any geometry passes: a link 20 % heavier misses K."""
    s, k_true, path = current_only_log
    p_x, p_y = true_gravity(s)
    urdf = _urdf(tmp_path, 1.2 * p_x, 1.2 * p_y)
    args = ["extract", str(path), "-o", str(tmp_path / "s.csv"), "--urdf", str(urdf)]
    res = CliRunner().invoke(app, [*args, "--urdf-joint", "elbow", *BINS])
    m = re.search(r"95 % CI (\S+) to (\S+);", " ".join(res.output.split()))
    assert res.exit_code == 0 and m, res.output
    assert float(m.group(1)) > k_true


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        (["--urdf-joint", "elbow"], "--urdf and --urdf-joint go together"),
        (["--urdf", "URDF", "--urdf-joint", "wrist"], "no joint 'wrist'"),
        (["--urdf", "URDF", "--urdf-joint", "elbow", "--gravity", "none"], "--gravity none"),
        (["--urdf", "URDF", "--urdf-joint", "elbow", "--urdf-position", "x"], "--urdf-position"),
    ],
)
def test_cli_urdf_refusals(current_only_log, tmp_path, extra, match):
    s, _, path = current_only_log
    urdf = str(_urdf(tmp_path, *true_gravity(s)))
    args = ["extract", str(path), "-o", str(tmp_path / "s.csv")]
    res = CliRunner().invoke(app, args + [urdf if a == "URDF" else a for a in extra] + BINS)
    assert res.exit_code == 2
    assert match in " ".join(res.output.split())


@pytest.mark.slow  # 1.3 s, quiet machine (the default run kept under 3 minutes)
def test_cli_urdf_generic_csv_without_k(current_only_log, tmp_path):
    """A CSV with current and no K cannot be extracted alone; with --urdf the samples come
    out in N m with the identified K (the same samples as the true K's, scaled)."""
    import pandas as pd

    from fricid.io import read_rawlog, read_samples

    s, k_true, path = current_only_log
    log = read_rawlog(path)
    csv = tmp_path / "run.csv"
    frame = {"t": log.time, "q": log.position, "dq": log.velocity, "i": log.current}
    pd.DataFrame({**frame, "T": log.temperature}).to_csv(csv, index=False)
    maps = ["time=t:s", "position=q:rad", "velocity=dq:rad/s", "current=i:A", "temperature=T:degC"]
    args = ["extract", str(csv), "--format", "generic", *BINS]
    args += [x for m in maps for x in ("--map", m)]
    alone = CliRunner().invoke(app, [*args, "-o", str(tmp_path / "a.csv")])
    assert alone.exit_code == 2 and "torque constant" in alone.output
    out = tmp_path / "s.csv"
    urdf = _urdf(tmp_path, *true_gravity(s))
    res = CliRunner().invoke(
        app, [*args, "-o", str(out), "--urdf", str(urdf), "--urdf-joint", "elbow"]
    )
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    m = re.search(r"from the gravity load\): K = (\S+) \+- (\S+) N m/A", text)
    k, se = float(m.group(1)), float(m.group(2))
    assert (
        abs(k - k_true) <= Z * se
        and f"samples converted with the identified K = {m.group(1)}" in text
    )
    truth = extract(
        log,
        positions=np.deg2rad(np.arange(-60.0, -19.0, 10.0)),
        bin_halfwidth=np.deg2rad(1.0),
        gravity="fit",
    ).samples
    got = read_samples(out)
    np.testing.assert_allclose(got.friction, truth.friction * k / k_true, rtol=1e-3, atol=1e-6)
