"""Unit conversions at the edge."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fricid.errors import ConfigError
from fricid.units import UNITS, from_si, to_si


def test_known_values():
    assert float(to_si(180.0, "deg", "position")) == pytest.approx(np.pi)
    assert float(to_si(60.0, "rpm", "velocity")) == pytest.approx(2 * np.pi)
    assert float(to_si(9.84, "mNm", "torque")) == pytest.approx(0.00984)
    assert float(to_si(300.0, "K", "temperature")) == pytest.approx(26.85)


@given(
    st.sampled_from([(q, u) for q, table in UNITS.items() for u in table]),
    st.floats(-1e6, 1e6, allow_nan=False),
)
def test_round_trip(qu, value):
    quantity, unit = qu
    back = from_si(to_si(value, unit, quantity), unit, quantity)
    assert float(back) == pytest.approx(value, rel=1e-12, abs=1e-9)


def test_unknown_unit_lists_choices():
    with pytest.raises(ConfigError, match=r"unknown velocity unit 'furlong/s'; use one of: rad/s"):
        to_si(1.0, "furlong/s", "velocity")
