"""Prediction intervals of a fitted model: where a new measured sample at ``x`` falls, with
probability ``level``, measurement noise included
(:meth:`fricid.fitted.FittedModel.predict_interval`).

Where the file stores the local spread of the fit's held-out errors (``local``,
:mod:`fricid.models._spread`; fits since it was added, wherever the scatter of a sample is
known or estimated), every model's interval is ``F(x) -+ k sqrt(v(x) + p(x))``: ``v`` the
local mean squared held-out error near ``x``, never below the scatter squared, ``p`` an
analytic model's parameter term ``(noise / s)^2 g^T C g`` (a hybrid's backbone's), a GP's
latent posterior variance above its local average at the samples (the held-out errors hold
the process's own error where there are samples; the excess is its growth away from them: in
a gap between measured speeds, or between measured loads and temperatures, where no
held-out error was seen; the whole variance added gave 94.9-97.5 % per class on the 82
tuning cases of ``benchmarks/bench_verdicts.py`` with the GP's noise floor, the excess
91.6-96.6 %), ``k``
the calibrated multiplier (:mod:`fricid.identify._intervals`, "Local spread"): narrow where
the model follows the data, wide where it misses them. An analytic fit's record holds the
signed errors too, and its interval is bias-aware: ``(k / z) h(m(x), s(x))``, ``h`` the
folded normal's quantile of a new sample ``N(m, s^2)`` about the model, ``m`` the local bias
and ``s^2 = max(v - m^2, noise^2) + p`` (:mod:`fricid.identify._intervals`, "Bias-aware";
the same as above without bias, about ``|m| + 1.645 s`` where the bias dominates). An
analytic fit's record is ``prediction_interval`` with method ``"delta"`` and ``local``
beside the delta method's fields; a learned model's has method ``"heldout"``. Otherwise,
one rule per kind of model, each from what the model file stores:

- **analytic** (``prediction_interval`` of the file, method ``"delta"``): the delta method,
  ``F(x) -+ k sqrt(g^T C g + s^2)``, ``g`` the gradient of ``F(x)`` in the free
  parameters (central differences, one batch call), ``C`` their covariance
  ``s^2 (J^T J)^+`` at the optimum and ``s^2`` the residual variance ``SSE / (n - p)``
  (Seber & Wild, *Nonlinear Regression*, 1989, section 5.1, eq. 5.7); ``k`` the multiplier
  calibrated on the fit's own leave-one-out residuals where stored at that level (``scale``,
  :mod:`fricid.identify._intervals`: a family that misses the law, or a few gross outliers,
  no longer give intervals that cover everything), else ``t(dof)``; ``s`` never below
  the measured scatter stored with the fit (``noise_floor``), ``C`` scaled with it; where
  the samples share an error the residuals never show (an arm's identified gravity,
  :mod:`fricid.identify.static.shared_error`), its covariance ``S`` (``shared_covariance``)
  adds ``g^T S g`` unscaled, in this rule and in the local spread's parameter term
  (measured in ``benchmarks/bench_arm_sweeps.py``, column ``PI95``);
- **gp**: the posterior standard deviation of the latent friction with the fitted white noise
  added, ``F(x) -+ k sqrt(std^2 + noise_std^2)`` (Rasmussen & Williams 2006, eq. 2.24 with
  the noise of the observation), ``k`` the held-out multiplier stored with each process
  (``interval_scale``, :func:`fricid.identify.learned._gp_posterior.heldout_scale`), the
  half-width not below the held-out residuals' conformal one stored with it; for processes
  without one (inducing points, older files), ``k`` the normal quantile;
- **rbf**, **hybrid**: the conformal half-widths stored with each network
  (``state["prediction_interval"]``, :func:`fricid.models.rbf.interval_half_width`), at the
  levels stored (0.9, 0.95); a hybrid's with its backbone's ``g^T C g`` added in
  quadrature (the residual's cross-validation holds the backbone).

Inside a gap between measured speeds (``provenance["speeds"]``,
:func:`fricid.models._range.speed_coverage`) the interval is not given (NaN): no residual
was seen there, and a family that bends inside the gap goes unseen (``auto``'s choices on
the verdict benchmark's gapped designs covered 82.9 % there and outside together; the
leave-out error of the gap's two edge speeds, tried as the spread inside, raised it to 85.6
%: a decade without samples hid a Stribeck dip of 5 noise std that the edges never showed).
Outside the operating range (:meth:`fricid.fitted.FittedModel.outside_range`: above or
below the measured speeds, on a side not measured, at other loads or temperatures) none of
these says anything a measurement backs, and none is given either (NaN): a network's
conformal half-width was as narrow at twice the largest measured speed as inside, and missed
the measured friction there.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..models import get_model, get_predictor
from ..models._range import in_gap
from ..models._spread import biased_half_width, local_bias_std, local_variance
from ..models.gp import gp_sides
from ..models.rbf import interval_half_width

__all__ = [
    "PredictionInterval",
    "analytic_half_width",
    "gradient",
    "no_steady_interval",
    "prediction_interval",
]


def _t_ppf(q: float, dof: int) -> float:
    from scipy import stats  # on first use: `fricid predict` starts without scipy.stats

    return float(stats.t.ppf(q, dof))


def _norm_ppf(q: float) -> float:
    from scipy import stats

    return float(stats.norm.ppf(q))


@dataclass(frozen=True)
class PredictionInterval:
    """Friction and its prediction interval at each input row.

    Attributes
    ----------
    friction, low, high : ndarray (n,)
        The prediction [N m] and the interval's ends [N m]; NaN ends at rest (``v = 0``: the
        friction is whatever holds the joint, up to break-away) and inside a gap between
        measured speeds (module notes).
    level : float
        The nominal coverage (0.95: 95 % of new samples inside).
    method : str
        How the interval was made (``"delta"``, ``"heldout"``, ``"gp"``, ``"conformal"``).
    """

    friction: np.ndarray
    low: np.ndarray
    high: np.ndarray
    level: float
    method: str

    @property
    def half_width(self) -> np.ndarray:
        """Half the interval's width [N m]."""
        return 0.5 * (self.high - self.low)


