"""Every set-point accounted for: labels and reasons in the quality table, merged runs with
scattered means flagged, set-points that cannot chain, standstill rows dropped."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

from _sweeps import friction, sweep_log
from fricid.cli import app
from fricid.errors import DataQualityWarning
from fricid.extract import cluster, extract
from fricid.io import read_samples, write_rawlog, write_samples
from fricid.samples import FrictionSamples


def _quiet(fn, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataQualityWarning)
        return fn(*args, **kwargs)


def test_every_row_is_labelled_with_a_reason(tmp_path):
    """A creep at 1e-5 rad/s is dropped as standstill, named with its speed and the threshold;
    every set-point row has a label; the CLI lists the dropped groups on stderr."""
    raw = sweep_log([0.4, 0.8], extra=[(1e-5, 10.0)])
    r = extract(raw, gravity="joint")
    rows = r.samples.meta["quality"]
    points = [q for q in rows if q["kind"] == "setpoint"]
    assert len(points) == 4 and all(q["label"] and q["note"] == "1 run" for q in points)
    rest = [q for q in rows if q["kind"] == "rest"]
    assert len(rest) == 1 and rest[0]["dropped_rest"] == 1000
    assert rest[0]["note"].startswith("dropped as standstill: 1 run(s) at 1e-05 rad/s")
    assert "rest threshold 0.0008 rad/s" in rest[0]["note"]
    assert all(q["label"] and q["note"] for q in rows)
    assert 1e-5 not in np.abs(r.by_direction.velocity)
    log = tmp_path / "log.csv"
    write_rawlog(raw, log)
    res = CliRunner().invoke(app, ["extract", str(log), "-o", str(tmp_path / "s.csv")])
    assert res.exit_code == 0, res.output
    assert "set-points: 4 kept" in res.output
    assert "rest (runs at 1e-05 rad/s): dropped as standstill" in res.output


def test_merged_runs_with_scattered_means_are_flagged():
    """Four runs at 0.6 rad/s whose friction differs by +-0.8 N m between runs (a disturbed
    condition) are merged into one set-point: flagged, with the reason; repeats that agree
    are not."""
    speeds = [0.2, 0.4, 0.6, 0.8, 1.0] * 2 + [0.6, 0.6]
    offsets = [0.0] * 10 + [0.8, -0.8]
    r = _quiet(extract, sweep_log(speeds, p=(0.0, 0.0), offsets=offsets), gravity="none")
    q = r.quality
    sp = q.setpoints
    assert q.runs[sp & np.isclose(np.abs(q.velocity), 0.6, rtol=0.01)].tolist() == [4, 4]
    hit = np.flatnonzero(q.flagged)
    assert sorted(np.abs(q.velocity[hit]).round(3).tolist()) == [0.6, 0.6]
    assert all("merged runs' means scatter" in q.note[i] for i in hit)
    assert all(q.note[i].startswith("4 runs merged (0.6") for i in hit)
    with pytest.warns(DataQualityWarning, match="runs merged into them"):
        extract(sweep_log(speeds, p=(0.0, 0.0), offsets=offsets), gravity="none")


def test_slow_distinct_speeds_do_not_chain():
    """0.1 to 5 deg/s in 0.1 deg/s steps (2-100 % apart): each speed is its own set-point
    (the gap rule alone chained everything above 2 deg/s into one); a level's span is bounded
    relative to its centre however many values sit within the tolerance of a neighbour."""
    deg = np.arange(1, 51) * 0.1
    rng = np.random.default_rng(0)
    runs = np.repeat(np.radians(deg), 3) * (1 + 2e-4 * rng.standard_normal(150))
    labels, centres = cluster(runs, 0.01, relative=True)
    assert centres.size == 50
    np.testing.assert_array_equal(np.bincount(labels), 3)
    chain = np.radians(0.5) * 1.03 ** np.arange(38)
    labels, centres = cluster(chain, 0.05, relative=True)
    for k, c in enumerate(centres):
        members = chain[labels == k]
        assert members.max() - members.min() <= 0.05 * c


def test_closely_spaced_speeds_stay_apart_in_extraction():
    """38 speeds 3 % apart: 38 set-points per direction, one run each."""
    speeds = 0.5 * 1.03 ** np.arange(38)
    r = _quiet(extract, sweep_log(speeds, p=(0.0, 0.0), span=(-0.3, 0.3)), gravity="none")
    assert r.diagnostics.velocity_setpoints.size == 38
    np.testing.assert_allclose(r.diagnostics.velocity_setpoints, speeds, rtol=1e-3)
    assert (r.quality.runs[r.quality.setpoints] == 1).all()
    by = r.by_direction
    assert np.abs(by.friction - friction(by.velocity)).max() < 0.05


def test_standstill_rows_of_a_samples_file_are_dropped(tmp_path):
    """A per-direction mean at 6.7e-6 rad/s (the slowest real speed 0.02) is not a +1
    set-point: dropped on reading, with a warning naming the row; a logarithmic sweep down to
    1e-4 of the fastest speed keeps every row."""
    from fricid.samples import standstill_rows

    v = np.r_[6.7e-6, np.linspace(0.02, 1.0, 10)]
    v = np.r_[v, -v[1:]]
    f = np.sign(v) * (1 + 2 * np.abs(v))
    f[0] = 0.2
    path = tmp_path / "means.csv"
    write_samples(FrictionSamples(velocity=v, friction=f, load=None, temperature=None), path)
    with pytest.warns(DataQualityWarning, match=r"standstill row\(s\): row 0 \(\+6\.7e-06 rad/s"):
        got = read_samples(path)
    assert len(got) == v.size - 1 and np.abs(got.velocity).min() == pytest.approx(0.02)
    assert got.meta["dropped_standstill"] == [0]
    sweep = np.geomspace(1e-4, 1.0, 9)
    assert not standstill_rows(np.r_[sweep, -sweep], np.r_[sweep * 0 + 1, sweep * 0 - 1]).any()
