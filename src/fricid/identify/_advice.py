"""What to do about a model whose held-out error misses the measurement scatter (the trust
verdict's "no", :mod:`fricid.identify.trust`): advice computed from the file and the
validation, never a promise of what another model would achieve.

Three readings, from the in-sample error against the scatter and, for leave-one-velocity-out,
the interior folds (:func:`fricid.identify.validate.interior_rmse`):

- the in-sample error alone misses (over :data:`~fricid.identify.trust.MISS_RATIO` times the
  scatter): the family cannot follow the data, and more data will not change that; a learned
  model (the hybrid: an analytic backbone plus a learned residual) or the comparison of every
  family by held-out error (``--model auto --learned``) is what to try;
- the model follows the measured set-points but misses the interior held-out levels: between
  the measured speeds its predictions are not backed by the data; measure more velocity levels
  in the widest gaps, or compare the families by held-out error;
- it follows the set-points and the interior levels, and misses only when the slowest or the
  fastest level is held out: an extrapolation; its predictions inside the measured speeds
  held up.

Before them, a model with a temperature law fitted on samples at one temperature is told so:
the law needs two temperatures or more, so the remedy is a recording at another temperature or
the model without the law, not a learned model.

Apart from them, whether the errors compare two torque units at all
(:func:`torque_unit_mismatch`, the report's check): a samples file whose friction column is
headed ``friction [mN m]`` while its numbers are in N m reads 1000x too small, and a model
identified on honest data then misses every sample by the factor: R² near minus a million, a
relative error of 1e5 %, numbers that are right for the file as labelled and say nothing about
the model. :func:`torque_unit_mismatch` recognises it from the model and the samples alone: the
model predicts a known unit factor (:data:`FACTORS`, the ratios between the torque units a
header may name) times every moving sample, and the samples rescaled by it fit the model
closely. A model of another drive, whose friction is merely larger, gives neither a ratio that
close to 1000 at every sample nor that close a fit once rescaled, so honest data do not trigger
it. A velocity column under the wrong unit (``velocity [rpm]`` over numbers in rad/s) is
recognised alike (:func:`velocity_unit_mismatch`): the samples' velocities times a known unit
factor (:data:`VELOCITY_FACTORS`) fall inside the model's operating range and fit it far more
closely than as read. :func:`unit_mismatches` runs both checks.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from ..fitted import FittedModel
from ..metrics import rmse
from ..samples import FrictionSamples
from ..units import UNITS
from .static.checks import _levels
from .validate import interior_rmse

__all__ = [
    "FACTORS",
    "VELOCITY_FACTORS",
    "misfit_advice",
    "torque_unit_mismatch",
    "unit_mismatches",
    "velocity_unit_mismatch",
]


def _in_sample_ratio(fitted: FittedModel, samples: FrictionSamples | None, scatter: float):
    """The in-sample error over the scatter: the file's, or on ``samples`` when the file has
    none or the fit was robust (the file's holds the outliers; ``samples`` are the inliers)."""
    ratio = fitted.metrics.get("rmse_over_scatter")
    robust = (fitted.loss or {}).get("loss") in ("soft_l1", "huber") and samples is not None
    if ratio is not None and not robust:
        return float(ratio)
    if samples is None or not np.isfinite(scatter) or scatter <= 0:
        return float("nan")
    return rmse(samples.y, fitted.predict(samples.X, warn=False)) / scatter


def _one_temperature(fitted: FittedModel, samples: FrictionSamples | None) -> float | None:
    """The one temperature [degC] a model with a temperature law was fitted at (the samples',
    else the file's operating range), None when it uses no temperature or saw two or more."""
    if fitted.kind == "rbf" or "temperature" not in fitted.inputs_used():
        return None
    if samples is not None:
        levels = _levels(samples.temperature[np.isfinite(samples.temperature)])
        return float(levels[0]) if levels.size == 1 else None
    span = (fitted.operating_range or {}).get("temperature")
    if isinstance(span, list | tuple) and len(span) == 2 and span[0] == span[1]:
        return float(span[0])
    return None


def _without_temperature(model: str) -> str:
    """``--model`` options without a temperature law to fit instead of ``model``: its own
    family's (``stribeck_temp`` -> ``stribeck``, ``stribeck_temp_asym`` -> ``stribeck_asym``),
    vlt's load law alone (BAS-RBFNN paper eq. 4 -> eq. 3: ``msk``), else stribeck's."""
    if model in ("vlt", "vlt_asym"):
        return f"--model {model.replace('vlt', 'msk')}"
    if model.endswith("_temp_asym"):
        return f"--model {model[: -len('_temp_asym')]}_asym"
    base = model[: -len("_temp")] if model.endswith("_temp") else "stribeck"
    return f"--model {base} or --model {base}_asym"


def misfit_advice(
    fitted: FittedModel,
    validation: dict[str, Any] | None,
    scatter: float,
    miss_ratio: float,
    samples: FrictionSamples | None = None,
) -> str:
    """What to do about a model whose (held-out) error exceeds ``miss_ratio`` scatters.

    Parameters
    ----------
    fitted : FittedModel
    validation : dict or None
        The validation the verdict is on (``Validation.to_dict()``), None for in-sample.
    scatter : float
        N m, the measurement scatter.
    miss_ratio : float
        The verdict's threshold (:data:`fricid.identify.trust.MISS_RATIO`).
    samples : FrictionSamples, optional
        Without a recorded in-sample ratio, or for a robust fit (``--loss soft_l1``,
        ``huber``: the samples given are its inliers), the in-sample error is computed on
        them. The
        commands name them ``SAMPLES``, not by their file: the advice is part of the trust
        record, which depends on the samples' content, not on where they were read from.

    Returns
    -------
    str
        One sentence (module notes), ``""`` when no reading applies.
    """
    name = "SAMPLES"
    one = _one_temperature(fitted, samples)
    if one is not None:
        return (
            f"the samples hold one temperature ({one:g} degC), and the temperature law of "
            f"{fitted.model} needs at least two: record at another temperature, or fit a model "
            f"without temperature (fricid fit {name} {_without_temperature(fitted.model)})"
        )
    learned = fitted.kind == "rbf"
    r_in = _in_sample_ratio(fitted, samples, scatter)
    auto = f"compare every family by held-out error (fricid fit {name} --model auto --learned)"
    if np.isfinite(r_in) and r_in > miss_ratio and learned:
        return (
            f"it does not follow the measured set-points either (in-sample {r_in:.3g}x the "
            "scatter): the settings it chose trade them for smoothness between the measured "
            f"speeds; measure more velocity levels in the widest gaps, or {auto}"
        )
    if np.isfinite(r_in) and r_in > miss_ratio:
        what = f"the {fitted.model} family"
        return (
            f"{what} cannot follow these data: its in-sample error alone is {r_in:.3g}x the "
            "scatter, so more data will not help; fit a learned model (fricid fit "
            f"{name} --model hybrid: an analytic backbone plus a learned residual), or {auto}"
        )
    folds = (validation or {}).get("folds") or []
    if (validation or {}).get("scheme") != "lovo" or len(folds) < 3 or not np.isfinite(r_in):
        return (
            f"it follows the samples in-sample ({r_in:.3g}x the scatter) but not held out: too "
            f"flexible for these data; {auto}"
            if np.isfinite(r_in)
            else ""
        )
    inner = interior_rmse(folds) / scatter
    speeds = np.sort([float(f["speed"]) for f in folds if float(f["speed"]) > 0])
    gap = float(np.max(speeds[1:] / speeds[:-1])) if speeds.size > 1 else float("nan")
    if np.isfinite(inner) and inner <= miss_ratio:
        return (
            f"it follows the measured set-points (in-sample {r_in:.3g}x the scatter) and the "
            f"interior held-out levels ({inner:.3g}x), and misses when the slowest or fastest "
            f"level is held out: an extrapolation; its predictions between "
            f"{speeds[0]:.3g} and {speeds[-1]:.3g} rad/s held up, beyond them measure first"
        )
    other = f"; or {auto}" if learned else ""
    return (
        f"it follows the measured set-points (in-sample {r_in:.3g}x the scatter) but not the "
        f"velocity levels held out (interior folds {inner:.3g}x): between the {len(folds)} "
        f"measured speeds, up to {gap:.3g}x apart, its predictions are not backed by the data; "
        f"measure more velocity levels in the widest gaps{other}"
    )


#: The factors a wrong torque unit in a header scales the numbers by (1000: mN m against N m).
FACTORS = sorted(
    {a / b for (a, _), (b, _) in itertools.permutations(UNITS["torque"].values(), 2) if a != b}
)
#: The middle 80 % of the per-sample ratios must lie within this relative distance of a factor.
RATIO_TOLERANCE = 0.05
#: ... and the rescaled samples' RMSE within this share of the predicted friction's RMS.
FIT_SHARE = 0.1
#: Moving samples needed for a judgement.
MIN_SAMPLES = 3


def torque_unit_mismatch(fitted: FittedModel, samples: FrictionSamples) -> str | None:
    """Why the errors of ``fitted`` on ``samples`` compare two torque units, else None.

    Returns
    -------
    str or None
        E.g. ``"the model predicts 1000x the measured friction at every moving sample of
        lsbad.csv, and the samples times 1000 follow it within 0.6 % of its RMS: ..."``,
        naming the friction column's header as the likely cause; None when the model and the
        samples agree in scale, or when too few samples move to tell.
    """
    moving = (samples.velocity != 0) & (samples.friction != 0)
    if int(moving.sum()) < MIN_SAMPLES:
        return None
    measured = samples.friction[moving]
    predicted = np.asarray(fitted.predict(samples.X[moving], warn=False), dtype=float)
    ok = np.isfinite(predicted) & (predicted != 0)
    if int(ok.sum()) < MIN_SAMPLES:
        return None
    measured, predicted = measured[ok], predicted[ok]
    ratio = predicted / measured
    low, mid, high = np.quantile(ratio, [0.1, 0.5, 0.9])
    if not low > 0:
        return None
    factor = min(FACTORS, key=lambda f: abs(math.log(mid / f)))
    if not all(abs(r / factor - 1.0) <= RATIO_TOLERANCE for r in (low, high)):
        return None
    miss = float(np.sqrt(np.mean((factor * measured - predicted) ** 2)))
    size = float(np.sqrt(np.mean(predicted**2)))
    if not miss <= FIT_SHARE * size:
        return None
    name = str(samples.source).rsplit("/", 1)[-1] if samples.source else "these samples"
    big, small = ("N m", "mN m") if factor > 1 else ("mN m", "N m")
    return (
        f"the model predicts {factor:.4g}x the measured friction at every moving sample of "
        f"{name} (ratios {low:.4g} to {high:.4g}), and the samples times {factor:.4g} follow "
        f"it within {100 * miss / size:.2g} % of its size: the friction column's header in "
        f"{name} likely names the wrong torque unit (numbers in {big} under a header in "
        f"{small}; or the model was identified on such a file), so the errors on these "
        "samples compare two units and say nothing about the model"
    )


#: The factors a wrong velocity unit in a header scales the speeds by (9.55: rad/s under rpm).
VELOCITY_FACTORS = sorted(
    {a / b for (a, _), (b, _) in itertools.permutations(UNITS["velocity"].values(), 2) if a != b}
)
#: The rescaled samples must fit the model this many times closer than as read ...
CLOSER = 3.0
#: ... with this share of the moving rows, rescaled, inside the model's operating range.
INSIDE_SHARE = 0.8


def _miss(fitted: FittedModel, X: np.ndarray, measured: np.ndarray) -> float:
    """RMS of the measured minus the predicted friction where the prediction is finite."""
    predicted = np.asarray(fitted.predict(X, warn=False), dtype=float)
    ok = np.isfinite(predicted)
    return rmse(measured[ok], predicted[ok]) if ok.sum() >= MIN_SAMPLES else float("inf")


def _velocity_units(factor: float) -> tuple[str, str]:
    """The unit the numbers are in and the one the header names, for ``factor`` (the true
    velocities over the velocities as read)."""
    names = list(UNITS["velocity"])
    return next(
        (true, header)
        for true, header in itertools.permutations(names, 2)
        if math.isclose(UNITS["velocity"][true][0] / UNITS["velocity"][header][0], factor)
    )


def velocity_unit_mismatch(fitted: FittedModel, samples: FrictionSamples) -> str | None:
    """Why the errors of ``fitted`` on ``samples`` compare two velocity units, else None.

    Returns
    -------
    str or None
        E.g. ``"the samples' velocities times 9.549 ... : the velocity column's header in
        ls.csv likely names the wrong unit (numbers in rad/s under a header in rpm ...)"``:
        the rescaled samples fall inside the model's operating range (:data:`INSIDE_SHARE`)
        and fit it within :data:`FIT_SHARE` of the friction's size, :data:`CLOSER` times
        closer than as read; None otherwise, or when too few samples move to tell.
    """
    moving = samples.velocity != 0
    if int(moving.sum()) < MIN_SAMPLES:
        return None
    X, measured = np.array(samples.X[moving], dtype=float), samples.friction[moving]
    size = float(np.sqrt(np.mean(measured**2)))
    as_read = _miss(fitted, X, measured)
    best: tuple[float, float] | None = None
    for factor in VELOCITY_FACTORS:
        scaled = X.copy()
        scaled[:, 0] *= factor
        if np.mean(~fitted.outside_range(scaled)) < INSIDE_SHARE:
            continue
        miss = _miss(fitted, scaled, measured)
        if miss <= FIT_SHARE * size and CLOSER * miss <= as_read and (not best or miss < best[1]):
            best = (factor, miss)
    if best is None:
        return None
    factor, miss = best
    true, header = _velocity_units(factor)
    name = str(samples.source).rsplit("/", 1)[-1] if samples.source else "these samples"
    return (
        f"the samples' velocities times {factor:.4g} follow the model within "
        f"{100 * miss / size:.2g} % of the friction's size, as read it misses by "
        f"{100 * as_read / size:.3g} %: the velocity column's header in {name} likely names "
        f"the wrong unit (numbers in {true} under a header in {header}; or the model was "
        "identified on such a file), so the errors on these samples compare two units and say "
        "nothing about the model"
    )


def unit_mismatches(fitted: FittedModel, samples: FrictionSamples) -> dict[str, str]:
    """The unit checks that found a header naming the wrong unit: ``{"torque unit": why}``
    (:func:`torque_unit_mismatch`), else ``{"velocity unit": why}``
    (:func:`velocity_unit_mismatch`), else empty."""
    torque = torque_unit_mismatch(fitted, samples)
    if torque:
        return {"torque unit": torque}
    velocity = velocity_unit_mismatch(fitted, samples)
    return {"velocity unit": velocity} if velocity else {}
