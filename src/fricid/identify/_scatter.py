"""The measurement scatter of friction samples, estimated from the data themselves.

A fit is good when its error is as small as the noise of the data it is compared with: the
standard error of each set-point's mean friction. :func:`measurement_scatter` estimates it, in
this order of preference (issue 11, "Validation built in"):

1. standard errors given by the caller (``sem=``, e.g. the scatter of repeated passes that
   :func:`fricid.extract.extract` computes as ``ExtractionResult.direction_sem``), or carried
   by the samples as ``meta["sem"]`` (method ``meta["sem_method"]`` where the extraction or
   reader recorded it, else "given");
2. the raw steady samples of each set-point (``raw=``): within-run, with the autocorrelation
   taken into account (an effective sample size from the lag-1 autocorrelation, and batch
   means; the larger standard error of the two);
3. repeated runs at one operating point among the samples: the pooled between-run standard
   deviation;
4. the samples' own ``std / sqrt(count)``, with the caveat that it ignores autocorrelation
   and is a lower bound.

It lives apart from :mod:`fricid.identify.validate` (which re-exports it) because ``fit``
uses it too (the scale of the robust losses, the weights), and validation calls ``fit``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..metrics import sem_autocorrelated
from ..samples import FrictionSamples

__all__ = [
    "WEIGHTS",
    "Scatter",
    "level_labels",
    "measurement_scatter",
    "sample_weights",
    "sem_autocorrelated",
    "speed_levels",
]

#: Relative gap between two velocity levels (as the extraction's set-point clustering).
LEVEL_RTOL = 0.05


@dataclass(frozen=True)
class Scatter:
    """The measurement scatter of samples and how it was estimated.

    Attributes
    ----------
    value : float
        N m, root mean square of ``per_sample``: the scatter an RMSE is compared with. NaN
        when it cannot be estimated.
    per_sample : numpy.ndarray
        N m, the standard error of each sample's friction.
    method : str
        ``"given"``, ``"within-run, autocorrelation-corrected"``, ``"between repeated runs"``,
        ``"within-run, std/sqrt(count)"`` or ``"none"``.
    caveat : str
        What the estimate leaves out ("" when nothing known).
    """

    value: float
    per_sample: np.ndarray = field(repr=False)
    method: str
    caveat: str = ""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: value, method and caveat (not the per-sample array)."""
        v = float(self.value)
        value = v if np.isfinite(v) else None
        return {"value": value, "method": self.method, "caveat": self.caveat}

    def describe(self) -> str:
        """``"1.4e-05 N m (within-run, std/sqrt(count); ...)"``."""
        if not np.isfinite(self.value):
            return f"unknown ({self.caveat})"
        note = f"; {self.caveat}" if self.caveat else ""
        return f"{self.value:.3g} N m ({self.method}{note})"


def level_labels(samples: FrictionSamples, rtol: float = LEVEL_RTOL) -> np.ndarray:
    """Velocity level of each sample: speeds ``|v|`` within ``rtol`` of each other share one.

    Parameters
    ----------
    samples : FrictionSamples
    rtol : float
        Relative gap between sorted speeds that starts a new level.

    Returns
    -------
    numpy.ndarray of int (n,)
        Level index, 0 for the slowest; both directions of a speed share a level.
    """
    return speed_levels(samples.velocity, rtol)


def speed_levels(speed: np.ndarray, rtol: float = LEVEL_RTOL) -> np.ndarray:
    """Level index of each ``|speed|`` (0 the slowest): sorted speeds within ``rtol`` of each
    other share one (:func:`level_labels` on bare speeds)."""
    s_abs = np.abs(np.asarray(speed, dtype=float))
    order = np.argsort(s_abs, kind="stable")
    s = s_abs[order]
    new = np.r_[False, s[1:] > s[:-1] * (1.0 + rtol) + 1e-12]
    labels = np.empty(s.size, dtype=int)
    labels[order] = np.cumsum(new)
    return labels


def _repeat_groups(samples: FrictionSamples, rtol: float) -> np.ndarray:
    """Group index of each sample's operating point (level, direction, load, temperature)."""
    keys = np.column_stack(
        [
            level_labels(samples, rtol),
            samples.direction,
            np.round(samples.load, 6),
            np.round(samples.temperature, 1),
        ]
    )
    _, group = np.unique(keys, axis=0, return_inverse=True)
    return group.ravel()


