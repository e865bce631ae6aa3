"""Metrics against hand-computed values and their invariants."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from fricid import metrics as M


def test_hand_computed():
    y = np.array([1.0, 2.0, 4.0])
    y_hat = np.array([1.0, 3.0, 2.0])
    assert M.sse(y, y_hat) == 5.0
    assert M.rmse(y, y_hat) == pytest.approx(np.sqrt(5 / 3))
    sst = np.sum((y - y.mean()) ** 2)
    assert M.fitness(y, y_hat) == pytest.approx(1 - 5 / sst)
    assert M.rmspe(y, y_hat) == pytest.approx(np.sqrt((0 + 0.25 + 0.25) / 3))
    assert M.mae(y, y_hat) == pytest.approx(1.0)
    assert M.max_abs_error(y, y_hat) == 2.0


finite = st.floats(-1e3, 1e3, allow_nan=False)


@given(arrays(float, st.integers(2, 40), elements=finite))
def test_perfect_prediction(y):
    assert M.sse(y, y) == 0.0
    assert M.fitness(y, y) == 1.0


@given(arrays(float, st.integers(2, 40), elements=finite), st.floats(-10, 10))
def test_rmse_of_constant_offset(y, c):
    assert M.rmse(y, y + c) == pytest.approx(abs(c), rel=1e-9, abs=1e-9)


def test_shape_mismatch():
    with pytest.raises(ValueError, match="shapes differ"):
        M.sse([1, 2], [1, 2, 3])
