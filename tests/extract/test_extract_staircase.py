"""A log whose speed steps from one set-point to the next without stopping (a staircase):
each step is a set-point; a run's slow acceleration ramp is not one."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fricid.extract import extract, iter_segments
from fricid.samples import RawLog

RATE = 500.0
F_C, BETA = 0.5, 0.2


def _log(profile: np.ndarray, seed: int = 0, noise: float = 0.002) -> RawLog:
    rng = np.random.default_rng(seed)
    t = np.arange(profile.size) / RATE
    torque = F_C * np.sign(profile) + BETA * profile + rng.normal(0, 0.01, profile.size)
    return RawLog(
        time=t,
        position=np.cumsum(profile) / RATE,
        velocity=profile + rng.normal(0, noise, profile.size),
        temperature=25.0,
        torque=torque,
        source="staircase.csv",
    )


def _staircase(speeds, seconds: float = 2.0) -> np.ndarray:
    up = [np.full(int(seconds * RATE), s) for s in speeds]
    return np.concatenate(up + [-u for u in up])


def test_every_step_of_a_staircase_without_rests_is_a_set_point():
    """Twelve speeds, 2 s each, one direction after the other with no rest between steps:
    twelve set-points per direction, each with its friction (before: one, the other eleven
    dropped as transient)."""
    speeds = np.linspace(0.1, 1.2, 12)
    r = extract(_log(_staircase(speeds)), gravity="none")
    q = r.quality
    points = q.kind == "setpoint"
    assert points.sum() == 24
    assert np.allclose(np.sort(np.abs(q.velocity[points]))[::2], speeds, atol=1e-3)
    v = r.samples.velocity
    assert np.allclose(r.samples.friction, F_C + BETA * np.abs(v), atol=2e-3)
    # every sample accounted for once: kept, trimmed (settling, steps) or dropped
    assert q.kept.sum() + q.dropped_transient.sum() + q.dropped_rest.sum() == 2 * 12 * 1000


def test_a_slow_ramp_into_a_plateau_is_not_a_step():
    """Runs accelerating over 4 s into a 6 s plateau and back (a ramp's stretch within a
    velocity band, 0.3 s at 0.6 rad/s, outlasts the settling trimmed): one set-point per
    direction (without the step's drift test, 16)."""
    ramp = np.linspace(0.0, 0.8, int(4 * RATE))[1:]
    run = np.concatenate([ramp, np.full(int(6 * RATE), 0.8), ramp[::-1]])
    r = extract(_log(np.concatenate([run, -run])), gravity="none")
    assert (r.quality.kind == "setpoint").sum() == 2
    assert len(r.samples) == 1


@settings(max_examples=25, deadline=None)
@given(
    levels=st.lists(st.floats(0.05, 2.0), min_size=1, max_size=6, unique=True),
    seconds=st.floats(0.6, 2.0),
)
def test_steps_partition_their_run(levels, seconds):
    """Levels in any order (up, down or both): the steps found in one run are disjoint and
    in order, their runs add up to the run's samples, each steady part holds one level."""
    if any(b / a < 1.15 for a, b in itertools.pairwise(sorted(levels))):
        return  # levels within the velocity band of each other are one set-point
    profile = np.concatenate([np.full(int(seconds * RATE), s) for s in levels])
    segments = list(iter_segments(_log(profile, noise=0.0)))
    assert sum(s.run_samples for s in segments) == profile.size
    rows = [s.row for s in segments]
    assert rows == sorted(rows)
    for a, b in itertools.pairwise(segments):
        assert a.row + len(a.log) <= b.row
    for s in segments:
        assert np.ptp(s.log.velocity) == pytest.approx(0.0, abs=1e-12)
    assert len(segments) == len(levels)
