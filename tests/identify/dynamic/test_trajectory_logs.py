"""Trajectory logs that would give a wrong answer (issue 25): a hole in the time column, a
time stamp moved by 1e6 s, a torque or current channel stuck. The virtual joint's log
(``fricid simulate --trajectory multisine --duration 2``) damaged: before, a 10 s hole gave an
inertia of 0.154 kg m^2 (0.0088 without it), the current stuck at 10 A an inertia of
-0.876 kg m^2, and the moved stamp tried to allocate 7.45 GiB. Now each is one DataError line
naming the file, the row and the column, before anything is resampled."""

from __future__ import annotations

import dataclasses
import re
import tracemalloc

import numpy as np
import pytest
from typer.testing import CliRunner

import fricid.samples._trajectory_log as samples_module
from fricid.cli import app
from fricid.errors import DataError
from fricid.identify.dynamic.trajectory import fit_trajectory
from fricid.io import read_rawlog, write_rawlog
from fricid.samples import RawLog


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    """The virtual joint's 2 s multi-sine at 1 kHz, as ``fricid simulate`` writes it."""
    path = tmp_path_factory.mktemp("traj") / "multisine.parquet"
    args = ["simulate", "--trajectory", "multisine", "--duration", "2", "-o", str(path), "-q"]
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 0, res.output
    return read_rawlog(path)


def check_trajectory_log(log: RawLog) -> None:
    samples_module.check_trajectory_log(log)


def damaged(log: RawLog, tmp_path, name: str, **columns) -> str:
    path = tmp_path / f"{name}.parquet"
    write_rawlog(dataclasses.replace(log, **columns), path)
    return str(path)


def refused_by_fit(path: str, *words: str) -> str:
    out = path.replace(".parquet", ".json")
    res = CliRunner().invoke(app, ["fit", path, "--trajectory", "--out", out])
    assert res.exit_code == 2, res.output
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith(f"error: {path}"), res.output
    for word in words:
        assert word in lines[0], lines[0]
    assert "Traceback" not in res.output
    return lines[0]


def test_the_clean_log_passes(clean):
    check_trajectory_log(clean)
    got = fit_trajectory(clean, "stribeck")
    joint = got.provenance["trajectory"]["joint"]
    assert joint["inertia"]["value"] == pytest.approx(0.01, rel=0.1)


