"""A position column's unit from its encoder's steps (``fricid.samples.position_unit_problem``):
a binary encoder read in degrees or revolutions labelled radians is named; radians, a
continuous position and other encoders are not."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from fricid.samples import encoder_quantum, position_unit_problem


def motion(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(5000) / 500.0
    return rng.uniform(0.2, 2.0) * np.sin(rng.uniform(0.2, 3.0) * t + rng.uniform(0, 6))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), bits=st.integers(10, 20))
@example(seed=6785, bits=17)  # never slower than 5 counts a sample: found by this property
@example(seed=837, bits=20)  # never slower than 13
def test_a_binary_encoder_is_named_in_the_wrong_unit_only(seed, bits):
    """Written in full: radians pass, degrees and revolutions are named with the encoder."""
    step = 2 * math.pi / 2**bits
    q = np.round(motion(seed) / step) * step
    assert position_unit_problem(q) is None
    degrees = position_unit_problem(np.degrees(q))
    assert degrees is not None and "in degrees labelled radians" in degrees
    turns = position_unit_problem(q / (2 * math.pi))
    assert turns is not None and "in revolutions labelled radians" in turns
    labelled_degrees = position_unit_problem(np.radians(q))  # radians read as degrees
    assert labelled_degrees is not None and "radians labelled degrees" in labelled_degrees


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), bits=st.integers(10, 22))
def test_positions_written_with_few_decimals_raise_no_false_claim(seed, bits):
    """Written with 7 decimals (a 2^17 count's steps read to 1e-4 of the power of two, a
    2^21 count's not at all): radians are never named, whatever the rounding leaves."""
    step = 2 * math.pi / 2**bits
    q = np.round(motion(seed) / step) * step
    assert position_unit_problem(np.round(q, 7)) is None


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), counts=st.sampled_from([1000, 2500, 10000, 36000]))
def test_other_encoders_and_continuous_positions_are_not_judged(seed, counts):
    """Decimal encoders read in radians or degrees, and a continuous position: no claim."""
    q = motion(seed)
    assert encoder_quantum(q) is None and position_unit_problem(q) is None
    step = 2 * math.pi / counts
    counted = np.round(q / step) * step
    assert position_unit_problem(counted) is None
    assert position_unit_problem(np.degrees(counted)) is None


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), bits=st.integers(14, 20), digits=st.integers(7, 12))
@example(seed=1, bits=18, digits=7)  # up to 268 counts a sample: found by this property
def test_an_encoder_written_with_few_significant_digits_is_still_read(seed, bits, digits):
    """A file's rounding moves the steps off whole counts: a 2^18-count log written with 7 or
    9 significant digits had been read as continuous, its LuGre fit then putting delta at
    0.72 [0.23, 1.21] for 2 with no flag. Fast motion (steps of up to ~150 counts) multiplies
    the smallest step's rounding error; the candidate is refined on the small steps and each
    step is allowed its own rounding."""
    step = 2 * math.pi / 2**bits
    q = np.round(motion(seed) / step) * step
    if digits < 9 and bits > 18:  # the digits must resolve a count: 1e-7 of 1 rad is 0.04
        return
    written = np.array([float(f"{x:.{digits}g}") for x in q])
    got = encoder_quantum(written)
    assert got is not None
    assert 2 * math.pi / got == pytest.approx(2**bits, rel=1e-4)


def test_a_continuous_position_written_with_few_digits_is_not_read_as_an_encoder():
    q = motion(3) + 1e-4 * np.random.default_rng(3).standard_normal(5000)
    for digits in (6, 7, 9, 17):
        assert encoder_quantum(np.array([float(f"{x:.{digits}g}") for x in q])) is None
