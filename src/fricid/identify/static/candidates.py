"""The models ``"auto"`` may fit (:func:`candidates`), each with the reason the data cannot
support it: the list :func:`fricid.identify.static.select.select` validates and the hybrid's
backbone search (:mod:`fricid.identify.learned.hybrid`) fits, in a module below both.

Every family that fits the data's inputs is a candidate: the analytic families of
:data:`FAMILIES`, their ``_asym`` variants, and, when the samples span at least
:data:`TEMPERATURE_MIN_LEVELS` temperatures, the temperature variants (``<name>_temp``,
``<name>_temp_asym``: the Arrhenius viscous term of :mod:`fricid.models._temperature`) of the
families in :data:`TEMPERATURE_FAMILIES`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...models import get_model
from ...samples import FrictionSamples
from .._scatter import input_keys, level_labels

__all__ = [
    "FAMILIES",
    "LEARNED",
    "PREFER_SIMPLER",
    "TEMPERATURE_FAMILIES",
    "TEMPERATURE_MIN_LEVELS",
    "Candidate",
    "candidates",
    "temperature_levels",
]


#: Analytic families tried by ``"auto"``, simplest first (their ``_asym`` variants follow), with
#: parameters held fixed: Stribeck with ``delta = 1`` is the RWSAVSBAS paper's eq. 7 as it
#: identifies it, one parameter fewer than the free shape, which extrapolates poorly from few
#: velocity levels.
FAMILIES: tuple[tuple[str, dict[str, float]], ...] = (
    ("coulomb_viscous", {}),
    ("stribeck", {"delta": 1.0}),
    ("stribeck", {}),
    ("msk", {}),
    ("vlt", {}),
)

#: Families whose temperature variant (``<name>_temp``, :mod:`fricid.models._temperature`)
#: is a candidate: those with a viscous term.
TEMPERATURE_FAMILIES: tuple[str, ...] = ("coulomb_viscous", "stribeck", "msk")

#: Fewest distinct temperatures (to 0.5 degC) for the temperature variants.
TEMPERATURE_MIN_LEVELS = 3

#: A simpler model within this fraction of the best held-out RMSE is preferred.
PREFER_SIMPLER = 0.05

#: Learned families ``"auto"`` also tries (issue 15), when the data suit them.
LEARNED: tuple[str, ...] = ("rbf", "hybrid")

#: Fewest velocity levels per direction for a learned candidate.
LEARNED_MIN_LEVELS = 5

#: Most samples for a learned candidate (each fold of its validation retrains it).
LEARNED_MAX_SAMPLES = 600


@dataclass(frozen=True)
class Candidate:
    """A model ``"auto"`` may fit.

    Attributes
    ----------
    label : str
        ``model`` with its fixed parameters, e.g. ``"stribeck (delta=1)"``.
    model : str
        Registry name.
    fixed : dict of str to float
        Parameters held fixed (``*_asym``: in both directions).
    n_params : int
        Free parameters.
    note : str
        Why the data cannot support it; ``""`` when they can.
    """

    label: str
    model: str
    fixed: dict[str, float]
    n_params: int
    note: str = ""


def _varies(x: np.ndarray, atol: float) -> bool:
    return bool(np.ptp(x) > atol)


def temperature_levels(samples: FrictionSamples) -> int:
    """Distinct temperatures of ``samples``, to 0.5 degC (0 when not measured)."""
    temps = samples.temperature[np.isfinite(samples.temperature)]
    return int(np.unique(np.round(temps * 2.0)).size)


def candidates(samples: FrictionSamples, learned: bool = False) -> list[Candidate]:
    """The families of :data:`FAMILIES` and their ``_asym`` variants, simplest first, each
    followed by its temperature variant where :data:`TEMPERATURE_FAMILIES` has one and the
    temperature varies at all, each with the reason the data cannot support it (module
    docstring), or ``""``; then, with ``learned``, the learned families :data:`LEARNED`.

    Parameters
    ----------
    samples : FrictionSamples
    learned : bool, default False
        Add the learned families.

    Returns
    -------
    list of Candidate
    """
    dirs = set(samples.directions())
    levels = level_labels(samples)
    load_varies = _varies(samples.load, 1e-9)
    temp_varies = _varies(samples.temperature, 0.5)
    temps = temperature_levels(samples)
    points = np.unique(
        np.column_stack([levels, *input_keys(samples)]),
        axis=0,
    ).shape[0]
    out: list[Candidate] = []
    for asym in (False, True):
        for family, fixed in FAMILIES:
            # a temperature that does not vary at all: its variants are not listed
            variants = [False, True] if family in TEMPERATURE_FAMILIES and temps > 1 else [False]
            for temp in variants:
                name = family + ("_temp" if temp else "") + ("_asym" if asym else "")
                held = (
                    {f"{k}_{d}": v for k, v in fixed.items() for d in ("pos", "neg")}
                    if asym
                    else dict(fixed)
                )
                p = len(get_model(name).param_names) - len(held)
                # what one direction's levels must determine: the family's own parameters
                need = len(get_model(family).param_names) - len(fixed) if asym else p
                reason = _reason(samples, family, asym, dirs, load_varies, temp_varies)
                if not reason and temp and temps < TEMPERATURE_MIN_LEVELS:
                    reason = (
                        f"{temps} temperature(s): the Arrhenius term needs {TEMPERATURE_MIN_LEVELS}"
                    )
                if not reason:
                    have, what = _support(samples, levels, family, asym, temp, points)
                    if have <= (p if temp else need):
                        reason = f"{have} {what} for {p if temp else need} parameters"
                if not reason and len(samples) <= p:  # the operating points count both sides
                    reason = f"{len(samples)} samples for {p} parameters"
                label = name + (
                    f" ({', '.join(f'{k}={v:g}' for k, v in fixed.items())})" if fixed else ""
                )
                out.append(Candidate(label, name, held, p, reason))
    return out + (_learned(samples, levels) if learned else [])


def _reason(
    samples: FrictionSamples,
    family: str,
    asym: bool,
    dirs: set[int],
    load_varies: bool,
    temp_varies: bool,
) -> str:
    """Why the data's inputs cannot support ``family`` (``_asym``), or ``""``."""
    if family == "msk" and not load_varies:
        return "the load does not vary"
    if family == "vlt" and not (load_varies and temp_varies):
        return "the load and the temperature do not both vary"
    if asym and not {-1, 1} <= dirs:
        return "needs samples of both directions"
    if asym and 0 in dirs:
        return "the samples combine both directions (eq. 11)"
    return ""


