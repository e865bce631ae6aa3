"""A trajectory fit records the temperature range its log measured, and none for a log that
logged none (an EPOS recording given no temperature holds a placeholder column)."""

from __future__ import annotations

import warnings

from fricid.identify import fit
from fricid.io import read_epos


def _fit(log):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(log, "coulomb_viscous")


def test_a_log_without_temperature_records_no_temperature_range(leadscrew_dir):
    path = leadscrew_dir / "10.csv"
    none = _fit(read_epos(path, flip_sign=True))
    assert "temperature" not in none.operating_range
    assert none.operating_range["velocity"][1] > 0
    given = _fit(read_epos(path, flip_sign=True, temperature=31.0))
    assert given.operating_range["temperature"] == [31.0, 31.0]
