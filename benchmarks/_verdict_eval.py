"""One case of the verdict-calibration benchmark through fricid's public API, scored against
the noiseless truth (``bench_verdicts.py``; the cases are :mod:`_verdict_cases`).

For a model on a case: ``fricid.identify.fit`` (the samples as given), then
``fricid.identify.trust.assess_trust`` (the one verdict, as ``fricid fit`` and the fleet
compute it, leave-one-velocity-out run there when the fit holds no validation), and against
the truth on the dense grid of :func:`_verdict_cases.truth_grid`:

true ratio (the verdict's counterpart, "the true held-out ratio against the noiseless truth")
    ``sqrt(mean_grid (F_hat - F)^2 + mean_grid sigma^2) / sqrt(mean_grid sigma^2)``: the
    root mean square of (prediction - a fresh noisy sample) over the grid, in expectation,
    divided by the root mean square of the true noise std; computed exactly from the
    noiseless truth ``F`` and the true ``sigma`` (no draw), so 1.0 is a perfect model. It is
    on the scale of fricid's held-out ratio (held-out RMSE over the measurement scatter),
    which a perfect model also brings to about 1.
model ratio
    ``sqrt(mean_grid (F_hat - F)^2) / sqrt(mean_grid sigma^2)``: the model's own error over
    the noise (0 for a perfect model); kept in the JSON beside the true ratio.
coverage
    The expected coverage of the model's 95 % prediction interval ``[lo, hi]`` of a fresh
    sample of the case's measurement process at each grid point, averaged over the grid
    (exact, no draw), over the grid points where the model gives one (fricid gives none
    inside a gap between measured speeds: ``withheld`` is the share of the grid without);
    None when the fitted model exposes no interval (:func:`prediction_interval`). The fresh
    sample is ``F + sigma z``, coverage
    ``Phi((hi - F)/sigma) - Phi((lo - F)/sigma)``; in the gravity class it is ``F + a sin(phi)
    + sigma z``, ``phi`` uniform in (-pi/2, pi/2) as every sample of the case was drawn
    (``spec["gravity_amp"]``), the coverage averaged over ``phi`` by the midpoint rule. A
    prediction interval is a statement about new measurements of the process the samples
    come from; the samples carry no position, so no model of them can tell the offset from
    noise, and measured against ``F + sigma z`` alone every honest interval over-covers.
    The true ratio stays against ``F`` (friction, the offset excluded).
"""

from __future__ import annotations

import inspect
import time
import warnings
from typing import Any

import numpy as np
from scipy.stats import norm

from fricid.errors import FricidError
from fricid.identify import fit
from fricid.identify.trust import assess_trust

__all__ = ["LEVEL", "prediction_interval", "run_model", "true_scores"]

#: The prediction intervals' level.
LEVEL = 0.95


