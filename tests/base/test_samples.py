"""Data types validate themselves on construction."""

from __future__ import annotations

import numpy as np
import pytest

from fricid.errors import DataError
from fricid.samples import FrictionSamples, RawLog


def _log(**kw):
    n = 5
    base = dict(
        time=np.arange(n) * 0.004,
        position=np.zeros(n),
        velocity=np.ones(n),
        temperature=25.0,
        current=np.ones(n),
        torque_constant=0.5,
        source="log.csv",
    )
    base.update(kw)
    return RawLog(**base)


def test_motor_torque_from_current_eq13():
    log = _log(current=np.array([1.0, 2.0, 3.0, 4.0, 5.0]), torque_constant=0.5)
    np.testing.assert_allclose(log.motor_torque, [0.5, 1.0, 1.5, 2.0, 2.5])
    assert log.temperature.shape == (5,)


def test_non_monotonic_time_names_row_and_column():
    with pytest.raises(
        DataError, match=r"log.csv, row 3, column 'time': time is not strictly"
    ) as e:
        _log(time=np.array([0.0, 1.0, 2.0, 1.5, 3.0]))
    assert "(2.0 then 1.5)" in str(e.value)  # the numbers as a user writes them, no np.float64


def test_nan_names_row_and_column():
    v = np.ones(5)
    v[2] = np.nan
    with pytest.raises(DataError, match=r"row 2, column 'velocity': non-finite"):
        _log(velocity=v)


def test_current_needs_torque_constant():
    with pytest.raises(DataError, match="torque constant"):
        _log(torque_constant=None)


def test_missing_effort():
    with pytest.raises(DataError, match="neither a torque nor a current"):
        _log(current=None)


def test_length_mismatch():
    with pytest.raises(DataError, match="has 4 values, expected 5"):
        _log(position=np.zeros(4))


def test_samples_validate_and_subset():
    s = FrictionSamples(velocity=[0.1, -0.1], load=0, temperature=25, friction=[0.2, -0.2])
    assert s.directions() == (-1, 1)
    assert s.X.shape == (2, 3)
    assert len(s.subset(s.direction > 0)) == 1
    with pytest.raises(DataError, match="direction must be -1, 0 or \\+1"):
        FrictionSamples(velocity=[0.1], load=0, temperature=25, friction=[0.2], direction=[2])
    with pytest.raises(DataError, match="no friction samples"):
        FrictionSamples(velocity=[], load=[], temperature=[], friction=[])
    with pytest.raises(DataError, match="std must be >= 0"):
        FrictionSamples(velocity=[0.1], load=0, temperature=25, friction=[0.2], std=[-1])


def test_concatenate_logs():
    a = _log()
    b = _log(time=np.arange(5) * 0.004 + 1.0)
    c = RawLog.concatenate([a, b])
    assert len(c) == 10
    assert c.torque is None and c.current is not None