def gradient(model_name: str, theta: np.ndarray, free, X: np.ndarray) -> np.ndarray:
    """``dF(x)/dtheta_j`` ``(p, n)`` of an analytic model at ``theta`` for the parameters
    named in ``free``, by central differences in one batch call."""
    model = get_model(model_name)
    idx = np.array([model.param_names.index(n) for n in free], dtype=int)
    p = idx.size
    if not p:
        return np.zeros((0, len(X)))
    h = 1e-6 * np.maximum(np.abs(theta[idx]), 1e-3)
    steps = np.repeat(np.asarray(theta, dtype=float)[None, :], 2 * p, axis=0)
    steps[np.arange(p), idx] += h
    steps[p + np.arange(p), idx] -= h
    F = np.atleast_2d(model.predict(steps, X))
    return (F[:p] - F[p:]) / (2 * h[:, None])


def analytic_half_width(
    model_name: str, theta: np.ndarray, record: Mapping[str, Any], X: np.ndarray, level: float
) -> np.ndarray:
    """Half-width of the delta-method interval of an analytic model (module notes) at ``X``.

    ``record`` is the model file's ``prediction_interval``: ``free`` (the names of the free
    parameters), ``covariance`` of those, ``noise_std`` and ``dof``.
    """
    G = gradient(model_name, theta, record["free"], X)
    C = np.asarray(record["covariance"], dtype=float)
    s = float(record["noise_std"])
    shared = _shared_variance(record, G)
    local = record.get("local")
    if isinstance(local, Mapping):
        check_local(local)
        grow = (float(local["noise"]) / s) ** 2 if s > 0 else 1.0
        extra = grow * np.einsum("pn,pq,qn->n", G, C, G) + shared
        return _local_half_width(local, X, level, extra)
    floor = record.get("noise_floor")
    known = isinstance(floor, int | float) and floor > s
    noise = float(floor) if known else s
    grow = (noise / s) ** 2 if s > 0 else 1.0
    var = grow * np.einsum("pn,pq,qn->n", G, C, G) + shared + noise**2
    return _delta_multiplier(record, level, known) * np.sqrt(np.maximum(var, 0.0))


