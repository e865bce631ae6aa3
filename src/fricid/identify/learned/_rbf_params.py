"""The checks of :class:`~fricid.identify.learned._rbf_estimator.RBFNetRegressor`'s parameters,
written here on scikit-learn's public contract alone (validation at ``fit``, parameters kept
as given by ``__init__``), with its wording: ``The 'n_centers' parameter of RBFNetRegressor
must be an int in the range [1, inf). Got 0 instead.``

scikit-learn's own constraint machinery (``sklearn.utils._param_validation``) is private and
may change in any release; fricid allows every scikit-learn from 1.4 on.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from numbers import Integral, Real
from typing import Any

import numpy as np

from ...errors import ConfigError

__all__ = ["CONSTRAINTS", "check_params"]

#: A constraint: (test of a value, what it accepts in words).
Constraint = tuple[Callable[[Any], bool], str]


def _number(kind: type, lo: float, hi: float | None, closed: str, none: bool = False):
    """A number of ``kind`` (Integral or Real; never a bool, NaN or infinity) between ``lo``
    and ``hi`` (None: no upper end), the ends included as ``closed`` says ("left", "right",
    "both", "neither"), or None when ``none``."""

    def test(v: Any) -> bool:
        if v is None:
            return none
        if isinstance(v, bool | np.bool_) or not isinstance(v, kind):
            return False
        if not math.isfinite(float(v)):
            return False
        low_ok = v >= lo if closed in ("left", "both") else v > lo
        high_ok = hi is None or (v <= hi if closed in ("right", "both") else v < hi)
        return bool(low_ok and high_ok)

    left = "[" if closed in ("left", "both") else "("
    right = "]" if hi is not None and closed in ("right", "both") else ")"
    name = "an int" if kind is Integral else "a float"
    words = f"{name} in the range {left}{lo}, {'inf' if hi is None else hi}{right}"
    return test, words + (" or None" if none else "")


def _options(*choices: str) -> Constraint:
    shown = ", ".join(repr(c) for c in sorted(choices))
    return (lambda v: isinstance(v, str) and v in choices), f"a str among {{{shown}}}"


def _boolean(v: Any) -> bool:
    return isinstance(v, bool | np.bool_)


def _random_state(v: Any) -> bool:
    if v is None or isinstance(v, np.random.RandomState):
        return True
    return isinstance(v, Integral) and not isinstance(v, bool) and 0 <= v <= 2**32 - 1


#: Every parameter of RBFNetRegressor and what it accepts (the trainer's name is checked
#: against the methods where it is read).
CONSTRAINTS: dict[str, Constraint] = {
    "n_centers": _number(Integral, 1, None, "left"),
    "trainer": ((lambda v: isinstance(v, str)), "an instance of 'str'"),
    "encoding": _options("hybrid", "full"),
    "init": _options("kmeans", "random"),
    "width_factor": _number(Real, 0, None, "neither"),
    "alpha": _number(Real, 0, None, "left"),
    "fit_bias": (_boolean, "an instance of 'bool'"),
    "linear_tail": (_boolean, "an instance of 'bool'"),
    "linear_magnitude": (
        (lambda v: isinstance(v, list | tuple | np.ndarray)),
        "an array-like (a list, tuple or array of column indices)",
    ),
    "tail_order": _number(Integral, 1, 2, "both"),
    "velocity_stretch": _number(Real, 0, None, "neither"),
    "velocity_scale": _number(Real, 0, None, "neither", none=True),
    "target_mse": _number(Real, 0, None, "neither", none=True),
    "max_epochs": _number(Integral, 1, None, "left"),
    "evals_per_epoch": _number(Integral, 1, None, "left"),
    "method_options": ((lambda v: v is None or isinstance(v, dict)), "a dict or None"),
    "random_state": (
        _random_state,
        "an int in the range [0, 4294967295], a numpy RandomState or None",
    ),
}


def check_params(estimator: Any) -> None:
    """Raise :class:`~fricid.errors.ConfigError` for the first parameter of ``estimator``
    that its constraint (:data:`CONSTRAINTS`) does not accept."""
    owner = type(estimator).__name__
    for name, (test, words) in CONSTRAINTS.items():
        value = getattr(estimator, name)
        if not test(value):
            raise ConfigError(
                f"The {name!r} parameter of {owner} must be {words}. Got {value!r} instead."
            )
