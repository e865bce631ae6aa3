"""The tables of the BAS-RBFNN study (:mod:`.rbfnn_study`), each computed from samples and a
:class:`~.rbfnn_config.StudyConfig`: [B] Table 1 (analytic models eq. 2-4), Table 3 (all data
and k-fold held out), Table 4 with Fig. 9's curves (GA-RBFNN against BAS-RBFNN over seeds),
Fig. 10's errors in the unseen region, training times and the performance targets.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
import pandas as pd

from ..identify import fit as identify_fit
from ..metrics import mae, max_abs_error, rmse
from ..samples import FrictionSamples
from .rbfnn_config import BAS_PAPER, PAPER, TABLE1_MODELS, StudyConfig
from .rbfnn_learners import describe, fit_learner, learners, search_network

__all__ = [
    "TIMED",
    "fig10",
    "search_effect",
    "table1",
    "table3",
    "table4",
    "targets",
    "timing",
]


def table1(samples: FrictionSamples, seed: int = 0) -> pd.DataFrame:
    """Table 1: fitness, RMSE, RMSPE of the stribeck, msk and vlt models (``lm``), ours
    beside the paper's."""
    rows = []
    for name, column in TABLE1_MODELS.items():
        fitted = identify_fit(samples, name, "lm", seed=seed)
        paper = PAPER["table1"][name]
        m = fitted.metrics
        rows.append(
            {
                "model": column,
                "registry": name,
                "fitness": m["fitness"],
                "rmse_mNm": 1e3 * m["rmse"],
                "rmspe": m["rmspe"],
                "paper_fitness": paper["fitness"],
                "paper_rmse": paper["rmse"],
                "paper_rmspe": paper["rmspe"],
            }
        )
    return pd.DataFrame(rows)


def _errors(y: np.ndarray, y_hat: np.ndarray, true_y: np.ndarray) -> dict[str, float]:
    return {
        "mean_mNm": 1e3 * mae(y, y_hat),
        "max_mNm": 1e3 * max_abs_error(y, y_hat),
        "rmse_mNm": 1e3 * rmse(y, y_hat),
        "rmse_truth_mNm": 1e3 * rmse(true_y, y_hat),
    }


def table3(
    samples: FrictionSamples, true_y: np.ndarray, cfg: StudyConfig, say: Callable[[str], None]
) -> tuple[pd.DataFrame, dict[str, Any], dict[str, float], pd.DataFrame]:
    """Table 3, all data as the training set and out of fold. Returns the table, the models
    fitted on all data (for Fig. 10), the seconds each took to train on all data, and what
    BAS-RBFNN's search itself achieved (:func:`search_effect`). The ``warnings`` column
    counts the warnings of all its fits (all data and every fold), recorded, not silenced."""
    from sklearn.model_selection import KFold

    makers = learners(cfg)
    folds = list(KFold(cfg.folds, shuffle=True, random_state=cfg.seed).split(samples.X))
    fitted_all: dict[str, Any] = {}
    fit_seconds: dict[str, float] = {}
    oof: dict[str, np.ndarray] = {}
    fold_models: dict[str, list[Any]] = {}
    rows = []
    for label, make in makers.items():
        say(f"Table 3: {label} on all data")
        t0 = time.perf_counter()
        model = fit_learner(make(), samples)
        fit_seconds[label] = time.perf_counter() - t0
        fitted_all[label] = model
        y_all = model.predict(samples.X)
        say(f"Table 3: {label}, {cfg.folds}-fold cross-validation")
        y_oof = np.empty(len(samples))
        fold_models[label] = []
        for train, test in folds:
            fold_model = fit_learner(make(), samples.subset(train))
            y_oof[test] = fold_model.predict(samples.X[test])
            fold_models[label].append(fold_model)
        oof[label] = y_oof
        caught = [w for m in (model, *fold_models[label]) for w in m.fit_warnings_]
        paper = PAPER["table3"].get(label, {})
        row = {"model": label, "setup": describe(label, cfg)}
        row.update({f"all_{k}": v for k, v in _errors(samples.y, y_all, true_y).items()})
        row.update({f"cv_{k}": v for k, v in _errors(samples.y, y_oof, true_y).items()})
        row["paper_mean_mNm"] = 1e3 * paper.get("mean", np.nan)
        row["paper_max_mNm"] = 1e3 * paper.get("max", np.nan)
        row["fit_s"] = fit_seconds[label]
        row["warnings"] = len(caught)
        row["warning_kinds"] = "; ".join(sorted({w.split(":")[0] for w in caught}))
        rows.append(row)
    search = search_effect(samples, folds, fitted_all, fold_models, oof)
    return pd.DataFrame(rows), fitted_all, fit_seconds, search