def _shared_variance(record: Mapping[str, Any], G: np.ndarray) -> np.ndarray | float:
    """``g^T S g`` [N^2 m^2] at each column of ``G`` (p, n), ``S`` the record's
    ``shared_covariance`` (an error every sample of the fit shares, such as an arm's
    identified gravity: not in the residuals, so added as it is, not scaled with the noise);
    0 without one. A malformed one (a model file from elsewhere) raises ConfigError."""
    raw = record.get("shared_covariance")
    if raw is None:
        return 0.0
    p = G.shape[0]
    try:
        S = np.asarray(raw, dtype=float)
    except (TypeError, ValueError) as err:
        raise ConfigError(f"the model file's shared_covariance is malformed ({err})") from None
    if S.shape != (p, p) or not np.isfinite(S).all():
        raise ConfigError(
            f"the model file's shared_covariance must be a finite {p} x {p} matrix (one row "
            "and column per free parameter)"
        )
    scale = float(np.max(np.abs(S), initial=0.0))
    if not np.allclose(S, S.T, rtol=0.0, atol=1e-9 * scale) or (
        p and float(np.linalg.eigvalsh(0.5 * (S + S.T))[0]) < -1e-9 * scale
    ):
        raise ConfigError(
            "the model file's shared_covariance is not a covariance (symmetric and positive "
            "semi-definite)"
        )
    return np.maximum(np.einsum("pn,pq,qn->n", G, S, G), 0.0)


def _local_half_width(
    local: Mapping[str, Any], X: np.ndarray, level: float, extra: np.ndarray | float = 0.0
) -> np.ndarray:
    """``(k / z) h(m(x), s(x))``: ``h`` the half-width that holds ``level`` of a new sample
    ``N(m, s^2)`` (:func:`fricid.models._spread.biased_half_width`; ``z s`` where ``m = 0``,
    so ``k sqrt(v(x) + extra)`` for a record without signed errors), ``m`` the local bias and
    ``s^2 = max(v - m^2, noise^2) + extra`` (:func:`fricid.models._spread.local_bias_std`),
    ``extra`` [N^2 m^2] the model's own uncertainty at ``x`` (an analytic model's parameter
    term, a GP's latent posterior variance); ``k`` the multiplier calibrated at ``level``
    (:func:`fricid.identify._intervals.local_record`), else the normal quantile ``z``.

    Where the bias dominates, ``h`` grows with the level by the one-sided quantile only, and
    a 0.95 multiplier calibrated below the normal one (light tails) under a 0.9 one at it
    gave a narrower 95 % interval. With a bias the widths at the calibrated levels are
    therefore taken non-decreasing (each at least the one below), linear in the reference
    quantile between them, and above the last never below it; without a bias this is the
    rule of :func:`nested_multiplier`."""
    check_local(local)
    m, sd = local_bias_std(local, X, extra)
    pairs = sorted(
        (float(lv), float(k))
        for lv, k in zip(local.get("levels") or (), local.get("scale") or (), strict=False)
        if 0 < float(lv) < 1
    )
    z = lambda q: _norm_ppf(0.5 + q / 2)  # noqa: E731
    if "e" not in local or not pairs:  # m = 0: h = z s
        k = nested_multiplier([p[0] for p in pairs], [p[1] for p in pairs], level, z)
        return k * sd
    at = [p[0] for p in pairs]
    ks = np.maximum.accumulate([max(p[1], 0.0) for p in pairs])
    H = np.maximum.accumulate(
        [k / z(c) * biased_half_width(m, sd, c) for c, k in zip(at, ks, strict=True)], axis=0
    )
    hit = [j for j, c in enumerate(at) if abs(c - level) < 1e-9]
    if hit:
        return H[hit[0]]
    if level < at[0]:
        return ks[0] / z(at[0]) * biased_half_width(m, sd, level)
    if level > at[-1]:
        return np.maximum(ks[-1] / z(at[-1]) * biased_half_width(m, sd, level), H[-1])
    j = int(np.searchsorted(at, level))  # at[j - 1] < level < at[j]: linear in the reference
    t = (z(level) - z(at[j - 1])) / (z(at[j]) - z(at[j - 1]))
    return H[j - 1] + t * (H[j] - H[j - 1])


