"""Can these samples determine this model? Checked before fitting, not discovered after.

A least-squares fit always returns numbers. When the data cannot determine the parameters it
returns one point of a whole family that fits equally well, with nothing in R^2 to say so:
a single velocity level for the five-parameter Stribeck model ([B] eq. 2, [R] eq. 7) fits to
R^2 ~ 1e-16 with arbitrary tau_s, w_s, delta; all velocities zero give R^2 -29, since every
model here is proportional to sign(v). :func:`check_identifiable` counts what the data
offer against what the model needs:

- velocity: distinct speed levels |v| (per direction for a per-direction model) against the
  number of free parameters that shape the velocity curve;
- load: for models with load coefficients ([B] eq. 3 and 4), at least two distinct |load|;
- temperature: for models with temperature coefficients ([B] eq. 4, the Arrhenius term of
  ``*_temp`` models), at least two distinct temperatures.

It raises :class:`~fricid.errors.DataError` when nothing useful can be fitted (no moving
sample, a single speed, fewer moving samples than free parameters) and warns
:class:`~fricid.errors.IdentifiabilityWarning`, naming the parameters, when the fit still
describes the data seen but some parameters are not determined by them.
"""

from __future__ import annotations

import warnings
from collections.abc import Collection

import numpy as np

from ...errors import DataError, IdentifiabilityWarning, user_stacklevel
from ...models import FrictionModel, get_model
from ...samples import FrictionSamples

__all__ = ["LEVEL_RTOL", "check_identifiable"]

#: Two values closer than this, relative to the largest magnitude, count as one level.
LEVEL_RTOL = 1e-6

#: Parameter kinds (``Parameter.kind``) that only act through the load or the temperature.
_LOAD_KINDS = ("load_coef",)
_TEMPERATURE_KINDS = ("temp_coef", "velocity_temp", "activation")


def _levels(values: np.ndarray) -> np.ndarray:
    """The distinct values, merging those within :data:`LEVEL_RTOL` of the largest magnitude."""
    if values.size == 0:
        return values
    v = np.sort(values)
    tol = LEVEL_RTOL * float(np.max(np.abs(v)))
    keep = np.concatenate([[True], np.diff(v) > tol])
    return v[keep]


def _group(model: FrictionModel, fixed: Collection[str]) -> dict[str, list[str]]:
    """Free parameters by what varies them: velocity, load or temperature."""
    groups: dict[str, list[str]] = {"velocity": [], "load": [], "temperature": []}
    for p in model.parameters:
        if p.name in fixed:
            continue
        if p.kind in _LOAD_KINDS:
            groups["load"].append(p.name)
        elif p.kind in _TEMPERATURE_KINDS:
            groups["temperature"].append(p.name)
        else:
            groups["velocity"].append(p.name)
    return groups


def _direction_sets(
    model: FrictionModel, velocity: np.ndarray, names: list[str]
) -> list[tuple[str, np.ndarray, list[str]]]:
    """``(label, |v| of the moving samples, parameters)`` per independently fitted set."""
    moving = velocity != 0
    if not model.is_asymmetric:
        return [("", np.abs(velocity[moving]), names)]
    out = []
    for sign, suffix, word in ((1, "_pos", "positive"), (-1, "_neg", "negative")):
        mask = np.sign(velocity) == sign
        out.append(
            (
                f" in the {word} direction",
                np.abs(velocity[mask]),
                [n for n in names if n.endswith(suffix)],
            )
        )
    return out


def _warn(message: str, stacklevel: int) -> None:
    warnings.warn(message, IdentifiabilityWarning, stacklevel=user_stacklevel())


def check_identifiable(
    samples: FrictionSamples,
    model: str | FrictionModel,
    *,
    fixed: Collection[str] = (),
    stacklevel: int = 2,
) -> tuple[str, ...]:
    """Check, before fitting, that ``samples`` can determine the free parameters of ``model``.

    Parameters
    ----------
    samples : FrictionSamples
        The data the model is to be fitted to.
    model : str or FrictionModel
        An analytic model or its registry name (``"stribeck"``, ``"msk_asym"``, ...).
    fixed : Collection[str]
        Names of the parameters held fixed (a ``fixed=`` mapping of :func:`fricid.identify.fit`
        works): they need no data.
    stacklevel : int
        Kept for callers that pass it; the warning points at the first caller outside
        fricid whatever the depth (:func:`fricid.errors.user_stacklevel`).

    Returns
    -------
    tuple of str
        The parameters the data do not determine (each also named in a warning); empty when
        every free parameter is determined as far as these counts can tell.

    Raises
    ------
    DataError
        Naming the samples' source: no sample with non-zero velocity; a single speed level
        (per direction for a per-direction model) for a model with several velocity
        parameters; fewer moving samples than free parameters.

    Warns
    -----
    IdentifiabilityWarning
        Fewer distinct speed levels than free velocity parameters; a constant |load| for
        load coefficients; a constant temperature for temperature coefficients.

    Notes
    -----
    The counts are necessary conditions, not sufficient ones: levels all far above the
    Stribeck velocity still leave w_s and delta poorly determined, which only the fit's
    standard errors show.
    """
    model = get_model(model)
    groups = _group(model, set(fixed))
    src = samples.source
    n_free = sum(len(g) for g in groups.values())
    moving = int(np.count_nonzero(samples.velocity))
    if moving == 0:
        raise DataError(
            f"all {len(samples)} samples have zero velocity; the friction models are "
            "proportional to sign(v), so samples at rest determine none of the parameters of "
            f"'{model.name}' (measure at constant non-zero velocities)",
            file=src,
        )
    if moving < n_free:
        raise DataError(
            f"{moving} samples with non-zero velocity cannot determine the {n_free} free "
            f"parameters of '{model.name}'",
            file=src,
        )
    flagged: list[str] = []
    for where, speeds, names in _direction_sets(model, samples.velocity, groups["velocity"]):
        n_levels = len(_levels(speeds))
        if len(names) <= n_levels:
            continue
        listed = ", ".join(names)
        if n_levels <= 1 and len(names) > 1:
            got = "no moving sample" if n_levels == 0 else "a single velocity level"
            raise DataError(
                f"{got}{where} cannot determine the {len(names)} velocity parameters "
                f"{listed} of '{model.name}' (it gives one friction value); measure at "
                f"{len(names)} or more speeds, or fix parameters",
                file=src,
            )
        flagged.extend(names)
        _warn(
            f"{src + ': ' if src else ''}{n_levels} distinct velocity levels{where} do not "
            f"determine all {len(names)} velocity parameters {listed} of '{model.name}' (at "
            f"least {len(names)} needed); measure more speeds or fix some parameters",
            stacklevel,
        )
    checks = (
        ("load", np.abs(samples.load), "|load|", "N m"),
        ("temperature", samples.temperature, "temperature", "degC"),
    )
    for group, values, label, unit in checks:
        names = groups[group]
        levels = _levels(values)
        if not names or len(levels) > 1:
            continue
        flagged.extend(names)
        how = (
            "is zero in every sample, so they have no effect"
            if group == "load" and levels[0] == 0
            else f"is the same ({levels[0]:g} {unit}) in every sample, so they cannot be told "
            "apart from the constant terms"
        )
        _warn(
            f"{src + ': ' if src else ''}parameters {', '.join(names)} of '{model.name}' are "
            f"not determined: {label} {how}; fix them or measure at two or more {group}s",
            stacklevel,
        )
    return tuple(flagged)
