"""The BAS-RBFNN paper's study on the virtual joint: every table's and figure's data.

[B] "An Optimized RBF Neural Network Based on Beetle Antennae Search Algorithm for Modeling the
Static Friction in a Robotic Manipulator Joint". :func:`run_bas_rbfnn` simulates and extracts
the ``paper1`` preset (eq. 9-13) and computes what each table and figure shows: the gravity
torque per operating point and its fit (Fig. 1, eq. 7 and 11), the samples as a grid (Fig. 6
a-c), the analytic models eq. 2-4 (Table 1, Fig. 7, Table 2), and the RBF network study
(Table 3, Fig. 8, Table 4, Fig. 9, Fig. 10) by
:func:`fricid.experiments.rbfnn_study.run_study` on the same samples; with the computed
claims the report's prose cites (:class:`BasRbfnnResult`). The document is composed by
:mod:`fricid.report.studies.bas_rbfnn`.
"""

from __future__ import annotations

import itertools
import logging
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import DataError
from ..extract import ExtractionResult, extract
from ..fitted import FittedModel
from ..identify import fit
from ..sim import preset, simulate, true_gravity
from . import rbfnn_study

__all__ = ["STEPS", "TABLE1_MODELS", "BasRbfnnResult", "run_bas_rbfnn"]

logger = logging.getLogger(__name__)

#: Labels of the steps reported to the progress callback, in order.
STEPS = (
    "simulating and extracting the virtual joint (paper1 preset)",
    "Fig. 1: gravity fit",
    "Fig. 6: two-factor surfaces",
    "Table 1, Fig. 7, Table 2: analytic models",
    "Table 3, Fig. 8: RBF networks on all data and out of fold",
    "Table 4, Fig. 9: GA-RBFNN against BAS-RBFNN over several seeds",
    "Fig. 10: the unseen region; training times",
)

#: [B] Table 1's models, in its column order (eq. 2, 3, 4).
TABLE1_MODELS = ("stribeck", "msk", "vlt")


@dataclass
class BasRbfnnResult:
    """What :func:`run_bas_rbfnn` computed.

    Attributes
    ----------
    extraction : fricid.extract.ExtractionResult
        The extracted samples (``extraction.samples``), per direction, and the gravity fit.
    scenario : fricid.sim.Scenario
        The simulated ``paper1`` scenario.
    gravity_points : tuple of numpy.ndarray
        Fig. 1: position [rad] and gravity torque ``-(tau+ + tau-)/2`` (eq. 11) per operating
        point [N m].
    true_gravity : tuple of float
        The virtual joint's ``(p_x, p_y)`` of eq. 7 [N m].
    grid : dict or None
        Fig. 6: friction as a (temperature, velocity, position bin) array, with the mean load
        per bin, the temperatures and velocities; None if the grid is incomplete.
    fits : dict
        Table 1, Fig. 7, Table 2: the analytic models fitted by ``lm``, by registry name.
    study : fricid.experiments.rbfnn_study.StudyResult
        Tables 3-4, Fig. 8-10.
    claims : dict
        Booleans the report's prose cites: ``table1_fitness_rises``,
        ``table3_order_as_paper`` (BAS-RBFNN < RBFNN < eq. 4 on all data),
        ``table3_bas_leads_held_out``, ``table4_bas_fewer_epochs`` (median epochs to the
        target), ``fig10_error_grows_beyond_45C`` (BAS-RBFNN's error at 47-55 degC above
        that at 45 degC).
    quick, seed : bool, int
        The run's settings.
    """

    extraction: ExtractionResult
    scenario: Any
    gravity_points: tuple[np.ndarray, np.ndarray]
    true_gravity: tuple[float, float]
    grid: dict[str, np.ndarray] | None
    fits: dict[str, FittedModel]
    study: rbfnn_study.StudyResult
    claims: dict[str, bool] = field(default_factory=dict)
    quick: bool = False
    seed: int = 0


def _data(quick: bool, seed: int) -> tuple[ExtractionResult, Any]:
    scenario = preset("paper1", "reduced" if quick else "full")
    result = extract(simulate(scenario, seed=seed), **scenario.extract_options())
    samples = replace(result.samples, source=f"virtual joint paper1/{scenario.size}, seed {seed}")
    return replace(result, samples=samples), scenario


def _gravity_points(result: ExtractionResult) -> tuple[np.ndarray, np.ndarray]:
    """Per operating point: position [rad] and ``tau_g = -(tau+ + tau-)/2`` (eq. 11)."""
    bd = result.by_direction
    tau = bd.friction - bd.load  # the motor torque of each direction: tau_f - tau_g
    if len(bd) != 2 * len(result.samples):
        raise DataError("expected both directions at every operating point")
    tau_minus, tau_plus = tau[0::2], tau[1::2]
    return result.position, -0.5 * (tau_plus + tau_minus)