def _split(out: Any, mean: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """``(lo, hi)`` from what an interval API returned: ``(lo, hi)``, ``(mean, lo, hi)``,
    ``(mean, (lo, hi))``, an ``(n, 2)`` array, a mapping with ``low``/``high`` (or
    ``lo``/``hi``, ``lower``/``upper``), an object with such attributes, or a half-width."""
    n = mean.shape[0]
    if isinstance(out, dict):
        for a, b in (("low", "high"), ("lo", "hi"), ("lower", "upper")):
            if a in out and b in out:
                return np.asarray(out[a], float), np.asarray(out[b], float)
        return None
    for a, b in (("low", "high"), ("lo", "hi"), ("lower", "upper")):
        if hasattr(out, a) and hasattr(out, b):
            return np.asarray(getattr(out, a), float), np.asarray(getattr(out, b), float)
    if isinstance(out, tuple | list):
        parts = [p for p in out if p is not None]
        if len(parts) == 3:
            return np.asarray(parts[1], float), np.asarray(parts[2], float)
        if len(parts) == 2:
            second = parts[1]
            if isinstance(second, tuple | list) or np.ndim(second) == 2:
                return _split(second, mean)
            a, b = np.asarray(parts[0], float), np.asarray(second, float)
            if a.shape == b.shape == (n,) and np.all(b >= a - 1e-12) and not np.allclose(a, mean):
                return a, b
            if b.shape == (n,):  # (mean, half-width)
                return mean - b, mean + b
        return None
    arr = np.asarray(out, float)
    if arr.shape == (n, 2):
        return arr[:, 0], arr[:, 1]
    if arr.shape == (2, n):
        return arr[0], arr[1]
    if arr.shape == (n,):
        return mean - arr, mean + arr
    return None


def _try(call, mean: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out = _split(call(), mean)
    except (FricidError, TypeError, ValueError, KeyError, NotImplementedError):
        return None
    if out is None:
        return None
    lo, hi = out
    # NaN ends where the model withholds its interval (gaps); infinite ends are no interval
    if np.isinf(lo).any() or np.isinf(hi).any() or not (np.isfinite(lo) & np.isfinite(hi)).any():
        return None
    return out


def prediction_interval(
    fitted: Any, X: np.ndarray, level: float = LEVEL
) -> tuple[tuple[np.ndarray, np.ndarray], str] | None:
    """The fitted model's ``level`` prediction interval at ``X`` and where it came from, or
    None when it exposes none.

    Tried in order, so an interval API added to ``FittedModel`` is picked up without a change
    here: a method ``predict_interval`` / ``prediction_interval`` / ``interval``
    (``(X, level=...)``); ``predict`` with a keyword ``interval``, ``level``,
    ``return_interval`` or ``alpha``; the stored conformal half-width of the RBF network and
    the hybrid (:func:`fricid.models.rbf.interval_half_width`); the GP's posterior standard
    deviation plus its fitted white noise (``noise_std`` of the state), Gaussian.
    """
    X = np.asarray(X, float)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mean = np.asarray(fitted.predict(X, warn=False), float)
    for name in ("predict_interval", "prediction_interval", "interval"):
        method = getattr(fitted, name, None)
        if callable(method):
            got = _try(lambda m=method: m(X, level=level), mean)
            if got is not None:
                return got, name
    params = inspect.signature(fitted.predict).parameters
    for key, value in (
        ("interval", level),
        ("level", level),
        ("return_interval", True),
        ("alpha", 1 - level),
    ):
        if key in params:
            kw = {key: value, "warn": False}
            if key == "return_interval" and "level" in params:
                kw["level"] = level
            got = _try(lambda kw=kw: fitted.predict(X, **kw), mean)
            if got is not None:
                return got, f"predict({key}=)"
    if fitted.model == "gp":
        return _gp_interval(fitted, X, mean, level)
    if fitted.kind == "rbf":
        from fricid.models.rbf import interval_half_width

        got = _try(lambda: interval_half_width(fitted.state, X, level), mean)
        if got is not None:
            return got, "conformal half-width"
    return None


def _gp_interval(fitted, X, mean, level):
    """The GP's latent posterior std with its fitted noise added, Gaussian."""
    try:
        _, sd = fitted.predict(X, warn=False, return_std=True)
    except (FricidError, TypeError, ValueError):
        return None
    state = fitted.state or {}
    noise = np.zeros(X.shape[0])
    for side, mask in (
        ("all", np.ones(X.shape[0], bool)),
        ("pos", X[:, 0] > 0),
        ("neg", X[:, 0] < 0),
    ):
        st = state if side == "all" else state.get(side)
        if isinstance(st, dict) and st.get("noise_std") is not None:
            noise[mask] = float(st["noise_std"])
    z = norm.ppf(0.5 + level / 2)
    half = z * np.sqrt(np.asarray(sd, float) ** 2 + noise**2)
    return (mean - half, mean + half), "gp std + noise_std"


def _coverage(lo, hi, truth, sigma, offset_amp: float = 0.0, nodes: int = 256) -> np.ndarray:
    """Expected coverage of ``[lo, hi]`` at each point (module notes, "coverage")."""
    if offset_amp <= 0:
        return norm.cdf((hi - truth) / sigma) - norm.cdf((lo - truth) / sigma)
    phi = -np.pi / 2 + np.pi * (np.arange(nodes) + 0.5) / nodes
    centre = truth[None, :] + offset_amp * np.sin(phi)[:, None]
    cov = norm.cdf((hi - centre) / sigma) - norm.cdf((lo - centre) / sigma)
    return cov.mean(axis=0)


def true_scores(
    pred: np.ndarray,
    truth: np.ndarray,
    sigma: np.ndarray,
    band: tuple | None,
    offset_amp: float = 0.0,
) -> dict[str, Any]:
    """True ratio, model ratio and coverage (module notes); ``offset_amp`` the amplitude of
    the gravity offset a fresh sample carries (0: none)."""
    mse = float(np.mean((pred - truth) ** 2))
    s2 = float(np.mean(sigma**2))
    out: dict[str, Any] = {
        "true_ratio": float(np.sqrt((mse + s2) / s2)),
        "model_ratio": float(np.sqrt(mse / s2)),
        "coverage": None,
    }
    if band is not None:
        lo, hi = (np.asarray(b, dtype=float) for b in band)
        given = np.isfinite(lo) & np.isfinite(hi)
        out["withheld"] = float(1.0 - np.mean(given))
        if given.any():
            cov = _coverage(lo[given], hi[given], truth[given], sigma[given], offset_amp)
            out["coverage"] = float(np.mean(cov))
    return out


def run_model(case: Any, model: str, grid: np.ndarray) -> dict[str, Any]:
    """Fit ``model`` to ``case.samples``, assess trust, score against the truth.

    Returns a JSON-ready row: case, class, model asked and chosen, the trust level (``yes``,
    ``with caveats``, ``no``, or ``error`` when fit raised a ``FricidError``), fricid's ratio
    and its source, scatter, the true scores (:func:`true_scores`), the interval's source and
    the seconds taken (wall and CPU: the machine may be shared).
    """
    t0, c0 = time.perf_counter(), time.process_time()
    row: dict[str, Any] = {"case": case.id, "class": case.klass, "model": model}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fitted = fit(case.samples, model)
            trust = assess_trust(fitted, case.samples)
    except FricidError as err:
        row.update(level="error", error=f"{type(err).__name__}: {str(err)[:200]}")
        row["seconds"] = time.perf_counter() - t0
        row["cpu_seconds"] = time.process_time() - c0
        return row
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pred = np.asarray(fitted.predict(grid, warn=False), float)
    truth = case.law(grid[:, 0], grid[:, 1], grid[:, 2])
    sigma = case.sigma(grid[:, 0], grid[:, 1], grid[:, 2])
    got = prediction_interval(fitted, grid)
    row.update(
        chosen=fitted.model,
        level=trust.level,
        fricid_ratio=float(trust.heldout_ratio) if np.isfinite(trust.heldout_ratio) else None,
        source=trust.heldout_source,
        scatter=float(trust.scatter) if np.isfinite(trust.scatter) else None,
        true_sigma=float(np.sqrt(np.mean(sigma**2))),
        interval=None if got is None else got[1],
        reasons=trust.reasons[:3],
        **true_scores(
            pred,
            truth,
            sigma,
            None if got is None else got[0],
            float(case.spec.get("gravity_amp", 0.0)),
        ),
    )
    row["seconds"] = time.perf_counter() - t0
    row["cpu_seconds"] = time.process_time() - c0
    return row