def search_effect(
    samples: FrictionSamples,
    folds: list[tuple[np.ndarray, np.ndarray]],
    fitted_all: dict[str, Any],
    fold_models: dict[str, list[Any]],
    oof: dict[str, np.ndarray],
    label: str = "BAS-RBFNN",
    start: str = "RBFNN",
) -> pd.DataFrame:
    """What the search of ``label`` achieved from its start, the ``start`` network (the same
    centres and widths: both are built from one configuration and seed), fold by fold.

    The search returns its start when it finds nothing better, so "``label`` <= ``start``"
    on the training data holds by construction; this table says instead, per fit (each fold,
    and all data), whether the search improved the training MSE and by how much, and how the
    held-out RMSE of the fold changed, which can be worse.

    Returns
    -------
    pandas.DataFrame
        One row per fold and one for all data: ``improved`` (training MSE below the start's),
        ``train_mse_start``, ``train_mse_search`` (scaled target, [B] section 4.3),
        ``train_change_pct``, and for folds ``heldout_rmse_start_mNm``,
        ``heldout_rmse_search_mNm`` and ``heldout_change_pct`` (negative: better).
    """
    if label not in fitted_all or start not in fitted_all:
        return pd.DataFrame()
    rows = []
    fits = [
        (f"fold {k + 1}", m, test)
        for k, (m, (_, test)) in enumerate(zip(fold_models[label], folds, strict=True))
    ]
    fits.append(("all data", fitted_all[label], None))
    for name, m, test in fits:
        m0, m1 = float(m.initial_mse_), float(m.train_mse_)
        row = {
            "fit": name,
            "improved": bool(m1 < m0),
            "train_mse_start": m0,
            "train_mse_search": m1,
            "train_change_pct": 100.0 * (m1 / m0 - 1.0),
        }
        if test is not None:
            r0 = 1e3 * rmse(samples.y[test], oof[start][test])
            r1 = 1e3 * rmse(samples.y[test], oof[label][test])
            row.update(
                {
                    "heldout_rmse_start_mNm": r0,
                    "heldout_rmse_search_mNm": r1,
                    "heldout_change_pct": 100.0 * (r1 / r0 - 1.0),
                }
            )
        rows.append(row)
    return pd.DataFrame(rows)


def table4(
    samples: FrictionSamples, cfg: StudyConfig, say: Callable[[str], None]
) -> tuple[pd.DataFrame, pd.DataFrame, dict[str, list[np.ndarray]]]:
    """Table 4 and Fig. 9: GA-RBFNN against BAS-RBFNN, ``cfg.seeds`` runs each, trained on
    all data to the target MSE at ``evals_per_epoch`` evaluations per epoch. Returns the
    summary table, the per-run table and the MSE curves."""
    # label: (method, options, network parameters changed from cfg.network())
    bas, ga = dict(cfg.bas_options), dict(cfg.ga_options)
    methods: dict[str, tuple[str, dict[str, Any], dict[str, Any]]] = {
        "GA-RBFNN": ("ga", ga, {}),
        "BAS-RBFNN": ("bas", bas, {}),
    }
    if cfg.variants:
        narrow = {"width_factor": cfg.narrow_width_factor}
        w = f"{cfg.narrow_width_factor:g}"
        methods.update(
            {
                f"GA-RBFNN, start widths x{w}": ("ga", ga, narrow),
                f"BAS-RBFNN, start widths x{w}": ("bas", bas, narrow),
                "BAS-RBFNN (eq. 21 constants)": ("bas", dict(BAS_PAPER), {}),
                "BAS-RBFNN (full encoding)": ("bas", bas, {"encoding": "full"}),
                "BAS-RBFNN (full, random start)": (
                    "bas",
                    bas,
                    {"encoding": "full", "init": "random"},
                ),
            }
        )
    runs = []
    curves: dict[str, list[np.ndarray]] = {label: [] for label in methods}
    for label, (method, options, changes) in methods.items():
        for r in range(cfg.seeds):
            seed = cfg.seed + r
            say(f"Table 4: {label}, seed {seed}")
            net = search_network(cfg, method, options, changes, seed)
            t0 = time.perf_counter()
            net.fit(samples.X, samples.y)
            seconds = time.perf_counter() - t0
            y_hat = net.predict(samples.X)
            curves[label].append(np.concatenate([[net.initial_mse_], net.mse_history_]))
            runs.append(
                {
                    "model": label,
                    "seed": seed,
                    "epochs_to_target": (
                        np.nan if net.epochs_to_target_ is None else net.epochs_to_target_
                    ),
                    "epochs_run": net.n_epochs_,
                    "evaluations": net.n_evals_,
                    "initial_mse": net.initial_mse_,
                    "final_mse": net.train_mse_,
                    # the search returns its start when it finds nothing better: say which
                    "improved": bool(net.train_mse_ < net.initial_mse_),
                    "mean_mNm": 1e3 * mae(samples.y, y_hat),
                    "max_mNm": 1e3 * max_abs_error(samples.y, y_hat),
                    "seconds": seconds,
                }
            )
    per_run = pd.DataFrame(runs)
    rows = []
    for label in methods:
        sub = per_run[per_run["model"] == label]
        ep = sub["epochs_to_target"].to_numpy(dtype=float)
        reached = np.isfinite(ep)
        paper = PAPER["table4"].get(label, {"epochs": np.nan, "mean": np.nan, "max": np.nan})
        rows.append(
            {
                "model": label,
                "runs": len(sub),
                "reached_target": int(reached.sum()),
                "improved_on_start": int(sub["improved"].sum()),
                "epochs_median": float(np.median(np.where(reached, ep, np.inf))),
                "epochs_mean_reached": float(ep[reached].mean()) if reached.any() else np.nan,
                "epochs_min": float(ep[reached].min()) if reached.any() else np.nan,
                "epochs_max": float(ep[reached].max()) if reached.any() else np.nan,
                "mean_mNm": float(sub["mean_mNm"].mean()),
                "max_mNm": float(sub["max_mNm"].mean()),
                "seconds_mean": float(sub["seconds"].mean()),
                "paper_epochs": paper["epochs"],
                "paper_mean_mNm": 1e3 * paper["mean"],
                "paper_max_mNm": 1e3 * paper["max"],
            }
        )
    return pd.DataFrame(rows), per_run, curves


