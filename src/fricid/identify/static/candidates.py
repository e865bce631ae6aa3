"""The models ``"auto"`` may fit (:func:`candidates`), each with the reason the data cannot
support it: the list :func:`fricid.identify.static.select.select` validates and the hybrid's
backbone
search (:mod:`fricid.identify.learned.hybrid`) fits, in a module below both."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...models import get_model
from ...samples import FrictionSamples
from .._scatter import level_labels

__all__ = ["FAMILIES", "LEARNED", "PREFER_SIMPLER", "Candidate", "candidates"]


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


def candidates(samples: FrictionSamples, learned: bool = False) -> list[Candidate]:
    """The families of :data:`FAMILIES` and their ``_asym`` variants, simplest first, each
    with the reason the data cannot support it (module docstring), or ``""``; then, with
    ``learned``, the learned families :data:`LEARNED`.

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
    points = np.unique(
        np.column_stack([levels, np.round(samples.load, 6), np.round(samples.temperature, 1)]),
        axis=0,
    ).shape[0]
    out: list[Candidate] = []
    for asym in (False, True):
        for family, fixed in FAMILIES:
            name = f"{family}_asym" if asym else family
            p = len(get_model(family).param_names) - len(fixed)
            reason = ""
            if family == "msk" and not load_varies:
                reason = "the load does not vary"
            elif family == "vlt" and not (load_varies and temp_varies):
                reason = "the load and the temperature do not both vary"
            elif asym and not {-1, 1} <= dirs:
                reason = "needs samples of both directions"
            elif asym and 0 in dirs:
                reason = "the samples combine both directions (eq. 11)"
            if not reason:
                if asym:
                    have = min(np.unique(levels[samples.direction == d]).size for d in (-1, 1))
                    what = "velocity levels per direction"
                else:
                    have = np.unique(levels).size
                    what = "velocity levels"
                if family in ("msk", "vlt"):
                    have, what = points, "operating points"
                if have <= p:
                    reason = f"{have} {what} for {p} parameters"
            held = {f"{k}_{d}": v for k, v in fixed.items() for d in ("pos", "neg")} if asym else {}
            label = name + (
                f" ({', '.join(f'{k}={v:g}' for k, v in fixed.items())})" if fixed else ""
            )
            out.append(Candidate(label, name, held or dict(fixed), p * (2 if asym else 1), reason))
    return out + (_learned(samples, levels) if learned else [])


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