def _support(
    samples: FrictionSamples,
    levels: np.ndarray,
    family: str,
    asym: bool,
    temp: bool,
    points: int,
) -> tuple[int, str]:
    """(count, what): what the data offer the parameters of a candidate: velocity levels
    (per direction for ``_asym``), or operating points for the load and temperature models."""
    if family in ("msk", "vlt") or temp:
        return points, "operating points"
    if asym:
        have = min(np.unique(levels[samples.direction == d]).size for d in (-1, 1))
        return int(have), "velocity levels per direction"
    return int(np.unique(levels).size), "velocity levels"


def _learned(samples: FrictionSamples, levels: np.ndarray) -> list[Candidate]:
    """The learned families (issue 15): ``rbf`` (the structured network) and ``hybrid``
    (analytic backbone plus RBF residual). Their ``n_params`` is the number of samples (an
    upper bound: their size is chosen by cross-validation), so the rule "the simplest within
    5 % of the best" picks one only when it is clearly better than every analytic family."""
    n = len(samples)
    dirs = [d for d in (-1, 0, 1) if d in set(samples.directions())]
    have = min(np.unique(levels[samples.direction == d]).size for d in dirs)
    reason = ""
    if have < LEARNED_MIN_LEVELS:
        reason = (
            f"{have} velocity levels per direction (a learned model needs {LEARNED_MIN_LEVELS})"
        )
    elif n > LEARNED_MAX_SAMPLES:
        reason = (
            f"{n} samples: validating a learned model refits it per fold (slow over "
            f"{LEARNED_MAX_SAMPLES}); fit 'rbf' or 'hybrid' by name"
        )
    elif 0 in dirs and len(dirs) > 1:
        reason = "the samples mix combined and per-direction rows"
    return [Candidate(name, name, {}, n, reason) for name in LEARNED]
