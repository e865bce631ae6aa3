"""The model report's figure of the 95 % prediction interval against speed
(:meth:`fricid.fitted.FittedModel.predict_interval`): where a new measurement falls, narrow
where the model follows the data and wide where it misses them."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ..errors import ConfigError
from ..fitted import FittedModel
from ..samples import FrictionSamples
from .document import Figure, Note
from .plots import plot_measured, speed_sides
from .style import COLORS, new_figure, png, styled, torque_scale, velocity_scale

__all__ = ["held_at", "prediction_band", "prediction_band_figure"]


def held_at(inputs: Sequence[str], whose: str = "the") -> str:
    """A caption's words for the inputs besides velocity that a curve over velocity holds
    at their median: ``"the median load and temperature"`` (``whose`` first) for a model of
    all three, ``"the median load"`` for one of velocity and load, ``""`` for a model of
    velocity alone (nothing is held)."""
    held = [name for name in ("load", "temperature") if name in inputs]
    return f"{whose} median {' and '.join(held)}" if held else ""


def prediction_band(
    samples: FrictionSamples,
    interval: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]],
    *,
    level: float = 0.95,
    velocity_unit: str = "rad/s",
    title: str = "Where a new measurement falls: the 95 % prediction interval",
) -> bytes:
    """The friction magnitude against speed on a log axis, per direction: the model
    (line) and its ``level`` prediction interval (band) at the median load and temperature
    (those the model uses), the measured samples (markers). ``interval(X)`` returns
    ``(friction, low, high)`` [N m] (:meth:`fricid.fitted.FittedModel.predict_interval`)."""
    vf, vunit = velocity_scale(velocity_unit)
    tf, tunit = torque_scale(samples.friction)
    with styled():
        fig, axes = new_figure(1, 1, width=7.5, height=4.4)
        ax = axes[0, 0]
        for k, d, sel, (label, _, dash), grid, X in speed_sides(samples):
            F, low, high = (d * np.asarray(a, dtype=float) * tf for a in interval(X))
            speed = np.abs(grid) * vf
            ax.fill_between(
                speed,
                np.minimum(low, high),
                np.maximum(low, high),
                color=COLORS[k],
                alpha=0.18,
                lw=0,
                label=f"{level:.0%} interval, {label}",
            )
            ax.plot(speed, F, dash, color=COLORS[k], label=f"model, {label}")
            plot_measured(ax, samples, sel, k, d, vf, tf)
        ax.set_xscale("log")
        ax.set_xlabel(f"speed |velocity| [{vunit}], log scale")
        ax.set_ylabel(f"|friction torque| [{tunit}]")
        ax.legend(loc="best")
        fig.suptitle(title, fontweight="bold")
        return png(fig)


def prediction_band_figure(
    fitted: FittedModel, moving: FrictionSamples, velocity_unit: str
) -> Figure | Note | None:
    """The figure of the model's 95 % prediction interval against speed; None when the
    model file stores none (files from before, trajectory models); a warning note saying why
    when it stores one that cannot be used (a malformed record)."""

    def interval(X: np.ndarray):
        pi = fitted.predict_interval(X, 0.95, warn=False)
        return pi.friction, pi.low, pi.high

    try:
        interval(moving.X[:1])
    except ConfigError as err:
        if not fitted.prediction_interval:
            return None
        return Note(f"No prediction interval is drawn: {err}.", kind="warning")
    record = fitted.prediction_interval or {}
    how = (
        "the local spread of the fit's held-out errors"
        if record.get("local") or record.get("method") == "heldout"
        else "the fit's residuals"
    )
    if record.get("shared_covariance") is not None:
        how += (
            ", and the error every sample shares (the arm's identified gravity, which the "
            "residuals cannot show), added as it is"
        )
    held = held_at(fitted.inputs_used())
    return Figure(
        "prediction_interval",
        "Where a new measurement falls: the 95 % prediction interval",
        prediction_band(moving, interval, velocity_unit=velocity_unit),
        caption="The band holds 95 % of new measured samples at each speed (noise "
        f"included){f', at {held}' if held else ''}; its width follows {how}: narrow "
        "where the model follows the data, wide where it misses them. There is no band inside "
        "a gap between measured speeds: nothing measured backs one there.",
    )