def fig10(
    models: dict[str, Any], unseen: FrictionSamples
) -> tuple[pd.DataFrame, dict[str, np.ndarray]]:
    """Fig. 10: each all-data model's absolute error in the unseen region, overall and split
    at the training data's highest temperature (45 degC: velocity and load extrapolation only;
    47-55 degC: temperature extrapolation as well)."""
    rows = []
    errors: dict[str, np.ndarray] = {"truth": unseen.y}
    edge = unseen.temperature <= 45.0 + 1e-9
    for label, model in models.items():
        err = np.abs(model.predict(unseen.X) - unseen.y)
        errors[label] = err
        row = {
            "model": label,
            "mean_mNm": 1e3 * err.mean(),
            "max_mNm": 1e3 * err.max(),
            "mean_at_45C_mNm": 1e3 * err[edge].mean() if edge.any() else np.nan,
            "mean_47_55C_mNm": 1e3 * err[~edge].mean() if (~edge).any() else np.nan,
        }
        if label == "BAS-RBFNN":
            row["paper_mean_mNm"] = 1e3 * PAPER["fig10"]["mean"]
            row["paper_max_mNm"] = 1e3 * PAPER["fig10"]["max"]
        rows.append(row)
    return pd.DataFrame(rows), errors


#: The models timed on all the data, by their Table 3 label (the larger lsq net is added).
TIMED = ("RBFNN", "BAS-RBFNN", "MLP")


def timing(
    samples: FrictionSamples,
    cfg: StudyConfig,
    say: Callable[[str], None],
    threads: int | None = 1,
) -> pd.DataFrame:
    """Training time on all the data, with ``threads`` BLAS and OpenMP threads (None: the
    libraries' defaults, all cores), every model timed
    by the same statistic: for each of the ``cfg.seeds`` seeds of Table 4 (the seed of the
    model's ``random_state``: k-means and BAS for the networks, the initial weights and
    mini-batches for the MLP), the best of ``timing_repeats`` fits; then the median
    (``seconds``) and the maximum (``seconds_max``) over the seeds. The models are fitted
    in turn within each repeat, so a change of load on the machine touches them alike.
    Every fit is a fresh estimator from the same factories as Table 3
    (:func:`~.rbfnn_learners.learners`).

    ``ratio_to_mlp`` is ``seconds`` over the MLP's ``seconds`` (median against median);
    ``ratio_max_to_mlp`` is ``seconds_max`` over the MLP's ``seconds_max`` (slowest seed
    against slowest seed). ``cpu_seconds`` is the same statistic of the process CPU time
    (the wall time minus waiting for a CPU on a shared machine, for single-threaded fits).
    """
    from threadpoolctl import threadpool_limits

    labels = list(TIMED)
    if cfg.large_centers:
        labels.append(f"RBFNN-{cfg.large_centers}")
    seeds = list(range(cfg.seed, cfg.seed + max(1, cfg.seeds)))
    repeats = max(1, cfg.timing_repeats)
    wall = {label: np.full((len(seeds), repeats), np.inf) for label in labels}
    cpu = {label: np.full((len(seeds), repeats), np.inf) for label in labels}

    with threadpool_limits(limits=threads):
        for i, seed in enumerate(seeds):
            makers = learners(replace(cfg, seed=seed))
            say(
                f"timing ({threads or 'all'} threads): seed {seed}, {', '.join(labels)}, "
                f"best of {repeats}"
            )
            for r in range(repeats):
                for label in labels:
                    model = makers[label]()
                    t0, c0 = time.perf_counter(), time.process_time()
                    fit_learner(model, samples)
                    wall[label][i, r] = time.perf_counter() - t0
                    cpu[label][i, r] = time.process_time() - c0
    timed = f"median (max) over {len(seeds)} seeds of the best of {repeats}"
    rows = []
    for label in labels:
        best, best_cpu = wall[label].min(axis=1), cpu[label].min(axis=1)
        rows.append(
            {
                "model": label,
                "seconds": float(np.median(best)),
                "seconds_max": float(best.max()),
                "cpu_seconds": float(np.median(best_cpu)),
                "timed": timed,
                "threads": "1" if threads == 1 else str(threads or "all"),
            }
        )
    out = pd.DataFrame(rows)
    mlp = out.set_index("model").loc["MLP"]
    out["ratio_to_mlp"] = out["seconds"] / float(mlp["seconds"])
    out["ratio_max_to_mlp"] = out["seconds_max"] / float(mlp["seconds_max"])
    return out


