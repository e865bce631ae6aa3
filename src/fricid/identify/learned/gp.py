"""Training the Gaussian-process friction model (:mod:`fricid.models.gp`) with scikit-learn.

:func:`fit_gp` (also ``fricid.identify.fit(samples, "gp")``) learns, per direction of motion
where the samples have both, ``g(|v|, load, T)`` with ``F = sign(v) g``:

1. the inputs: |v| warped by ``asinh(|v| / velocity_scale)`` with ``velocity_scale`` the
   slowest measured speed (speeds spread as by log |v| above it, zero maps to zero), |load|
   (friction grows with the magnitude of the load, [B] eq. 3-4) and temperature as
   measured; an input with a single value in the data is left out (noted in
   ``state["dropped_inputs"]``); all standardised (mean 0, standard deviation 1);
2. the prior mean: ``c_0 + c_v |v| + c_l |load| + c_T T + c_vT |v| T`` by least squares
   (Coulomb-viscous with linear load and temperature terms, what the model returns to far
   from the data), |load| and T held to their measured range (``mean_bounds``), so that the
   mean stays bounded outside it (:mod:`fricid.models.gp`);
3. the kernel: scikit-learn's ``ConstantKernel * RBF(length_scale per input) + WhiteKernel``
   (ARD squared exponential plus white noise), its hyperparameters by maximum marginal
   likelihood (``GaussianProcessRegressor``, L-BFGS-B with ``n_restarts`` random restarts
   seeded by ``seed``) on the residuals of the mean, scaled to unit standard deviation; the
   white noise never below the measured scatter of a sample (given, between repeated runs,
   or the within-run std/sqrt(count), itself a lower bound; ``state["noise_floor"]``; none
   where the scatter is only estimated from the data). Without it a sample 15 noise std off
   was followed by a process whose white noise fell to 1e-3 of the scatter, and in a gap the
   posterior that interpolated every sample covered 60 % of new samples (tuning case 264 of
   ``benchmarks/bench_verdicts.py``, true held-out ratio 2.4; with the floor 93 % and
   1.44; over the 82 tuning cases the median true ratio fell from 1.68 to
   1.38 in the gaps class, 2.93 to 2.55 with gross outliers);
4. the posterior, with the mean's coefficients estimated with it (R&W section 2.7: their
   uncertainty widens the band where the model extrapolates; the correction to the
   least-squares coefficients has the prior N(0, I) on the standardised basis, eq. 2.42 with
   ``b = 0``, ``B = I``: a regularised mean, so that inputs that hardly vary, such as a
   temperature drifting by a few tenths of a degree, neither make ``H K^-1 H^T`` singular
   nor give coefficients of thousands that cancel inside the data): exact (R&W eq. 2.25-2.26) on all
   samples up to ``max_points``; above that, the hyperparameters are fitted on an inducing subset
   of ``max_points`` samples chosen by farthest-point sampling in the standardised input space
   (deterministic, starting from the sample farthest from the mean: it covers the measured
   region, edges first, as a grid would), and the posterior uses every sample through the
   deterministic training conditional on that subset (Quinonero-Candela & Rasmussen 2005,
   DTC), so prediction is a kernel sum over at most ``max_points`` stored points;
5. gross errors: a process whose held-out errors (leave-one-out at the fitted
   hyperparameters) hold gross ones (beyond :data:`fricid.identify._intervals.GROSS` robust
   standard deviations, looked for among 20 samples or more) is trained again without them,
   and they are recorded (``state["left_out"]``) and named by the trust verdict, as a robust
   analytic fit's down-weighted samples are (30 speeds a direction, one sample 15 noise std
   off on each: the process's error 0.89 -> 0.40 noise std; ``tests/identify/learned/
   test_gp_robust.py``).

The hyperparameters are not chosen by the cross-validation over whole speed levels that the RBF
networks' structure search uses (:mod:`fricid.identify.learned._rbf_folds`): scoring them by
held-out levels would refit the GP per fold for each of the optimiser's dozens of candidate
hyperparameters, where the marginal likelihood needs one factorisation each. The trust
verdict's leave-one-velocity-out (:mod:`fricid.identify._heldout`) refits them in every fold:
holding them at the full fit's values would be cheaper (R&W section 5.4.2), but the held-out
level's own targets would then have chosen the length scales that predict it, the optimism the
level folds are there to remove.

The state holds the points, the weights and the matrix of the posterior variance, so the
predictive standard deviation travels with the model file (``FittedModel.predict(X,
return_std=True)``). The model file records the marginal-likelihood optimiser's own status
and evaluations (``state["optimizer"]``, the ``convergence`` block) and the effective degrees
of freedom, the trace of the posterior mean's smoother (``state["edf"]``; the fit statistics
count them, :mod:`fricid.identify.learned._trust`).
"""