def nested_multiplier(levels: list[float], scale: list[float], level: float, base) -> float:
    """The multiplier at ``level`` from those calibrated at ``levels`` (``scale``), so that
    a higher level never gives a narrower interval: at a calibrated level its own; below or
    above them the reference quantile ``base(level)`` (normal, or Student-t) times the
    calibrated multiplier's ratio to it at the nearest; between two, linear in the reference
    quantile; ``base(level)`` without a calibration. The calibrated multipliers are taken
    non-decreasing in level."""
    pairs = sorted((lv, k) for lv, k in zip(levels, scale, strict=False) if 0 < lv < 1)
    if not pairs:
        return float(base(level))
    at = np.array([p[0] for p in pairs])
    ks = np.maximum.accumulate(np.array([max(p[1], 0.0) for p in pairs]))
    hit = np.flatnonzero(np.abs(at - level) < 1e-9)
    if hit.size:
        return float(ks[hit[0]])
    ref = np.array([base(lv) for lv in at])
    b = float(base(level))
    if level < at[0]:
        return b * float(ks[0] / ref[0])
    if level > at[-1]:
        return b * float(ks[-1] / ref[-1])
    j = int(np.searchsorted(at, level))  # at[j - 1] < level < at[j]: linear in the reference
    t = (b - ref[j - 1]) / (ref[j] - ref[j - 1])
    return float(ks[j - 1] + t * (ks[j] - ks[j - 1]))


def check_local(local: Mapping[str, Any]) -> None:
    """Raise :class:`~fricid.errors.ConfigError` unless ``local`` is a well-formed local
    spread (a model file from elsewhere: equal lengths, finite numbers, positive weights,
    bandwidths, noise and multipliers, one multiplier per level)."""
    try:
        cols = [np.asarray(local[k], dtype=float) for k in _LOCAL_COLUMNS]
        n = len(cols[0])
        bw = local["bandwidth"]
        spans = list(local["spans"])
        fine = (
            n > 0
            and all(c.ndim == 1 and len(c) == n and np.isfinite(c).all() for c in cols)
            and (cols[3] >= 0).all()
            and (cols[4] > 0).all()
            and len(spans) == 2
            and all(sp is None or (len(sp) == 2 and float(sp[1]) > float(sp[0])) for sp in spans)
            and float(bw["decades"]) > 0
            and float(bw["span"]) > 0
            and float(local["noise"]) > 0
            and np.isfinite([float(bw["decades"]), float(bw["span"]), float(local["noise"])]).all()
        )
        if "e" in local:  # the signed errors of an analytic fit (its local bias)
            bias = np.asarray(local["e"], dtype=float)
            fine = fine and bias.shape == (n,) and bool(np.isfinite(bias).all())
        levels = np.asarray(local.get("levels") or [], dtype=float)
        scale = np.asarray(local.get("scale") or [], dtype=float)
        fine = fine and levels.shape == scale.shape and levels.ndim == 1
        fine = fine and bool(np.isfinite(scale).all() and (scale > 0).all())
    except (KeyError, TypeError, ValueError) as err:
        raise ConfigError(f"the model file's local interval record is malformed ({err})") from None
    if not fine:
        raise ConfigError(
            "the model file's local interval record is malformed (lengths, non-finite or "
            "non-positive values)"
        )


#: The arrays of a local spread record, in :func:`check_local`'s order.
_LOCAL_COLUMNS = ("velocity", "load", "temperature", "e2", "weight")


def _delta_multiplier(record: Mapping[str, Any], level: float, known: bool = False) -> float:
    """The multiplier of the delta method's standard deviation at ``level``: the jackknife
    calibration stored with the fit (``scale``) where stored at that level, else the
    Student-t quantile with the fit's residual degrees of freedom; the normal quantile in
    place of the Student-t one where the measured scatter sets the noise (``known``)."""
    dof = max(int(record["dof"]), 1)

    def base(q: float) -> float:
        return _norm_ppf(0.5 + q / 2) if known else _t_ppf(0.5 + q / 2, dof)

    cal = record.get("scale")
    if not isinstance(cal, Mapping):
        return base(level)
    levels = [float(x) for x in cal.get("levels") or ()]
    scale = [float(x) for x in cal.get("scale") or ()]
    student = list(cal.get("student_t") or ())
    # a Student-t fall-back stored where the measured scatter sets the noise: the normal one
    scale = [
        base(lv) if known and j < len(student) and student[j] else k
        for j, (lv, k) in enumerate(zip(levels, scale, strict=False))
    ]
    return nested_multiplier(levels[: len(scale)], scale, level, base)


