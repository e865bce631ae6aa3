"""Is a model compared with samples in another torque unit? A header that names the wrong one.

A samples file whose friction column is headed ``friction [mN m]`` while its numbers are in
N m reads 1000x too small, and a model identified on honest data then misses every sample by
the factor: R² near minus a million, a relative error of 1e5 %, numbers that are right for the
file as labelled and say nothing about the model. :func:`torque_unit_mismatch` recognises it
from the model and the samples alone: the model predicts a known unit factor
(:data:`FACTORS`, the ratios between the torque units a header may name) times every moving
sample, and the samples rescaled by it fit the model closely. A model of another drive, whose
friction is merely larger, gives neither a ratio that close to 1000 at every sample nor that
close a fit once rescaled, so honest data do not trigger it.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ..fitted import FittedModel
from ..samples import FrictionSamples
from ..units import UNITS

__all__ = ["FACTORS", "torque_unit_mismatch"]

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
