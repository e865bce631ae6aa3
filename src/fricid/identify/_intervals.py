"""What an analytic fit stores for its prediction intervals: the covariance of its free
parameters, the residual variance, and the multiplier calibrated on its leave-one-out
residuals (:mod:`fricid.fitted._interval`, the delta method).

``C = s^2 (J^T J)^+`` with ``J`` the Jacobian of the predictions in the free parameters at
the optimum and ``s^2 = SSE / (n - p)`` of the unweighted residuals (Seber & Wild 1989,
eq. 5.7). The pseudo-inverse (SVD, cut at ``eps max(n, p)`` of the largest singular value of
the column-scaled ``J``, as scipy's ``curve_fit``) leaves out the directions the data do not
determine: a prediction inside the data hardly moves along them, so the interval there stays
finite where a parameter's own standard error is not.

The multiplier (``scale``): ``F(x) -+ k sqrt(g^T C g + s^2)`` with ``k = t(n - p)`` is exact
when the family holds and the noise is Gaussian. Where it does not, ``s^2`` holds what is not
Gaussian noise: a few gross outliers inflate ``s`` for every prediction (two samples 10-20
noise std off gave intervals covering 99.8-100 % of clean samples), and a bounded spread,
such as an offset that varies from run to run, has no tails for ``t s`` to reach into. ``k``
is therefore the normalised (studentised) jackknife quantile of the samples' own prediction
errors (Lei et al. 2018, section 5.2; Barber et al. 2021): the leave-one-out residual
``r_i / (1 - h_ii)`` over its standard deviation ``s / sqrt(1 - h_ii)`` under the same
formula, ``z_i = |r_i| / (s sqrt(1 - h_ii))``, ``h_ii`` the leverages of ``J``. ``k`` is the
order statistic of rank ``(n + 1) level``, interpolated between its neighbours (Hyndman &
Fan 1996, type 6): the ``j``-th smallest of ``n`` exchangeable scores covers ``j / (n + 1)``
of a new one in expectation, so this rank covers ``level`` on average (the conformal
``ceil`` of the rank guarantees at least ``level`` and sits on the largest one or two of 20-40
scores). Gross outliers (``|r_i| / sqrt(1 - h_ii)`` beyond :data:`GROSS` robust standard
deviations, ``1.4826 median``) are left out of the scores, looked for among
:data:`GROSS_MIN` scores or more: the interval is for measurements, not for faults. With too
few scores for the rank (under 19 at 95 %) ``k`` is the Student-t quantile with ``n - p``
degrees of freedom: the largest of a dozen scores, most of them pulled towards zero by a fit
of 3-5 parameters, is no quantile.

The noise term is never below the measured scatter of a sample (``noise_floor``: given
with the samples, or from repeated runs; not the estimate from second differences): the
residuals of 10-30 samples fitted by 2-5 parameters may come out well below the noise by
chance, or because ``auto`` picked the family whose residuals did (``s`` at half the noise
gave 80 % on a tuning case of six speed levels). The noise of a new sample is the scatter;
``s`` above it holds misfit as well, and stays. ``C`` is scaled with it. Where the scatter
sets the noise term and the multiplier is the Student-t fall-back, the multiplier is the
normal quantile: the noise is then known from the raw measurements behind every sample,
not estimated from ``n - p`` residuals.

Where the family misses the law by several times the noise, no multiplier makes an interval
centred on it cover 95 %: at each speed the new sample is the fixed bias plus noise, covered
with probability near 0 or near 1, and the share of speeds covered follows the shape of the
misfit. Such a fit is one the trust verdict refuses; a model that follows the law (the hybrid
model's residual network) is the cure, not a wider or narrower interval.

**Local spread** (``local``, used in place of the above wherever the scatter of a sample is
known, measured or estimated): one width for every speed, scaled by the root mean square of
all the residuals, holds the misfit of the worst speeds everywhere; on 82 tuning cases of
``benchmarks/bench_verdicts.py`` (laws outside fricid's families) the Coulomb-viscous
family's intervals so covered 98-99.6 % of new samples in 9 of 13 classes. The interval is
``F(x) -+ k sqrt(v(x) + (noise / s)^2 g^T C g)``: ``v(x)`` the local mean of the squared
leave-one-out errors ``e_i^2 = r_i^2 / (1 - h_ii)`` near ``x``
(:func:`fricid.models._spread.local_variance`: a kernel average along ``log10 |v|`` and,
where they vary, load and temperature), never below the scatter squared, so the interval is
narrow where the family follows the data and wide where it does not; the parameters' term at
the noise of a sample. ``k`` is the normal quantile, or the normalised jackknife quantile of
the scores ``e_i / sqrt(v_(-i)(x_i))`` (each sample's spread from the others) where that is
smaller: bounded spreads (a run's gravity offset; the bias at repeated runs, which pins it)
have lighter tails than the normal, while a larger quantile comes from the leave-one-out
spread missing a sample's own sharp bias, which the spread at ``x`` does not. On those tuning
cases: 94.1-97.3 % (Coulomb-viscous), 90.0-97.1 % (Stribeck) per class.

**Bias-aware** (an analytic fit's record, ``bias=True``: the signed errors ``e`` stored
beside ``e2``). Where the bias at a speed is many times the noise, ``1.96 sqrt(v)`` is about
twice the bias and covered nearly every new sample: a Lorentzian dip of 20 noise std under
a Coulomb-viscous line, 99.3 % over 8 seeds (``tests/fitted/test_local_spread.py``); on the
verdict benchmark's report cases the Coulomb-viscous family's misfit fits covered 98.3 % in
the unknown-scatter class. The interval is the folded normal's quantile instead
(:func:`fricid.models._spread.biased_half_width`, the critical value of Armstrong and
Kolesar 2020): a new sample ``N(m(x), s(x)^2)``, ``m`` the local mean of the signed errors,
``s^2 = max(v - m^2, noise^2)`` plus the parameters' term; ``z s`` without bias, about
``|m| + 1.645 s`` where it dominates. The dip: 95.3 %. ``k`` is calibrated the same way,
the scores then ``z |e_i| / h_(-i)(x_i)``. On the 82 tuning cases the Coulomb-viscous
family's cells went from 94.1-97.3 % to 92.6-96.3 %, the Stribeck family's 91.5-97.2 % to
91.6-97.9 %; on the report cases the Coulomb-viscous unknown-scatter cell 98.3 -> 96.3 %,
every cell of every model then within 90.6-97.9 % (``benchmarks/results/verdicts.txt``). A
learned model's record keeps the symmetric form: its cross-validation errors carry little
bias, and the bias-aware form moved its tuning cells the wrong way (the hybrid in the
load-temperature class 90.4 -> 89.0 %, the GP's up by as much as 2.7 points).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..fitted._interval import _norm_ppf, gradient
from ..models import get_model
from ..models._spread import (
    BANDWIDTH_DECADES,
    BANDWIDTH_SPAN,
    biased_half_width,
    input_spans,
    local_bias_std,
    spread_points,
)

__all__ = [
    "GROSS",
    "GROSS_MIN",
    "INTERVAL_LEVELS",
    "delta_record",
    "gross_errors",
    "jackknife_scale",
    "local_record",
]

#: Levels at which the calibrated multiplier is stored.
INTERVAL_LEVELS = (0.9, 0.95)

#: A residual beyond this many robust standard deviations is a gross error, not a score.
GROSS = 6.0

#: Gross errors are looked for among this many scores or more (fewer: the median of a
#: handful of residuals, most of them pulled to zero by the fit, is no scale).
GROSS_MIN = 20


def _t_ppf(q: float, dof: int) -> float:
    from scipy import stats

    return float(stats.t.ppf(q, dof))


def gross_errors(e: np.ndarray) -> np.ndarray:
    """The gross errors among the absolute scores ``e``: beyond :data:`GROSS` robust standard
    deviations (``1.4826 median``), looked for among :data:`GROSS_MIN` scores or more."""
    robust = 1.4826 * float(np.median(e)) if e.size else 0.0
    if robust > 0 and e.size >= GROSS_MIN:
        return e > GROSS * robust
    return np.zeros(e.size, bool)


def local_record(
    e: np.ndarray,
    X: np.ndarray,
    noise: float,
    levels=INTERVAL_LEVELS,
    source: str = "leave-one-out errors",
    bias: bool = False,
) -> dict[str, Any] | None:
    """The local spread of the held-out errors ``e`` [N m] of the samples at ``X`` (module
    notes, "Local spread"; :mod:`fricid.models._spread`) and its calibrated multipliers;
    ``noise`` [N m] the measured or estimated scatter of a sample. For an analytic fit
    ``e_i = r_i / sqrt(1 - h_ii)``; a learned model's are its cross-validation errors.
    ``bias``: store the signed errors too (``e``), for the bias-aware interval (module
    notes); an analytic fit's.
    Samples at rest or with a NaN error are left out; None without a positive finite
    ``noise`` or 3 usable samples."""
    signed = np.asarray(e, dtype=float)
    ok = np.isfinite(signed) & (X[:, 0] != 0) & np.isfinite(X[:, 0])
    if not (np.isfinite(noise) and noise > 0) or ok.sum() < 3:
        return None
    gross = gross_errors(np.abs(signed[ok]))
    keep = ~gross
    Xk, ek = X[ok][keep], signed[ok][keep]
    e2 = ek**2
    spans = input_spans(Xk)
    P, e2p, w, point = spread_points(Xk, e2, spans)
    record: dict[str, Any] = {
        "method": f"local spread of the {source} (kernel average)",
        "noise": float(noise),
        "bandwidth": {"decades": BANDWIDTH_DECADES, "span": BANDWIDTH_SPAN},
        "spans": spans,
        "velocity": P[:, 0].tolist(),
        "load": np.nan_to_num(P[:, 1]).tolist(),
        "temperature": np.nan_to_num(P[:, 2]).tolist(),
        "e2": e2p.tolist(),
        "weight": w.tolist(),
    }
    if bias:
        record["e"] = (np.bincount(point, ek, minlength=len(w)) / w).tolist()
    m, sd = local_bias_std(record, P, leave_out_self=True)
    scale, ranked = [], []
    for level in levels:
        gauss = _norm_ppf(0.5 + float(level) / 2)
        half = biased_half_width(m, sd, float(level))[point]
        z = np.sort(gauss * np.sqrt(e2) / half)
        rank = (z.size + 1) * float(level) <= z.size
        ranked.append(rank)
        q = float(np.quantile(z, float(level), method="weibull")) if rank else gauss
        scale.append(min(q, gauss))
    record.update(levels=list(levels), scale=scale, ranked=ranked, gross=int(gross.sum()))
    return record


def jackknife_scale(
    r: np.ndarray, h: np.ndarray, s: float, dof: int, levels=INTERVAL_LEVELS
) -> dict[str, Any] | None:
    """The calibrated multipliers of the delta-method interval (module notes) from the
    residuals ``r``, the leverages ``h`` and the residual standard deviation ``s``; None
    when there is nothing to calibrate on (``s == 0`` or fewer than 3 usable scores)."""
    ok = h < 1 - 1e-9
    if s <= 0 or ok.sum() < 3:
        return None
    e = np.abs(r[ok]) / np.sqrt(1 - h[ok])
    gross = gross_errors(e)
    z = np.sort(e[~gross] / s)
    m = z.size
    if m < 3:
        return None
    scale, student = [], []
    for level in levels:
        ranked = (m + 1) * float(level) <= m
        student.append(not ranked)
        if ranked:
            scale.append(float(np.quantile(z, float(level), method="weibull")))
        else:
            scale.append(_t_ppf(0.5 + level / 2, max(dof, 1)))
    return {
        "levels": list(levels),
        "scale": scale,
        "student_t": student,
        "scores": int(m),
        "gross": int(gross.sum()),
        "method": "normalised jackknife (leave-one-out residuals by leverage)",
    }


def delta_record(
    model_name: str,
    theta: np.ndarray,
    free: Sequence[str],
    X: np.ndarray,
    y: np.ndarray,
    noise_floor: float | None = None,
    scatter: float | None = None,
    shared: np.ndarray | None = None,
) -> dict[str, Any] | None:
    """The model file's ``prediction_interval`` of an analytic fit (module notes), or None
    when there are no spare observations (``n <= p``) or the Jacobian is not finite.

    ``noise_floor`` [N m]: the measured scatter of a sample (given, or from repeated runs),
    stored as ``noise_floor`` (module notes); ``scatter`` [N m]: the scatter the trust
    verdict uses, measured or estimated (from second differences), the noise of the local
    spread (``local``; none without it); ``shared`` ``(p, p)``: the free parameters'
    covariance from an error every sample shares (an arm's identified gravity,
    :mod:`fricid.identify.static.shared_error`), stored as ``shared_covariance`` and added to
    the interval's variance as it is: the residuals never show it, so neither the residual
    variance nor the measured scatter scales it."""
    free = list(free)
    n, p = len(y), len(free)
    if n <= p:
        return None
    r = y - get_model(model_name).predict(theta, X)
    J = gradient(model_name, theta, free, X).T  # (n, p)
    if not (np.isfinite(J).all() and np.isfinite(r).all()):
        return None
    s2 = float(r @ r) / (n - p)
    cov = np.zeros((p, p))
    h = np.zeros(n)
    if p:
        norms = np.linalg.norm(J, axis=0)
        norms[norms == 0] = 1.0
        U, s, VT = np.linalg.svd(J / norms, full_matrices=False)
        keep = s > np.finfo(float).eps * max(n, p) * s[0] if s[0] > 0 else s > np.inf
        cov = s2 * ((VT[keep].T / s[keep] ** 2) @ VT[keep]) / np.outer(norms, norms)
        h = np.sum(U[:, keep] ** 2, axis=1)
    out = {
        "method": "delta",
        "free": free,
        "covariance": (0.5 * (cov + cov.T)).tolist(),
        "noise_std": float(np.sqrt(s2)),
        "dof": n - p,
    }
    scale = jackknife_scale(r, h, float(np.sqrt(s2)), n - p)
    if scale is not None:
        out["scale"] = scale
    if shared is not None and np.shape(shared) == (p, p) and np.isfinite(shared).all():
        out["shared_covariance"] = np.asarray(shared, dtype=float).tolist()
    if noise_floor is not None and np.isfinite(noise_floor) and noise_floor > 0:
        out["noise_floor"] = float(noise_floor)
    noise = noise_floor if "noise_floor" in out else scatter
    ok = h < 1 - 1e-9
    e = np.where(ok, r / np.sqrt(np.where(ok, 1 - h, 1.0)), np.nan)
    local = None if noise is None else local_record(e, X, float(noise), bias=True)
    if local is not None:
        out["local"] = local
    return out