def _gp_scale(st: Mapping[str, Any], level: float) -> tuple[float, float]:
    """The multiplier of a process's predictive standard deviation at ``level`` and the
    least half-width [N m]: its held-out calibration (``interval_scale``) where stored at
    that level, else the normal quantile and 0."""
    cal = st.get("interval_scale")
    if isinstance(cal, Mapping):
        levels = [float(x) for x in cal.get("levels") or ()]
        hits = [j for j, lv in enumerate(levels) if abs(lv - level) < 1e-9]
        scale, least = list(cal.get("scale") or ()), list(cal.get("half_width") or ())
        if hits and hits[0] < min(len(scale), len(least)):
            return max(float(scale[hits[0]]), 0.0), max(float(least[hits[0]]), 0.0)
    return float(_norm_ppf(0.5 + level / 2)), 0.0


def _gp_half_width(state: Mapping[str, Any], std: np.ndarray, X: np.ndarray, level: float):
    v = X[:, 0]
    half = np.zeros(len(X))
    for side, st in gp_sides(state).items():
        mask = {"all": v != 0, "pos": v > 0, "neg": v < 0}[side]
        noise = float(st.get("noise_std", 0.0))
        k, least = _gp_scale(st, level)
        half[mask] = np.maximum(k * np.sqrt(std[mask] ** 2 + noise**2), least)
    return half


def _backbone_gcg(state: Mapping[str, Any], X: np.ndarray):
    """A hybrid backbone's ``g^T C g`` [N^2 m^2] at ``X`` and its delta record, or None
    without a record."""
    bb = state.get("backbone") if isinstance(state, Mapping) else None
    record = bb.get("prediction_interval") if isinstance(bb, Mapping) else None
    if not isinstance(record, Mapping) or record.get("method") != "delta":
        return None
    model = get_model(str(bb["model"]))
    G = gradient(model.name, model.param_vector(dict(bb["params"])), record["free"], X)
    var = np.einsum("pn,pq,qn->n", G, np.asarray(record["covariance"], dtype=float), G)
    return np.maximum(var, 0.0), record


def _backbone_variance(
    state: Mapping[str, Any], X: np.ndarray, local: Mapping[str, Any]
) -> np.ndarray | float:
    """A hybrid's backbone term ``(noise / s)^2 g^T C g`` [N^2 m^2] beside the local spread
    of its residual network's cross-validation errors (which hold the backbone fixed): the
    backbone's covariance ``C`` holds its own residual variance ``s^2``, the misfit that the
    network takes up included, and is scaled to the noise of a sample as an analytic fit's
    (:func:`analytic_half_width`); 0 without a backbone record."""
    got = _backbone_gcg(state, X)
    if got is None:
        return 0.0
    check_local(local)
    var, record = got
    s = float(record["noise_std"])
    return ((float(local["noise"]) / s) ** 2 if s > 0 else 1.0) * var


def _with_backbone(state: Mapping[str, Any], X: np.ndarray, half: np.ndarray, level: float):
    """A hybrid's conformal half-width with its backbone's parameter uncertainty added in
    quadrature (:mod:`fricid.identify.learned.hybrid` notes); as it is without a record."""
    got = _backbone_gcg(state, X)
    if got is None:
        return half
    var, record = got
    q = _t_ppf(0.5 + level / 2, max(int(record["dof"]), 1))
    return np.sqrt(half**2 + q**2 * var)


def _excess_latent_variance(
    fitted, local: Mapping[str, Any], var: np.ndarray, X: np.ndarray
) -> np.ndarray:
    """A GP's latent posterior variance at ``X`` above its local average at the samples
    [N^2 m^2]: the held-out errors of the local spread already hold the process's own error
    where there are samples; what it adds is the growth away from them (in a gap, between
    measured loads and temperatures)."""
    check_local(local)
    P = np.column_stack(
        [np.asarray(local[k], dtype=float) for k in ("velocity", "load", "temperature")]
    )
    _, at = fitted.predict(P, warn=False, return_std=True)
    near = local_variance({**local, "e2": np.asarray(at, dtype=float) ** 2}, X)
    return np.maximum(var - np.where(np.isfinite(near), near, 0.0), 0.0)