def _ratio(a: float, b: float) -> float:
    """a / b, NaN when both are infinite (neither method reached the target)."""
    if math.isinf(a) and math.isinf(b):
        return float("nan")
    return a / b if b else float("inf")


def targets(
    t3: pd.DataFrame,
    t4: pd.DataFrame,
    tm: pd.DataFrame,
    floor: float,
    cfg: StudyConfig,
    tm_all: pd.DataFrame | None = None,
) -> pd.DataFrame:
    """The issue's performance targets, measured: value, goal, met."""
    rbf = t3[t3["model"].str.contains("RBFNN")]
    best = rbf.loc[rbf["cv_rmse_mNm"].idxmin()]
    ratio = float(best["cv_rmse_mNm"]) / (1e3 * floor)
    by = t4.set_index("model")
    bas_ep, ga_ep = by.loc["BAS-RBFNN", "epochs_median"], by.loc["GA-RBFNN", "epochs_median"]
    times = tm.set_index("model")["ratio_to_mlp"]
    worst = tm.set_index("model")["ratio_max_to_mlp"]
    cv = t3.set_index("model")["cv_rmse_mNm"]
    rows = [
        {
            "target": f"held-out RMSE of the best RBF trainer ({best['model']}) / noise floor "
            f"({1e3 * floor:.3f} mN m)",
            "value": ratio,
            "goal": "<= 1.15",
            "met": ratio <= 1.15,
        },
        {
            "target": f"median epochs to MSE {cfg.target_mse:g}: BAS / GA "
            f"({bas_ep:g} / {ga_ep:g}), {cfg.seeds} seeds, {cfg.evals_per_epoch} "
            "evaluations per epoch",
            "value": _ratio(bas_ep, ga_ep),
            "goal": "< 1",
            "met": bool(bas_ep < ga_ep),
        },
        {
            "target": "lsq training time / MLP's (all data)",
            "value": float(times["RBFNN"]),
            "goal": "<= 0.1",
            "met": float(times["RBFNN"]) <= 0.1,
        },
        {
            "target": "hybrid BAS-RBFNN training time / MLP's (all data; both: median over "
            f"{cfg.seeds} seeds of the best of {max(1, cfg.timing_repeats)}; slowest seed "
            f"against slowest seed {float(worst['BAS-RBFNN']):.3g})",
            "value": float(times["BAS-RBFNN"]),
            "goal": "<= 1",
            "met": float(times["BAS-RBFNN"]) <= 1.0,
        },
        *(
            []
            if tm_all is None
            else [
                {
                    "target": "the same, both with the libraries' default threads (all "
                    "cores; slowest seed against slowest seed "
                    f"{float(tm_all.set_index('model').loc['BAS-RBFNN', 'ratio_max_to_mlp']):.3g})",
                    "value": float(tm_all.set_index("model").loc["BAS-RBFNN", "ratio_to_mlp"]),
                    "goal": "<= 1",
                    "met": float(tm_all.set_index("model").loc["BAS-RBFNN", "ratio_to_mlp"]) <= 1.0,
                }
            ]
        ),
        {
            "target": "held-out RMSE: hybrid BAS-RBFNN / MLP",
            "value": float(cv["BAS-RBFNN"] / cv["MLP"]),
            "goal": "< 1",
            "met": float(cv["BAS-RBFNN"]) < float(cv["MLP"]),
        },
    ]
    return pd.DataFrame(rows)
