"""Tuning of the BAS-RBFNN study's searches and MLP, apart from what the study reports.

[B] The BAS-RBFNN paper gives neither BAS's starting values nor its GA's operators, so the
study picks them, and the MLP baseline's layers and penalty, from small grids
(:data:`~.rbfnn_config.BAS_GRID`, :data:`~.rbfnn_config.GA_GRID`,
:data:`~.rbfnn_config.MLP_GRID`). Picking them on the data and seeds then reported would tilt
the comparison towards whatever was tuned hardest, so :func:`tune` picks on

* **other data**: the same ``paper1`` design with another noise draw (the oracle's friction
  plus noise of the expected size, seed ``seed +`` :data:`TUNING_SEED_OFFSET`), split once into
  training points and held-out points (one fold in ``cfg.folds``);
* **other search seeds**: ``seed + TUNING_SEED_OFFSET + r``; the reported runs use
  ``seed .. seed + seeds - 1``;
* **one criterion for all**: the held-out RMSE (mean over the tuning seeds);
* **one budget rule**: BAS and GA get as many settings, seeds and epochs each (the same number
  of evaluations); the MLP as many settings, one fit each (its own early stopping ends it).

The table it returns states every setting's score and each learner's tuning budget.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
import pandas as pd

from ..errors import ConfigError
from ..metrics import rmse
from .rbfnn_config import BAS_GRID, GA_GRID, MLP_GRID, StudyConfig
from .rbfnn_learners import fit_learner, mlp_model, search_network

__all__ = ["TUNING_SEED_OFFSET", "tune", "tuning_budget"]

#: Offset of the tuning data's and searches' seeds from the reported ones.
TUNING_SEED_OFFSET = 1000


def _setting(options: dict[str, Any]) -> str:
    return ", ".join(f"{k} {v}" for k, v in options.items() if k != "evaluate_position")


def tuning_budget(cfg: StudyConfig) -> dict[str, str]:
    """Each tuned learner's budget, as text (settings x seeds x epochs x evaluations)."""
    per = cfg.tune_epochs * cfg.evals_per_epoch
    return {
        "BAS-RBFNN": f"{len(BAS_GRID)} settings x {cfg.tune_seeds} seeds x {cfg.tune_epochs} "
        f"epochs x {cfg.evals_per_epoch} evaluations = "
        f"{len(BAS_GRID) * cfg.tune_seeds * per} evaluations",
        "GA-RBFNN": f"{len(GA_GRID)} settings x {cfg.tune_seeds} seeds x {cfg.tune_epochs} "
        f"epochs x {cfg.evals_per_epoch} evaluations = "
        f"{len(GA_GRID) * cfg.tune_seeds * per} evaluations",
        "MLP": f"{len(MLP_GRID)} settings x 1 fit (early stopping)",
    }


def tune(
    cfg: StudyConfig, say: Callable[[str], None] | None = None
) -> tuple[StudyConfig, pd.DataFrame]:
    """Pick BAS's, GA's and the MLP's settings on tuning data (see the module docstring).

    Parameters
    ----------
    cfg : StudyConfig
        The study's settings; ``cfg.seeds`` must be below :data:`TUNING_SEED_OFFSET` (the
        reported seeds never meet the tuning ones).
    say : callable, optional
        Progress, one line per setting.

    Returns
    -------
    tuple
        ``cfg`` with the chosen ``bas_options``, ``ga_options`` and ``mlp_options``, and the
        tuning table: one row per learner and setting (held-out RMSE [mN m], training MSE
        of the searches, evaluations or fits, warnings, seconds, ``chosen``), each learner's
        budget in ``budget``.

    Raises
    ------
    ConfigError
        If the reported seeds would reach the tuning seeds.
    """
    from .rbfnn_data import paper1_data

    if cfg.seeds >= TUNING_SEED_OFFSET:
        raise ConfigError(f"seeds must be below {TUNING_SEED_OFFSET} to stay apart from tuning")
    say = say or (lambda _msg: None)
    base = cfg.seed + TUNING_SEED_OFFSET
    samples, _, _ = paper1_data(cfg.size, base, "oracle")
    perm = np.random.default_rng(base).permutation(len(samples))
    n_test = max(1, len(samples) // max(2, cfg.folds))
    test, train = np.sort(perm[:n_test]), np.sort(perm[n_test:])
    fit_on, X_test, y_test = samples.subset(train), samples.X[test], samples.y[test]
    small = replace(cfg, max_epochs=cfg.tune_epochs)
    budget = tuning_budget(cfg)
    rows: list[dict[str, Any]] = []
    for label, method, grid in (("BAS-RBFNN", "bas", BAS_GRID), ("GA-RBFNN", "ga", GA_GRID)):
        for options in grid:
            say(f"tuning {label}: {_setting(options)}")
            scores, mses, evals, t0 = [], [], 0, time.perf_counter()
            for r in range(cfg.tune_seeds):
                net = search_network(small, method, options, {}, base + r)
                net.fit(fit_on.X, fit_on.y)
                scores.append(1e3 * rmse(y_test, net.predict(X_test)))
                mses.append(float(net.train_mse_))
                evals += int(net.n_evals_)
            rows.append(
                {
                    "learner": label,
                    "setting": _setting(options),
                    "heldout_rmse_mNm": float(np.mean(scores)),
                    "train_mse": float(np.mean(mses)),
                    "cost": f"{evals} evaluations",
                    "warnings": 0,
                    "seconds": time.perf_counter() - t0,
                    "options": dict(options),
                }
            )
    for options in MLP_GRID:
        say(f"tuning MLP: {_setting(options)}")
        t0 = time.perf_counter()
        model = fit_learner(mlp_model(cfg, options, seed=base), fit_on)
        rows.append(
            {
                "learner": "MLP",
                "setting": _setting(options),
                "heldout_rmse_mNm": 1e3 * rmse(y_test, model.predict(X_test)),
                "train_mse": np.nan,
                "cost": "1 fit",
                "warnings": len(model.fit_warnings_),
                "seconds": time.perf_counter() - t0,
                "options": dict(options),
            }
        )
    table = pd.DataFrame(rows)
    table["chosen"] = False
    for label in ("BAS-RBFNN", "GA-RBFNN", "MLP"):
        sub = table[table["learner"] == label]
        table.loc[sub["heldout_rmse_mNm"].idxmin(), "chosen"] = True
    table["budget"] = table["learner"].map(budget)
    pick = table[table["chosen"]].set_index("learner")["options"]
    tuned = replace(
        cfg,
        bas_options=dict(pick["BAS-RBFNN"]),
        ga_options=dict(pick["GA-RBFNN"]),
        mlp_options=dict(pick["MLP"]),
    )
    table["tuning_data"] = f"paper1/{cfg.size} oracle + noise, seed {base}; {len(test)} held out"
    return tuned, table.drop(columns="options")