def test_a_hole_in_time(clean, tmp_path):
    n = len(clean)
    t = clean.time.copy()
    t[n // 2 :] += 10.0
    path = damaged(clean, tmp_path, "hole", time=t)
    refused_by_fit(path, f"row {n // 2}", "column 'time'", "time jumps by 10.001 s")


def test_a_stamp_moved_by_1e6_s_allocates_nothing(clean, tmp_path):
    t = clean.time.copy()
    t[-1] += 1e6
    log = dataclasses.replace(clean, time=t, source="moved.parquet")
    tracemalloc.start()
    try:
        with pytest.raises(DataError, match=r"row 1999, column 'time': time jumps by 1e\+06 s"):
            fit_trajectory(log, "stribeck")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 10 * 2**20, peak
    refused_by_fit(damaged(clean, tmp_path, "moved", time=t), "time jumps by 1e+06 s")


def test_the_grid_is_bounded_before_allocation(clean, monkeypatch):
    monkeypatch.setattr(samples_module, "MAX_TRAJECTORY_SAMPLES", 1500)
    with pytest.raises(DataError, match=r"2000 samples on its uniform grid .* over the 1500"):
        check_trajectory_log(clean)


def test_the_current_stuck_at_10_A(clean, tmp_path):
    assert clean.torque is None and clean.current is not None
    path = damaged(clean, tmp_path, "stuck", current=np.full(len(clean), 10.0))
    refused_by_fit(path, "column 'current'", "10 A in every row", "stuck")


@pytest.mark.parametrize("share", [0.025, 0.1, 0.5])
def test_a_current_stuck_while_the_joint_moves(clean, tmp_path, share):
    n = len(clean)
    a, b = n // 4, n // 4 + int(share * n)
    current = clean.current.copy()
    current[a:b] = current[a]
    path = damaged(clean, tmp_path, f"stuck{share}", current=current)
    refused_by_fit(path, f"row {a}", f"rows {a} to {b - 1}", "while the velocity changes")


def test_a_stuck_torque_channel(clean):
    torque = clean.motor_torque.copy()
    torque[300:700] = torque[300]
    log = dataclasses.replace(clean, torque=torque, current=None, torque_constant=None)
    with pytest.raises(DataError, match=r"row 300, column 'torque': the torque holds"):
        check_trajectory_log(log)


def test_what_real_logs_do_passes(clean):
    """Quantisation (0.02 A steps), stamps jittered by 0.5 %, two samples dropped (a step
    three times the median), a current held while the joint rests, one held for 15 rows
    (under ``STUCK_MIN_SAMPLES``) while it moves."""
    rng = np.random.default_rng(3)
    current = np.round(clean.current / 0.02) * 0.02
    t = clean.time + rng.uniform(-0.005, 0.005, len(clean)) * 1e-3
    keep = np.ones(len(clean), bool)
    keep[1000:1002] = False
    log = dataclasses.replace(clean, time=t, current=current)
    check_trajectory_log(log.slice(0, 1000))
    check_trajectory_log(RawLog.concatenate([log.slice(0, 1000), log.slice(1002, len(log))]))
    rest = dataclasses.replace(
        clean, velocity=np.where(np.arange(len(clean)) < 500, 0.0, clean.velocity)
    )
    current = rest.current.copy()
    current[:500] = 0.3
    check_trajectory_log(dataclasses.replace(rest, current=current))
    current = clean.current.copy()
    current[1200:1215] = current[1200]
    assert np.ptp(clean.velocity[1200:1215]) > 0.05 * np.ptp(clean.velocity)
    check_trajectory_log(dataclasses.replace(clean, current=current))


def test_a_coarse_channel_is_not_judged_by_its_stretches(clean, monkeypatch):
    """A current in 0.2 A steps (over ``STUCK_QUANTUM`` of its range) holds its levels while
    the joint moves: judged as a fine channel it would be refused."""
    coarse = dataclasses.replace(clean, current=np.round(clean.current / 0.2) * 0.2)
    check_trajectory_log(coarse)
    monkeypatch.setattr(samples_module, "STUCK_QUANTUM", 1.0)
    with pytest.raises(DataError, match="while the velocity changes"):
        check_trajectory_log(coarse)


@pytest.mark.parametrize("where", ["position", "time"])
def test_the_first_sample_does_not_steer_the_fit(clean, where):
    """The derivative filter's edges are extrapolated: they are left out of the regression.
    Before, the first position 0.3 mrad off (or the first stamp 0.2 ms late) moved the
    inertia from 0.0101 to 0.0058 kg m^2 and tau_c to 0.40 (or 0.0) N m."""
    column = getattr(clean, where).copy()
    column[0] += 3e-4 if where == "position" else 2e-4
    got = fit_trajectory(dataclasses.replace(clean, **{where: column}), "stribeck")
    base = fit_trajectory(clean, "stribeck")
    inertia = [f.provenance["trajectory"]["joint"]["inertia"]["value"] for f in (got, base)]
    assert inertia[0] == pytest.approx(inertia[1], rel=0.05)
    assert got.params["tau_c"] == pytest.approx(base.params["tau_c"], rel=0.02)


@pytest.mark.parametrize(
    ("factor", "words"),
    [(180 / np.pi, "degrees against radians"), (-1.0, "sign reversed"), (12.0, "gear ratio")],
)
def test_a_velocity_that_is_not_the_position_derivative(clean, tmp_path, factor, words):
    """A velocity in deg/s labelled rad/s, one of reversed sign, a motor-side one: the fit
    would read it as it is, so the log is refused with the factor and its likely cause."""
    path = damaged(clean, tmp_path, f"velocity{factor:.3g}", velocity=clean.velocity * factor)
    line = refused_by_fit(path, "column 'velocity'", words)
    said = re.search(r"the position changes by (\S+)x the integral of the velocity", line)
    assert said and float(said.group(1)) == pytest.approx(1 / factor, rel=0.02), line


@pytest.mark.parametrize("flip", ["torque", "motion"])
def test_a_reversed_sign_is_refused(clean, tmp_path, flip):
    """The torque's sign reversed, or the position's and velocity's together (the velocity
    check cannot see that): friction would have to feed energy in, so the log is refused."""
    if flip == "torque":
        columns = {"current": -clean.current}
    else:
        columns = {"position": -clean.position, "velocity": -clean.velocity}
    path = damaged(clean, tmp_path, f"reversed_{flip}", **columns)
    line = refused_by_fit(path, "the torque works against friction", "flip one")
    level = float(re.search(r"Coulomb level of (\S+)", line).group(1))
    assert level < 0


def test_an_angle_wrapped_to_one_turn_is_refused(clean, tmp_path):
    """A joint that turns on (the multi-sine plus 6 rad/s), its angle logged in [-pi, pi):
    the fit differentiates the position, so each wrap would be a huge false acceleration."""
    turning = clean.position + 6.0 * (clean.time - clean.time[0])
    wrapped = (turning + np.pi) % (2 * np.pi) - np.pi
    first = int(np.flatnonzero(np.abs(np.diff(wrapped)) > np.pi)[0]) + 1
    path = damaged(clean, tmp_path, "wrapped", position=wrapped, velocity=clean.velocity + 6.0)
    refused_by_fit(path, f"row {first}", "column 'position'", "wrapped to one turn")


def test_sample_options_with_trajectory_are_refused(clean, tmp_path):
    path = tmp_path / "clean.parquet"
    write_rawlog(clean, path)
    args = ["fit", str(path), "--trajectory", "--validate", "kfold", "--loss", "huber"]
    res = CliRunner().invoke(app, [*args, "--out", str(tmp_path / "x.json")])
    assert res.exit_code == 2, res.output
    assert "--validate, --loss apply to friction samples, not to --trajectory" in res.output
    assert not (tmp_path / "x.json").exists()
    # --bound is refused for its own reason (the ranges a trajectory fit searches), not the
    # held-out log's
    res = CliRunner().invoke(app, ["fit", str(path), "--trajectory", "--bound", "sigma_0=1:1e6"])
    text = " ".join(res.output.split())
    assert res.exit_code == 2 and "sigma_0 from 1e2 to 1e7 N m/rad" in text, text
    assert "second log" not in text


@pytest.mark.parametrize(
    ("unit", "factor"), [("degrees", 180 / np.pi), ("revolutions", 0.5 / np.pi)]
)
def test_a_position_and_velocity_both_in_another_unit_are_refused(clean, tmp_path, unit, factor):
    """Position and velocity both in degrees (or revolutions) labelled radians agree with each
    other, and the fit gave an inertia 57.3^2 times off with caveats only. The steps of a
    2^16-count encoder give it away: 2 pi / step reads 1143.8 counts per revolution, a power
    of two only in degrees. The same log in radians passes."""
    step = 2 * np.pi / 2**16
    counted = np.round(clean.position / step) * step
    check_trajectory_log(dataclasses.replace(clean, position=counted))
    columns = {"position": counted * factor, "velocity": clean.velocity * factor}
    path = damaged(clean, tmp_path, f"in_{unit}", **columns)
    refused_by_fit(path, "column 'position'", "65536-count encoder", f"in {unit} labelled radians")


def test_a_csv_log_s_hole_is_named_by_its_line_and_label(clean, tmp_path):
    """A CSV log's hole in the time is named by the file's line and the column's label, as the
    reader's own errors are (it had been 'row 500, column time', the sample's index)."""
    path = tmp_path / "hole.csv"
    write_rawlog(clean, path)
    lines = path.read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    cut = header + 1 + 500  # the 0-based index of the line of sample 500
    path.write_text("\n".join(lines[:cut] + lines[cut + 50 :]) + "\n")
    args = ["fit", str(path), "--trajectory", "--out", str(tmp_path / "o.json")]
    res = CliRunner().invoke(app, args)
    text = " ".join(res.output.split())
    assert res.exit_code == 2 and f"row {cut + 1}, column 'time [s]'" in text, text
