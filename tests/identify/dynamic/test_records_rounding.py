"""A trajectory fit's interval that reaches its search range's end up to rounding is open there.

Measured on the other simulator's PD-tracked trapezoid (``stribeck_asym`` from
``trapezoid_pd_1000Hz_131072cpr.csv`` in the shared foreign data): delta_pos printed
``4 +/- 19.5 (95 % CI [0.2, 4]) [at boundary]``, its interval's lower end
0.20000000000000018 against the range's 0.2, so the interval spanning the whole range (and
a standard error five times its width) was read as closed at the lower end and the parameter
as determined.
"""

from __future__ import annotations

from fricid.identify.dynamic._result import _records


def _one(low: float, high: float, value: float = 4.0, se: float = 19.5):
    final = {"delta": {"value": value, "stderr": se, "ci95_low": low, "ci95_high": high}}
    return _records(["delta"], final, {"delta": "1"}, {"delta": [0.2, 4.0]}, True)["delta"]


def test_an_interval_reaching_the_range_up_to_rounding_is_open():
    p = _one(0.20000000000000018, 4.0)
    assert p.low_open and p.high_open
    assert p.not_determined and p.note.startswith("not identified"), p.note


def test_an_interval_inside_the_range_stays_closed():
    p = _one(0.25, 3.9, value=3.0, se=0.4)
    assert not (p.low_open or p.high_open or p.not_determined)


def test_a_value_a_hair_above_a_zero_bound_is_at_the_bound():
    """A new user's trial: ``stribeck_asym`` from a foreign log printed tau_c_pos 3.4e-36 N m
    in [0, 2] without "at boundary" (a relative test against 0 never holds)."""
    final = {"tau_c": {"value": 3.4e-36, "stderr": 0.3, "ci95_low": 0.0, "ci95_high": 0.6}}
    p = _records(["tau_c"], final, {"tau_c": "N m"}, {"tau_c": [0.0, 2.0]}, True)["tau_c"]
    assert p.at_bound and p.low_open


def test_a_value_near_a_log_scaled_lower_bound_is_not_at_it():
    final = {"sigma_0": {"value": 150.0, "stderr": 10.0, "ci95_low": 130.0, "ci95_high": 170.0}}
    box = {"sigma_0": [100.0, 1e8]}
    p = _records(["sigma_0"], final, {"sigma_0": "N m/rad"}, box, True)["sigma_0"]
    assert not (p.at_bound or p.low_open)