def _grid(result: ExtractionResult, scenario) -> dict[str, np.ndarray] | None:
    """Samples as a (temperature, velocity, position bin) grid, or None if incomplete."""
    s = result.samples
    d = scenario.design
    nt, nv, nb = d.temperatures.size, d.velocities.size, d.positions.size
    if len(s) != nt * nv * nb:
        return None
    return {
        "friction": s.friction.reshape(nt, nv, nb),
        "load": s.load.reshape(nt, nv, nb).mean(axis=(0, 1)),
        "temperature": d.temperatures,
        "velocity": d.velocities,
    }


def _study_progress(say: Callable[[str], None]) -> Callable[[str], None]:
    """Log the study's own progress lines; its Table 4 and timing stages start steps 6 and 7
    of :data:`STEPS`."""
    pending = [("Table 4", STEPS[5]), ("timing", STEPS[6])]

    def on(message: str) -> None:
        logger.info("RBF study: %s", message)
        if pending and message.startswith(pending[0][0]):
            say(pending.pop(0)[1])

    return on


def _run_study(samples, scenario, *, quick: bool, seed: int, say: Callable[[str], None]):
    cfg = rbfnn_study.study_config(quick, seed=seed, timing_repeats=1)
    true_y = rbfnn_study.true_friction(samples, scenario)
    data = (samples, true_y, rbfnn_study.noise_floor(scenario))
    return rbfnn_study.run_study(cfg, data=data, progress=_study_progress(say))


def _claims(fits: dict[str, FittedModel], res: rbfnn_study.StudyResult) -> dict[str, bool]:
    t3 = res.tables["table3"].set_index("model")
    t4 = res.tables["table4"].set_index("model")
    f10 = res.tables["fig10"].set_index("model")
    rb, bas, vlt = (t3.loc[m] for m in ("RBFNN", "BAS-RBFNN", "VLT model"))
    return {
        "table1_fitness_rises": all(
            fits[a].metrics["fitness"] < fits[b].metrics["fitness"]
            for a, b in itertools.pairwise(TABLE1_MODELS)
        ),
        "table3_order_as_paper": bool(
            bas["all_mean_mNm"] < rb["all_mean_mNm"] < vlt["all_mean_mNm"]
        ),
        "table3_bas_leads_held_out": bool(bas["cv_mean_mNm"] < rb["cv_mean_mNm"]),
        "table4_bas_fewer_epochs": bool(
            float(t4.loc["BAS-RBFNN", "epochs_median"]) < float(t4.loc["GA-RBFNN", "epochs_median"])
        ),
        "fig10_error_grows_beyond_45C": bool(
            float(f10.loc["BAS-RBFNN", "mean_47_55C_mNm"])
            > float(f10.loc["BAS-RBFNN", "mean_at_45C_mNm"])
        ),
    }


def run_bas_rbfnn(
    *, quick: bool = False, seed: int = 0, progress: Callable[[str], None] | None = None
) -> BasRbfnnResult:
    """Compute every table and figure of [B] on the virtual joint.

    Parameters
    ----------
    quick : bool
        The reduced ``paper1`` design (330 samples) and the RBF study's quick settings
        (:func:`~fricid.experiments.rbfnn_study.study_config`), for tests; otherwise the
        paper's full design (21 positions, 15 velocities, 21 temperatures) and the study's
        full settings (with Table 4's variants and the tuning of :mod:`.rbfnn_tuning`).
    seed : int
        Seeds the simulator and every stochastic step.
    progress : callable, optional
        Called with the label of each step of :data:`STEPS` as it starts.

    Returns
    -------
    BasRbfnnResult
    """
    say = progress or (lambda _label: None)
    say(STEPS[0])
    result, scenario = _data(quick, seed)
    samples = result.samples
    say(STEPS[1])
    gravity = _gravity_points(result)
    truth = true_gravity(scenario)
    say(STEPS[2])
    grid = _grid(result, scenario)
    say(STEPS[3])
    fits = {name: fit(samples, name, "lm", seed=seed) for name in TABLE1_MODELS}
    say(STEPS[4])
    res = _run_study(samples, scenario, quick=quick, seed=seed, say=say)
    return BasRbfnnResult(
        result,
        scenario,
        gravity,
        truth,
        grid,
        fits,
        res,
        claims=_claims(fits, res),
        quick=quick,
        seed=seed,
    )
