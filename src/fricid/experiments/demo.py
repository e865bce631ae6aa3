"""The demo: the whole chain on the virtual joint at a reduced size.

Simulate the BAS-RBFNN paper's experiment (``paper1`` preset, reduced design), extract the
friction samples (eq. 9-13), fit the four analytic models (eq. 1-4) and tabulate them as the
paper's Table 1 does (fitness = R^2, RMSE, RMSPE), with the paper's numbers beside ours.
:func:`run_demo` computes; :func:`fricid.report.studies.demo.write_demo` writes the files.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from ..extract import ExtractionResult, extract
from ..fitted import FittedModel
from ..identify import assess_trust, fit
from ..samples import FrictionSamples
from ..sim import preset, simulate, true_gravity

__all__ = ["DEMO_MODELS", "PAPER_TABLE1", "DemoResult", "run_demo"]

#: Models of the demo, in the order of the paper's Table 1 (plus Coulomb-viscous, eq. 1).
DEMO_MODELS = ("coulomb_viscous", "stribeck", "msk", "vlt")

#: The BAS-RBFNN paper's Table 1 ("Velocity", "Velocity-load", "Velocity-temperature-load").
#: Its RMSE has no stated unit (see :func:`.paper_numbers.table1_rmse_unit`); printed as is.
PAPER_TABLE1 = {
    "stribeck": {"fitness": 0.8732, "rmse": 35.25, "rmspe": 0.1792},
    "msk": {"fitness": 0.9418, "rmse": 24.16, "rmspe": 0.1077},
    "vlt": {"fitness": 0.9783, "rmse": 6.103, "rmspe": 0.02312},
}


@dataclass
class DemoResult:
    """What the demo produced: the table, the fitted models, the extraction, the true gravity
    coefficients (eq. 7), timings and the samples the models were fitted to.

    The table's columns: ``model``, ``inputs``, ``parameters``, ``fitness`` (R^2),
    ``rmse_mNm``, ``rmspe_percent`` (RMSPE in percent, as the report shows it),
    ``max_abs_error_mNm``, and the paper's ``paper_fitness``, ``paper_rmse``,
    ``paper_rmspe_percent``.
    """

    table: pd.DataFrame
    models: dict[str, FittedModel]
    extraction: ExtractionResult
    true_gravity: tuple[float, float]
    seconds: dict[str, float]
    samples: FrictionSamples


def run_demo(
    *,
    size: str = "reduced",
    seed: int = 0,
    method: str = "lm",
    progress: Callable[[str], None] | None = None,
) -> DemoResult:
    """Run the chain: simulate, extract, fit :data:`DEMO_MODELS`, tabulate.

    Parameters
    ----------
    size : str
        Preset size of ``paper1`` (``reduced``, ``quick`` or ``full``).
    seed : int
        Seed of the simulation and the fits.
    method : str
        Optimiser of the fits.
    progress : callable, optional
        Called with a line per step.

    Returns
    -------
    DemoResult
    """
    say = progress or (lambda _msg: None)
    scenario = preset("paper1", size)
    seconds: dict[str, float] = {}

    t0 = time.perf_counter()
    say(f"simulating the paper1 preset ({size}): {scenario.design.n_samples():,} raw samples")
    result = extract(simulate(scenario, seed=seed), **scenario.extract_options())
    seconds["simulate+extract"] = time.perf_counter() - t0
    samples = replace(result.samples, source=f"virtual joint paper1/{size}, seed {seed}")

    models: dict[str, FittedModel] = {}
    rows = []
    for name in DEMO_MODELS:
        say(f"fitting {name} ({method})")
        t1 = time.perf_counter()
        fitted = fit(samples, name, method, seed=seed)
        # the verdict `fricid fit` gives, kept in the file: an export reads it
        trust = assess_trust(fitted, samples)
        fitted.trust = trust.to_dict()
        seconds[f"fit {name}"] = time.perf_counter() - t1
        models[name] = fitted
        paper = PAPER_TABLE1.get(name, {})
        rows.append(
            {
                "model": name,
                "inputs": ", ".join(fitted.friction_model().inputs),
                "parameters": len(fitted.params),
                "fitness": fitted.metrics["fitness"],
                "rmse_mNm": 1e3 * fitted.metrics["rmse"],
                "rmspe_percent": 100.0 * fitted.metrics["rmspe"],
                "max_abs_error_mNm": 1e3 * fitted.metrics["max_abs_error"],
                "paper_fitness": paper.get("fitness", np.nan),
                "paper_rmse": paper.get("rmse", np.nan),
                "paper_rmspe_percent": 100.0 * paper.get("rmspe", np.nan),
                "trust": trust.level,
                "heldout_ratio": trust.heldout_ratio,
            }
        )
    table = pd.DataFrame(rows)

    return DemoResult(table, models, result, true_gravity(scenario), seconds, samples)