def no_steady_interval(fitted) -> str:
    """Why a model identified from a trajectory gives no prediction interval of steady
    friction (``"was identified from a trajectory: ..."``), or ``""`` when it is not such a
    model or stores one."""
    record = fitted.prediction_interval
    stored = isinstance(record, Mapping) and record.get("method") in ("heldout", "delta")
    if (
        stored
        or not (fitted.provenance or {}).get("trajectory")
        or fitted.model == "gp"
        or get_predictor(fitted.model).stateful
    ):
        return ""
    return (
        "was identified from a trajectory: its torque is predicted along a motion (fricid "
        "report), and it gives no prediction interval of steady friction"
    )


def prediction_interval(fitted, X, level: float = 0.95) -> PredictionInterval:
    """The interval of ``fitted`` (a :class:`~fricid.fitted.FittedModel`) at ``X (n, 3)``;
    see :meth:`fricid.fitted.FittedModel.predict_interval`."""
    level = float(level)
    if not 0.0 < level < 1.0:
        raise ConfigError(f"the interval's level must lie in (0, 1); got {level!r}")
    X = np.asarray(X, dtype=float)
    record = fitted.prediction_interval
    if isinstance(record, Mapping) and record.get("method") == "heldout":
        extra = 0.0
        local = record.get("local") or {}
        if fitted.model == "gp":  # its latent variance beyond the samples': away from the data
            F, std = fitted.predict(X, warn=False, return_std=True)
            extra = _excess_latent_variance(fitted, local, np.asarray(std, dtype=float) ** 2, X)
        else:
            F = fitted.predict(X, warn=False)
        if fitted.model == "hybrid":  # the backbone's parameter term, at the noise of a sample
            extra = _backbone_variance(fitted.state, X, local)
        half = _local_half_width(local, X, level, extra)
        method = "heldout"
    elif fitted.model == "gp":
        F, std = fitted.predict(X, warn=False, return_std=True)
        half, method = _gp_half_width(fitted.state, std, X, level), "gp"
    elif get_predictor(fitted.model).stateful:
        F = fitted.predict(X, warn=False)
        half, method = interval_half_width(fitted.state, X, level), "conformal"
        if np.isnan(half[X[:, 0] != 0]).any():
            raise ConfigError(
                f"model '{fitted.model}' stores no prediction interval at level {level:g} "
                "(the levels stored are 0.9 and 0.95; files before they were stored have none)"
            )
        half = np.nan_to_num(half)
        if fitted.model == "hybrid":
            half = _with_backbone(fitted.state, X, half, level)
    else:
        if not isinstance(record, Mapping) or record.get("method") != "delta":
            if why := no_steady_interval(fitted):
                raise ConfigError(f"model '{fitted.model}' {why}")
            stats = fitted.statistics or {}
            n, p = stats.get("ndata"), stats.get("nvarys")
            if isinstance(n, int | float) and isinstance(p, int | float) and n <= p:
                raise ConfigError(
                    f"model '{fitted.model}' stores no prediction interval: its {n:g} "
                    f"samples for {p:g} free parameters leave no residual to measure the "
                    "scatter by (measure more speeds, or fit a family with fewer parameters)"
                )
            raise ConfigError(
                f"model '{fitted.model}' stores no prediction interval (fit it again with "
                "this fricid to get one)"
            )
        F = fitted.predict(X, warn=False)
        half, method = analytic_half_width(fitted.model, fitted.theta(), record, X, level), "delta"
    # at rest the friction is whatever holds the joint, up to break-away: no interval; nor
    # inside a gap between measured speeds or outside the operating range, where nothing
    # measured backs one
    rest = X[:, 0] == 0
    gap = in_gap(X[:, 0], (fitted.provenance or {}).get("speeds"))
    half = np.where(rest | gap | fitted.outside_range(X), np.nan, half)
    return PredictionInterval(F, F - half, F + half, level, method)
