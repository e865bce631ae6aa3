"""Clamping of a model's inputs to its operating range (``fricid export --to c --clamp``).

A model is trusted only over the data it was identified on; the model file records that
operating range (``FittedModel.operating_range``: [low, high] of velocity [rad/s], load [N m]
and temperature [degC]). With clamping the exported C function holds each input the model
uses inside it before evaluating (:func:`clamp_limits`):

* load and temperature: to ``[low, high]``;
* velocity: to ``[low, high]`` when the range spans zero; else (a direction-combined model,
  identified on speeds ``|v|``, records e.g. 0.005 to 4 rad/s) its magnitude to at most the
  largest speed with the sign kept, so the model never extrapolates to higher speeds, stays
  odd in velocity, and is untouched near zero (where smoothing applies).

:func:`clamp_inputs` is the same clamping in Python (what the C computes is
``smooth_predict(fitted, clamp_inputs(fitted, X), smoothing)``). Clamping is off by default.
"""

from __future__ import annotations

import numpy as np

from ..fitted import FittedModel
from ._common import ExportError, fmt_float, operating_pair

__all__ = ["clamp_code", "clamp_inputs", "clamp_limits", "unclamped_speeds"]


def clamp_limits(fitted: FittedModel) -> dict[str, tuple[str, float, float]]:
    """How ``clamp=True`` holds each input the model uses inside its operating range.

    Returns
    -------
    dict
        input name -> ``("range", low, high)`` (clamp to ``[low, high]``) or
        ``("speed", 0.0, high)`` (velocity magnitude at most ``high``, sign kept; a range
        that does not span zero, as a direction-combined model records).

    Raises
    ------
    ExportError
        The model file records no range for an input the model uses, or a zero speed range.
    DataError
        A recorded range that is not two finite numbers with low <= high.
    """
    from .points import model_inputs

    limits: dict[str, tuple[str, float, float]] = {}
    for name in model_inputs(fitted):
        pair = operating_pair(fitted, name)
        if pair is None:
            raise ExportError(
                f"--clamp needs the operating range of {name}, and the model file records "
                "none; export without --clamp"
            )
        lo, hi = pair
        if name == "velocity" and not (lo < 0.0 < hi):
            top = max(abs(lo), abs(hi))
            if top <= 0.0:
                raise ExportError("--clamp: the recorded velocity range is zero")
            limits[name] = ("speed", 0.0, top)
        else:
            limits[name] = ("range", lo, hi)
    return limits


def clamp_inputs(fitted: FittedModel, X) -> np.ndarray:
    """``X`` (n, 3) with its inputs clamped as the C export with ``clamp=True`` does."""
    X = np.array(np.atleast_2d(X), dtype=float)
    columns = {"velocity": 0, "load": 1, "temperature": 2}
    for name, (how, lo, hi) in clamp_limits(fitted).items():
        col = X[:, columns[name]]
        if how == "speed":
            X[:, columns[name]] = np.copysign(np.minimum(np.abs(col), hi), col)
        else:
            X[:, columns[name]] = np.minimum(np.maximum(col, lo), hi)
    return X


def unclamped_speeds(fitted: FittedModel) -> str:
    """One line on the speeds clamping cannot hold, from the measured speeds per direction
    the model file records (``provenance["speeds"]``,
    :func:`fricid.models._range.speed_coverage`): below the slowest measured speed (every
    reversal passes through it) and inside gaps between measured speeds; "" when there are
    none or the file records no speeds."""
    from ..models._range import coverage_text

    coverage = (fitted.provenance or {}).get("speeds")
    if not isinstance(coverage, dict) or "velocity" not in clamp_limits(fitted):
        return ""
    lines = coverage_text(coverage)
    if not lines:
        return ""
    return (
        "--clamp holds the speed to the measured maximum but cannot hold speeds below the "
        "slowest measured one or inside gaps, where the model is extrapolated or interpolated: "
        + "; ".join(lines)
    )


def clamp_code(fitted: FittedModel) -> tuple[list[str], str]:
    """(header comment lines, C statements) of the input clamping, for :mod:`fricid.export.c`."""
    units = {"velocity": "rad/s", "load": "N m", "temperature": "degC"}
    notes, code = [], "    /* clamp the inputs to the operating range */\n"
    for name, (how, lo, hi) in clamp_limits(fitted).items():
        h = fmt_float(hi, f"operating_range.{name}")
        if how == "speed":
            notes.append(f"  |{name}| at most {h} {units[name]}, sign kept")
            code += f"    {name} = copysign(fmin(fabs({name}), {h}), {name});\n"
        else:
            lo_text = fmt_float(lo, f"operating_range.{name}")
            notes.append(f"  {name} held in {lo_text} to {h} {units[name]}")
            code += f"    {name} = fmin(fmax({name}, {lo_text}), {h});\n"
    unheld = unclamped_speeds(fitted)
    if unheld:
        notes.append(f"  not held: {unheld.split(': ', 1)[1]}")
    return ["Inputs are clamped to the operating range before evaluation:", *notes], code