def measurement_scatter(
    samples: FrictionSamples,
    *,
    raw: Sequence[Any] | None = None,
    sem: Any | None = None,
    rtol: float = LEVEL_RTOL,
) -> Scatter:
    """The standard error of the samples' friction, estimated from the data (module docstring).

    Parameters
    ----------
    samples : FrictionSamples
    raw : sequence of array_like, optional
        One array per sample row: the raw steady torque samples [N m] averaged into it, in
        time order.
    sem : array_like (n,), optional
        Standard errors [N m] known otherwise (e.g. ``ExtractionResult.direction_sem``).
    rtol : float
        Relative gap between velocity levels, for finding repeated runs.

    Returns
    -------
    Scatter

    Raises
    ------
    ConfigError
        ``raw`` or ``sem`` of a length other than the number of samples.
    """
    n = len(samples)
    if sem is None and "sem" in samples.meta:
        given = np.asarray(samples.meta["sem"], dtype=float)
        if given.shape == (n,):
            how = samples.meta.get("sem_method")
            if isinstance(how, str) and how:  # the reader or extraction says how
                return _scatter(given, how, str(samples.meta.get("sem_caveat") or ""))
            sem = given
    if sem is not None:
        se = np.asarray(sem, dtype=float)
        if se.shape != (n,):
            raise ConfigError(f"sem needs {n} standard errors, one per sample; got {se.shape}")
        return _scatter(se, "given", "")
    if raw is not None:
        if len(raw) != n:
            raise ConfigError(f"raw needs {n} series, one per sample; got {len(raw)}")
        se = np.array([sem_autocorrelated(x) for x in raw])
        return _scatter(
            se,
            "within-run, autocorrelation-corrected",
            "one run per set-point: offsets between runs are not in it",
        )
    group = _repeat_groups(samples, rtol)
    sizes = np.bincount(group)
    if (sizes > 1).any():
        means = np.bincount(group, weights=samples.y) / sizes
        dof = float(np.sum(sizes - 1))
        s = float(np.sqrt(np.sum((samples.y - means[group]) ** 2) / dof))
        k = int((sizes > 1).sum())
        return _scatter(np.full(n, s), "between repeated runs", f"{k} operating points repeated")
    if (samples.std > 0).any():
        return _scatter(
            samples.std / np.sqrt(samples.count),
            "within-run, std/sqrt(count)",
            "ignores autocorrelation of the raw samples: a lower bound",
        )
    return Scatter(
        float("nan"),
        np.full(n, np.nan),
        "none",
        "the samples have no std, no repeated runs and no raw data",
    )


def _scatter(se: np.ndarray, method: str, caveat: str) -> Scatter:
    ok = np.isfinite(se)
    value = float(np.sqrt(np.mean(se[ok] ** 2))) if ok.any() else float("nan")
    return Scatter(value, se, method, caveat)


#: Choices of ``fit(..., weights=...)`` by name.
WEIGHTS = ("none", "std")


def sample_weights(samples: FrictionSamples, kind: str, scatter: Scatter | None = None):
    """Weights of weighted least squares from the samples' own standard errors.

    Parameters
    ----------
    samples : FrictionSamples
    kind : {"none", "std"}
        ``"std"``: ``w_i = (s / se_i)^2``, ``se_i`` each sample's standard error
        (:func:`measurement_scatter`) and ``s`` their root mean square, so the weights
        average about 1 and weighted residuals stay in N m; ``"none"``: no weights.
    scatter : Scatter, optional
        The scatter to use (default: :func:`measurement_scatter` of ``samples``).

    Returns
    -------
    numpy.ndarray (n,) or None
        None for ``"none"``.

    Raises
    ------
    ConfigError
        An unknown ``kind``, or a sample without a positive standard error (its row named).
    """
    key = str(kind).strip().lower()
    if key not in WEIGHTS:
        raise ConfigError(f"unknown weights '{kind}'; choose one of: {', '.join(WEIGHTS)}")
    if key == "none":
        return None
    sc = scatter if scatter is not None else measurement_scatter(samples)
    se = np.asarray(sc.per_sample, dtype=float)
    bad = np.flatnonzero(~(np.isfinite(se) & (se > 0)))
    if bad.size:
        raise ConfigError(
            f"weights 'std' need a positive standard error for every sample; row {int(bad[0])} "
            f"has {se[bad[0]]!r} (the std column is 0 or missing: use weights 'none')"
        )
    return (sc.value / se) ** 2
