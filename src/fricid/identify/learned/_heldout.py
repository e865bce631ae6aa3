"""A learned model's held-out errors, carried from its training to the local spread of its
prediction intervals (:func:`fricid.identify._intervals.local_record`): each side's state
holds them under :data:`ERRORS` while the model is assembled, never in the model file."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ...samples import FrictionSamples
from .._intervals import local_record

__all__ = ["ERRORS", "interval_record", "take_errors"]

#: The key of a side's held-out errors [N m] (one per sample of the side, NaN: none).
ERRORS = "_heldout_errors"


def take_errors(
    samples: FrictionSamples, state: dict[str, Any], symmetry: str
) -> np.ndarray | None:
    """Every sample's held-out error [N m], taken out of the state (one side, or ``pos``
    and ``neg`` for a per-direction model); None when a side has none."""
    if symmetry != "per_direction":
        return state.pop(ERRORS, None)
    out = np.full(len(samples.velocity), np.nan)
    for side, d in (("pos", 1), ("neg", -1)):
        held = state[side].pop(ERRORS, None)
        if held is None:
            return None
        out[samples.direction == d] = held
    return out


def interval_record(
    errors: np.ndarray | None, samples: FrictionSamples, scatter: float, source: str
) -> Mapping[str, Any] | None:
    """The model file's ``prediction_interval`` of a learned model (method ``heldout``), or
    None without errors or a known scatter [N m]; ``source`` says what the errors are."""
    if errors is None:
        return None
    local = local_record(errors, samples.X, scatter, source=source)
    return None if local is None else {"method": "heldout", "local": local}