from __future__ import annotations

import time
import warnings
from typing import Any

import numpy as np
import scipy.optimize
from sklearn.exceptions import ConvergenceWarning as SklearnConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel
from threadpoolctl import threadpool_limits

from ...errors import ConfigError, DataError
from ...fitted import FittedModel, OptimizerRecord
from ...metrics import metrics
from ...models import INPUTS
from ...models.gp import GP_KIND, predict_gp
from ...samples import FrictionSamples
from .._intervals import GROSS, gross_errors
from .._records import operating_range, provenance
from .._scatter import measurement_scatter
from ._gp_posterior import _posterior, _smoother_trace, heldout_scale
from ._heldout import ERRORS, interval_record, take_errors
from ._trust import learned_statistics, process_convergence

__all__ = ["DEFAULT_MAX_POINTS", "farthest_points", "fit_gp"]

#: Stored points above which the inducing subset is used (module notes, step 4).
DEFAULT_MAX_POINTS = 400


def farthest_points(Z: np.ndarray, m: int) -> np.ndarray:
    """Indices of ``m`` rows of ``Z (n, d)`` chosen by farthest-point sampling: first the row
    farthest from the mean, then each time the row farthest from those chosen (ties: the
    first). Deterministic; O(n m)."""
    n = Z.shape[0]
    if m >= n:
        return np.arange(n)
    chosen = np.empty(m, dtype=int)
    chosen[0] = int(np.argmax(np.sum((Z - Z.mean(axis=0)) ** 2, axis=1)))
    dist = np.sum((Z - Z[chosen[0]]) ** 2, axis=1)
    for k in range(1, m):
        chosen[k] = int(np.argmax(dist))
        dist = np.minimum(dist, np.sum((Z - Z[chosen[k]]) ** 2, axis=1))
    return np.sort(chosen)


def _symmetry(samples: FrictionSamples) -> str:
    dirs = set(samples.directions())
    if 0 in dirs and len(dirs) > 1:
        raise DataError(
            "the samples mix combined (direction 0, eq. 11) and per-direction rows; fit the "
            "GP on one kind",
            file=samples.source,
        )
    if dirs == {0}:
        return "odd"
    return "per_direction" if dirs == {-1, 1} else ("pos" if dirs == {1} else "neg")


def _interaction(A: np.ndarray, used: list[str]) -> list[np.ndarray]:
    """``|v| T`` when both are used: the viscous coefficient linear in temperature."""
    return [A[:, 0] * A[:, used.index("temperature")]] if "temperature" in used else []


def _train_side(
    samples: FrictionSamples, names: list[str], max_points: int, n_restarts: int, seed: int
) -> dict[str, Any]:
    """The state of one process on ``samples`` (one direction, or combined), trained again
    without its gross errors (module notes, step 5) when it has any."""
    state = _train_once(samples, names, max_points, n_restarts, seed)
    held = state.get(ERRORS)
    if held is None:
        return state
    found = np.isfinite(held)
    gross = np.zeros(held.size, bool)
    gross[found] = gross_errors(np.abs(held[found]))
    if not gross.any():
        return state
    try:
        kept = _train_once(samples.subset(~gross), names, max_points, n_restarts, seed)
    except DataError:  # too few left: the first training stands
        return state
    again = np.full(held.size, np.nan)
    again[~gross] = kept[ERRORS] if kept.get(ERRORS) is not None else np.nan
    again[gross] = held[gross]  # their errors against a process that saw them: gross still
    kept[ERRORS] = again
    kept["left_out"] = {
        "count": int(gross.sum()),
        "velocity": samples.velocity[gross].tolist(),
        "friction": samples.friction[gross].tolist(),
        "reason": f"held-out error beyond {GROSS:g} robust standard deviations",
    }
    return kept


def _noise_floor(samples: FrictionSamples) -> float:
    """The least noise std [N m] of a sample the white kernel may fit (module notes, step
    3): the measured scatter of the moving samples (given, between repeated runs, or the
    within-run lower bound), 0 where it is only estimated from the data."""
    scatter = measurement_scatter(samples)
    se = np.asarray(scatter.per_sample, dtype=float)[samples.velocity != 0]
    se = se[np.isfinite(se)]
    if scatter.estimated or not se.size:
        return 0.0
    return float(np.sqrt(np.mean(se**2)))


