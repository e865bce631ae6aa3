"""The BAS-RBFNN paper's study (section 4), reproduced on the virtual joint: computation only.

[B] The BAS-RBFNN paper (``seeds/bas-rbfnn-static-friction.txt``). On the ``paper1`` preset
(15 velocities x 21 loads x 21 temperatures = 6615 operating points, simulated and extracted by
eq. 9-13) :func:`run_study` computes

* **Table 1**: fitness (R^2), RMSE and RMSPE of the velocity (``stribeck``, eq. 2),
  velocity-load (``msk``, eq. 3) and velocity-load-temperature (``vlt``, eq. 4) models;
* **Table 3**: mean and max absolute error of RBFNN (``lsq``), BAS-RBFNN and the ``vlt``
  model with all data as the training set, as the paper does, **and** out of fold (k-fold
  cross-validation), which the paper does not report; scikit-learn's ``MLPRegressor`` and
  ``GaussianProcessRegressor`` beside them on the same folds and inputs;
* **Table 4 and Fig. 9**: GA-RBFNN against BAS-RBFNN over several seeds: epochs to the
  target MSE at equal evaluations per epoch, accuracy, and the MSE curves; GA's population
  starts around the least-squares network, as BAS starts from it;
* **tuning** (:mod:`.rbfnn_tuning`): BAS's, GA's and the MLP's settings picked on another
  noise draw and other search seeds than those reported, each budget stated;
* **what the search achieved** (:func:`~.rbfnn_tables.search_effect`): BAS-RBFNN against its
  own start, improved or not, by how much, held out;
* **Fig. 10**: generalisation to the unseen region (52-60 deg/s, -22 to -10 deg, 45-55 degC,
  steps of 2), where the oracle gives the true friction;
* timings of training on all the data, and the performance targets of the issue.

Everything is returned as pandas DataFrames and arrays (:class:`StudyResult`); the paper's
numbers sit beside ours in the tables (:data:`PAPER`). Rendering (the Markdown summary, the
figures, the files) is :mod:`fricid.report.studies.rbfnn`'s. The settings are in
:mod:`.rbfnn_config`, the learners in :mod:`.rbfnn_learners`, the tables in
:mod:`.rbfnn_tables`.

Units: errors in the tables are in mN m (the paper's are N m; the paper columns are converted
to mN m too, so both read alike).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pandas as pd

from ..errors import ConfigError
from ..metrics import rmse
from ..samples import FrictionSamples
from ..units import DEG
from .rbfnn_config import (
    BAS_PAPER,
    BAS_TUNED,
    GA_TUNED,
    PAPER,
    TABLE1_MODELS,
    StudyConfig,
    study_config,
)
from .rbfnn_data import paper1_data, true_friction
from .rbfnn_learners import SubsetGP, mlp_model
from .rbfnn_tables import TIMED, fig10, search_effect, table1, table3, table4, targets, timing
from .rbfnn_tuning import TUNING_SEED_OFFSET, tune

__all__ = [
    "BAS_PAPER",
    "BAS_TUNED",
    "GA_TUNED",
    "PAPER",
    "TABLE1_MODELS",
    "TIMED",
    "TUNING_SEED_OFFSET",
    "StudyConfig",
    "StudyResult",
    "SubsetGP",
    "fig10",
    "mlp_model",
    "noise_floor",
    "paper1_data",
    "run_study",
    "search_effect",
    "study_config",
    "table1",
    "table3",
    "table4",
    "targets",
    "timing",
    "true_friction",
    "tune",
    "unseen_region",
]

logger = logging.getLogger(__name__)


@dataclass
class StudyResult:
    """What the study produced.

    ``tables`` by name (``table1``, ``table3``, ``table4``, ``fig10``, ``timing``,
    ``targets``, ``data``); ``curves``: per method, one MSE-per-epoch array per seed (Fig. 9);
    ``unseen``: the unseen-region inputs, truth and each model's absolute errors (Fig. 10);
    ``predictions``: the measured and true friction and each all-data model's prediction at
    the samples (Fig. 8); ``config``; ``seconds`` per stage.
    """

    tables: dict[str, pd.DataFrame]
    curves: dict[str, list[np.ndarray]]
    unseen: dict[str, np.ndarray]
    predictions: dict[str, np.ndarray]
    config: StudyConfig
    seconds: dict[str, float]


# -- data --------------------------------------------------------------------------------------


def noise_floor(scenario: Any) -> float:
    """The RMS of :func:`fricid.sim.expected_noise_std` over the design [N m]."""
    from ..sim import expected_noise_std

    return float(np.sqrt(np.mean(expected_noise_std(scenario) ** 2)))


def unseen_region(size: str = "full") -> FrictionSamples:
    """The true friction in Fig. 10's unseen region: 52-60 deg/s, positions -22 to -10 deg
    (their gravity loads, eq. 7 and 12), 45-55 degC, all in steps of 2 (210 points)."""
    from ..sim import Design, preset, true_samples

    scenario = preset("paper1", size)
    design = replace(
        scenario.design,
        velocities=np.arange(52.0, 60.5, 2.0) * DEG,
        positions=np.arange(-22.0, -9.5, 2.0) * DEG,
        temperatures=np.arange(45.0, 55.5, 2.0),
    )
    if not isinstance(design, Design):  # pragma: no cover - replace keeps the type
        raise ConfigError("unexpected design type")
    truth = true_samples(replace(scenario, design=design))
    return replace(truth, source="unseen region (Fig. 10)")


# -- the whole study ---------------------------------------------------------------------------


def run_study(
    cfg: StudyConfig | None = None,
    *,
    data: tuple[FrictionSamples, np.ndarray, float] | None = None,
    progress: Callable[[str], None] | None = None,
) -> StudyResult:
    """Run the study (see the module docstring) and return its tables and curves.

    Parameters
    ----------
    cfg : StudyConfig, optional
        The settings (default :func:`study_config`).
    data : tuple, optional
        ``(samples, true friction at their rows, noise floor [N m])`` already at hand (e.g.
        from a reproduction that simulated the joint itself); by default
        :func:`paper1_data` makes them from ``cfg``.
    progress : callable, optional
        Called with a line per step.

    Returns
    -------
    StudyResult

    Raises
    ------
    ConfigError
        If the true friction's shape differs from the samples'.
    """
    cfg = cfg or study_config()
    say = progress or (lambda _msg: None)
    seconds: dict[str, float] = {}

    def stage(name: str, t0: float) -> None:
        seconds[name] = time.perf_counter() - t0
        logger.info("%s: %.1f s", name, seconds[name])

    t0 = time.perf_counter()
    if data is None:
        say(f"data: paper1/{cfg.size} ({cfg.data})")
        data = paper1_data(cfg.size, cfg.seed, cfg.data)
    samples, true_y, floor = data
    true_y = np.asarray(true_y, dtype=float)
    if true_y.shape != samples.y.shape:
        raise ConfigError(
            f"the true friction has shape {true_y.shape}; the samples {samples.y.shape}"
        )
    stage("data", t0)
    data_table = pd.DataFrame(
        [
            {
                "samples": len(samples),
                "source": samples.source,
                "noise_floor_mNm": 1e3 * floor,
                "rms_samples_minus_truth_mNm": 1e3 * rmse(true_y, samples.y),
                "friction_min_Nm": float(samples.y.min()),
                "friction_max_Nm": float(samples.y.max()),
                "target_rmse_mNm": 1e3
                * math.sqrt(cfg.target_mse)
                * 0.5
                * float(samples.y.max() - samples.y.min()),
            }
        ]
    )

    tuning = pd.DataFrame()
    if cfg.tune:
        t0 = time.perf_counter()
        cfg, tuning = tune(cfg, say)
        stage("tuning", t0)

    t0 = time.perf_counter()
    say("Table 1")
    t1 = table1(samples, cfg.seed)
    stage("table1", t0)

    t0 = time.perf_counter()
    t3, fitted_all, _, search = table3(samples, true_y, cfg, say)
    stage("table3", t0)

    t0 = time.perf_counter()
    t4, per_run, curves = table4(samples, cfg, say)
    stage("table4", t0)

    t0 = time.perf_counter()
    unseen = unseen_region(cfg.size)
    f10, errors = fig10(fitted_all, unseen)
    stage("fig10", t0)

    t0 = time.perf_counter()
    tm = timing(samples, cfg, say)
    tm_all = timing(samples, cfg, say, threads=None)
    stage("timing", t0)

    tg = targets(t3, t4, tm, floor, cfg, tm_all)
    return StudyResult(
        tables={
            "data": data_table,
            "table1": t1,
            "table3": t3,
            "table4": t4,
            "table4_runs": per_run,
            "search": search,
            "tuning": tuning,
            "fig10": f10,
            "timing": tm,
            "timing_all_threads": tm_all,
            "targets": tg,
        },
        curves=curves,
        unseen={
            "velocity": unseen.velocity,
            "load": unseen.load,
            "temperature": unseen.temperature,
            **errors,
        },
        predictions={
            "measured": samples.y,
            "truth": true_y,
            **{label: model.predict(samples.X) for label, model in fitted_all.items()},
        },
        config=cfg,
        seconds=seconds,
    )
