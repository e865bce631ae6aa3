"""A warning from deep inside fricid names the user's line (``file:line: Category:``), not
a line of the library, however deep the call that raised it."""

from __future__ import annotations

import inspect
import warnings

import numpy as np
import pytest

from fricid.errors import ConvergenceWarning, FricidWarning, IdentifiabilityWarning
from fricid.identify import fit
from fricid.samples import FrictionSamples


def _samples(v: np.ndarray) -> FrictionSamples:
    v = np.concatenate([v, -v])
    f = np.sign(v) * (0.1 + 0.05 * np.exp(-((v / 0.05) ** 2))) + 0.02 * v
    f = f + 1e-4 * np.random.default_rng(0).standard_normal(v.size)
    return FrictionSamples(v, None, None, f)


def _check(caught, lines) -> None:
    ours = [w for w in caught if issubclass(w.category, FricidWarning)]
    assert set(lines) <= {w.category for w in ours}, [w.category for w in ours]
    for w in ours:
        assert w.filename == __file__, (w.category.__name__, w.filename, w.lineno)
        if w.category in lines:
            assert w.lineno == lines[w.category], (w.category.__name__, w.lineno)


def test_a_convergence_warning_points_at_the_caller():
    lines = {}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lines[ConvergenceWarning] = inspect.currentframe().f_lineno + 1
        fit(_samples(np.geomspace(0.5, 1.0, 5)), "stribeck", max_evals=20)  # budget too small
    _check(caught, lines)


@pytest.mark.slow  # 3-7 s measured under load (a multi-start fit on degenerate data)
def test_an_identifiability_warning_points_at_the_caller():
    lines = {}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lines[IdentifiabilityWarning] = inspect.currentframe().f_lineno + 1
        fit(_samples(np.geomspace(0.5, 1.0, 5)), "stribeck", fixed={"delta": 1.0})
    _check(caught, lines)


def test_user_stacklevel_is_one_outside_fricid():
    from fricid.errors import user_stacklevel

    assert user_stacklevel() == 1  # called from a test: this frame is the user's
