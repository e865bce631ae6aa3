"""The time-left estimate: none until the rate of completed work is known, "about", corrected
as it goes (fricid.cli._estimate). A fake clock: nothing sleeps, nothing depends on timing."""

from __future__ import annotations

import pytest

from fricid.cli import _progress
from fricid.cli._estimate import MIN_FRACTION, Estimator


class Clock:
    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


def test_no_estimate_until_the_rate_is_known_from_completed_work():
    clock = Clock()
    est = Estimator(100, clock)
    assert est.remaining() is None  # nothing done
    clock.t = 2.0
    est.observe(10)
    assert est.remaining() is None  # one report: a count, no rate
    clock.t = 2.5
    est.observe(20)
    assert est.remaining() is None  # half a second of work is too little to time
    clock.t = 4.0
    est.observe(30)
    # the rate over the recent half since the first report: 10 done from 2.5 s to 4 s
    assert est.remaining() == pytest.approx(70 / (10 / 1.5))


def test_start_up_at_zero_is_not_counted_in_the_rate():
    """The old estimate (time so far over fraction done) said minutes after a slow start."""
    clock = Clock()
    est = Estimator(1000, clock)
    clock.t = 58.0  # compiling, loading: no work reported
    est.observe(60)
    clock.t = 60.0
    est.observe(260)  # 100 per second since the work began
    left = est.remaining()
    assert left == pytest.approx(740 / 100)
    naive = clock.t * (1000 - 260) / 260
    assert naive > 20 * left


def test_estimate_follows_a_change_of_pace_and_a_stall():
    clock = Clock()
    est = Estimator(1000, clock)
    for t in range(1, 11):  # 10 per second for 10 s
        clock.t = float(t)
        est.observe(10 * t)
    assert est.remaining() == pytest.approx(900 / 10)
    for t in range(11, 31):  # then 40 per second
        clock.t = float(t)
        est.observe(100 + 40 * (t - 10))
    left = est.remaining()
    assert left == pytest.approx((1000 - 900) / 40, rel=0.05)  # the recent rate, not the mean
    clock.t = 60.0  # no report for 30 s: the estimate grows, it does not freeze
    assert est.remaining() > 2 * left


def test_no_estimate_below_the_minimum_fraction_or_when_done_or_total_unknown():
    clock = Clock()
    est = Estimator(10_000, clock)
    n = int(MIN_FRACTION * 10_000) - 1
    clock.t = 1.0
    est.observe(1)
    clock.t = 10.0
    est.observe(n)
    assert est.remaining() is None
    est.observe(10_000)
    assert est.remaining() is None
    open_ended = Estimator(None, clock)
    open_ended.observe(5)
    clock.t = 20.0
    open_ended.observe(50)
    assert open_ended.remaining() is None


def test_a_restarted_count_forgets_the_old_rate():
    clock = Clock()
    est = Estimator(100, clock)
    for t, d in ((1.0, 10), (3.0, 50)):
        clock.t = t
        est.observe(d)
    assert est.remaining() is not None
    clock.t = 4.0
    est.observe(5)  # a new count
    assert est.remaining() is None


def test_tracker_lines_say_about_only_once_the_rate_is_known(monkeypatch, capsys):
    monkeypatch.setattr(_progress, "GRACE_S", 0.0)
    monkeypatch.setattr(_progress, "MIN_GAP_S", 0.0)
    clock = Clock()
    t = _progress.Tracker("work", 10, "plain", unit="items", clock=clock)
    clock.t = 30.0  # a slow start
    t.update(1)
    assert t.line() == "work: 1/10 items (10 %)"  # no estimate from one report
    clock.t = 32.0
    t.update(3)
    assert t.line() == "work: 3/10 items (30 %), about 7.0 s left"
    t.update(10)
    assert "left" not in t.line()