def _train_once(
    samples: FrictionSamples, names: list[str], max_points: int, n_restarts: int, seed: int
) -> dict[str, Any]:
    """The state of one process trained on every moving sample of ``samples``."""
    moving = samples.velocity != 0
    v = samples.velocity[moving]
    g = np.sign(v) * samples.friction[moving]
    R = np.column_stack([np.abs(v)] + [samples.X[moving, INPUTS.index(n)] for n in names[1:]])
    if "load" in names:
        R[:, names.index("load")] = np.abs(R[:, names.index("load")])
    kept = [0] + [j for j in range(1, len(names)) if np.ptp(R[:, j]) > 0]
    dropped = {names[j]: float(R[0, j]) for j in range(1, len(names)) if j not in kept}
    R = R[:, kept]
    used = [names[j] for j in kept]
    n, d = R.shape
    if n < d + 3:
        raise DataError(
            f"{n} moving samples are too few for a GP on {', '.join(used)}", file=samples.source
        )
    vscale = float(R[:, 0].min())
    W = R.copy()
    W[:, 0] = np.arcsinh(W[:, 0] / vscale)
    shift = W.mean(axis=0)
    scale = W.std(axis=0)
    scale[scale <= 0] = 1.0
    Z = (W - shift) / scale
    A = np.column_stack([np.ones(n), R, *_interaction(R, used)])
    coef = np.linalg.lstsq(A, g, rcond=None)[0]
    r = g - A @ coef
    y_scale = float(np.std(r))
    if not y_scale > 0:
        y_scale = max(float(np.max(np.abs(g))), 1.0) * 1e-6
    t = r / y_scale
    sub = farthest_points(Z, max_points)
    floor = _noise_floor(samples)
    least = float(np.clip((floor / y_scale) ** 2, 1e-10, 5.0))
    kernel = ConstantKernel(1.0, (1e-4, 1e4)) * RBF(np.ones(d), (1e-2, 1e3)) + WhiteKernel(
        max(1e-2, least), (least, 10.0)
    )
    runs: list[Any] = []

    def lbfgs(obj_func, initial_theta, bounds):
        """scikit-learn's own L-BFGS-B call (``optimizer="fmin_l_bfgs_b"``), its result kept:
        the optimiser's status and evaluations go into the model file."""
        res = scipy.optimize.minimize(
            obj_func, initial_theta, method="L-BFGS-B", jac=True, bounds=bounds
        )
        runs.append(res)
        return res.x, res.fun

    gpr = GaussianProcessRegressor(
        kernel, alpha=1e-10, optimizer=lbfgs, n_restarts_optimizer=n_restarts, random_state=seed
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", SklearnConvergenceWarning)
        gpr.fit(Z[sub], t[sub])
    best = min(runs, key=lambda r: float(r.fun))
    k = gpr.kernel_
    s2 = float(k.k1.k1.constant_value)
    lengths = np.atleast_1d(np.asarray(k.k1.k2.length_scale, dtype=float)) * np.ones(d)
    noise = float(k.k2.noise_level)
    P = Z[sub]
    exact = len(sub) == n
    # the mean's correction on the standardised basis h_s = T h (prior N(0, I) there)
    mu = np.r_[0.0, A[:, 1:].mean(axis=0)]
    sd = np.r_[1.0, A[:, 1:].std(axis=0)]
    sd[sd <= 0] = 1.0
    Tm = np.diag(1.0 / sd)
    Tm[1:, 0] = -mu[1:] / sd[1:]
    As = A @ Tm.T
    alpha, Bm, gain, cov, dbeta = _posterior(P, Z, t, As, lengths, s2, noise, exact)
    coef = coef + y_scale * (Tm.T @ dbeta)
    gain, cov = np.linalg.solve(Tm, gain), Tm.T @ cov @ Tm  # on the raw basis h
    edf = _smoother_trace(P, Z, As, lengths, s2, noise, exact)
    calibration, errors = (
        heldout_scale(Z, A, As, g, (lengths, s2, noise), y_scale) if exact else (None, None)
    )
    inducing = (
        "all training points"
        if exact
        else f"farthest-point subset of {len(sub)} of {n} samples (DTC)"
    )
    state: dict[str, Any] = {
        "inputs": used,
        "velocity_scale": vscale,
        "input_shift": shift.tolist(),
        "input_scale": scale.tolist(),
        "mean_coef": coef.tolist(),
        "length_scales": lengths.tolist(),
        "signal_var": s2,
        "noise_var": noise,
        "noise_std": y_scale * float(np.sqrt(noise)),
        "noise_floor": floor,
        "y_scale": y_scale,
        "points": P.tolist(),
        "alpha": alpha.tolist(),
        "var_matrix": Bm.tolist(),
        "mean_gain": gain.tolist(),
        "mean_cov": cov.tolist(),
        "mean_bounds": np.column_stack([R.min(axis=0), R.max(axis=0)]).tolist(),
        "inducing": inducing,
        "n_train": n,
        "log_marginal_likelihood": float(gpr.log_marginal_likelihood_value_),
        "kernel": str(k),
        "edf": edf,
        "optimizer": {
            "starts": len(runs),
            "nfev": int(sum(int(r.nfev) for r in runs)),
            "converged": bool(best.success),
            "message": str(best.message),
        },
    }
    if calibration is not None:
        state["interval_scale"] = calibration
        held = np.full(len(samples.velocity), np.nan)
        held[moving] = errors
        state[ERRORS] = held  # taken out again by _fit: not stored
    if dropped:
        state["dropped_inputs"] = dropped
    notes = sorted({str(w.message).split(". ")[0] for w in caught})
    if notes:
        state["training_notes"] = notes
    return state


def fit_gp(
    samples: FrictionSamples,
    *,
    inputs: list[str] | tuple[str, ...] = INPUTS,
    max_points: int = DEFAULT_MAX_POINTS,
    n_restarts: int = 2,
    seed: int | None = 0,
) -> FittedModel:
    """Train the Gaussian-process model on ``samples`` (module notes).

    Parameters
    ----------
    samples : FrictionSamples
        The data; samples at zero velocity are left out (``sign(0) = 0``).
    inputs : sequence of str
        Among velocity (required), load and temperature; those the samples do not measure
        are left out.
    max_points : int, default 400
        The most points stored (and the size of the exact GP); above it, the inducing subset.
    n_restarts : int, default 2
        Random restarts of the marginal-likelihood optimiser.
    seed : int, optional
        Seeds the restarts (the second direction's process gets ``seed + 1``).

    Returns
    -------
    FittedModel
        ``model="gp"``, the process(es) in ``state``.

    Raises
    ------
    ConfigError
        Bad ``inputs``, ``max_points`` or ``n_restarts``.
    DataError
        Mixed combined and per-direction samples, too few moving samples.
    """
    names = [str(n).strip().lower() for n in inputs]
    if not names or names[0] != "velocity" or any(n not in INPUTS for n in names):
        raise ConfigError(f"GP inputs must start with velocity, among {INPUTS}; got {inputs!r}")
    names = [n for n in names if n == "velocity" or n in samples.measured]
    if int(max_points) < 10 or int(n_restarts) < 0:
        raise ConfigError(
            f"max_points must be >= 10 and n_restarts >= 0; got {max_points}, {n_restarts}"
        )
    with threadpool_limits(limits=1, user_api="blas"):  # small matrices: threads only cost
        return _fit(samples, names, int(max_points), int(n_restarts), seed)


def _fit(
    samples: FrictionSamples, names: list[str], max_points: int, n_restarts: int, seed: int | None
) -> FittedModel:
    start = time.perf_counter()
    symmetry = _symmetry(samples)
    seed0 = 0 if seed is None else int(seed)
    args = (names, max_points, n_restarts)
    if symmetry == "per_direction":
        state: dict[str, Any] = {
            side: _train_side(samples.subset(samples.direction == d), *args, seed0 + k)
            for k, (side, d) in enumerate((("pos", 1), ("neg", -1)))
        }
    else:
        state = _train_side(samples, *args, seed0)
    errors = take_errors(samples, state, symmetry)
    state = {"kind": GP_KIND, "symmetry": symmetry, **state}
    y_hat = predict_gp(state, samples.X)
    sides = [state["pos"], state["neg"]] if symmetry == "per_direction" else [state]
    n_hyper = sum(len(s["length_scales"]) + 2 for s in sides)
    statistics, note = learned_statistics(
        samples.y,
        y_hat,
        sum(float(s["edf"]) for s in sides),
        "trace of the posterior mean's smoother at the fitted hyperparameters, the mean's "
        f"coefficients included (R&W section 2.6); the {n_hyper} kernel hyperparameters "
        "fitted by marginal likelihood are not counted",
    )
    scatter = measurement_scatter(samples)
    notes = sorted({n for s in sides for n in s.get("training_notes", [])})
    runs = [s["optimizer"] for s in sides]
    return FittedModel(
        model="gp",
        metrics=metrics(samples.y, y_hat, samples.direction, scatter.value),
        statistics=statistics,
        statistics_note=note,
        convergence=process_convergence(runs, notes),
        loss={"scatter": scatter.to_dict()},
        optimizer=OptimizerRecord(
            method="sklearn-gpr",
            seed=seed,
            status=0 if all(r["converged"] for r in runs) else 1,
            message=f"trained in {time.perf_counter() - start:.3g} s",
            nfev=sum(r["nfev"] for r in runs),
            max_evals=0,
        ),
        operating_range=operating_range(samples),
        provenance=provenance(
            samples,
            estimator="fricid.identify.learned.gp.fit_gp",
            estimator_params={
                "inputs": names,
                "max_points": max_points,
                "n_restarts": n_restarts,
            },
        ),
        state=state,
        prediction_interval=interval_record(errors, samples, scatter.value, HELD),
    )


#: What the local spread of a GP's intervals is made of.
HELD = "leave-one-out errors of refits at the fitted hyperparameters"
