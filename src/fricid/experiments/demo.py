"""The demo: the whole chain on the virtual joint at a reduced size.

Simulate the BAS-RBFNN paper's experiment (``paper1`` preset, reduced design), extract the
friction samples (eq. 9-13), fit the four analytic models (eq. 1-4) and tabulate them as the
paper's Table 1 does (fitness = R^2, RMSE, RMSPE), with the paper's numbers beside ours.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd

from ..extract import ExtractionResult, extract
from ..fitted import FittedModel
from ..identify import fit
from ..io import atomic_write, write_samples
from ..sim import preset, simulate, true_gravity

__all__ = ["DEMO_MODELS", "PAPER_TABLE1", "DemoResult", "run_demo"]

#: Models of the demo, in the order of the paper's Table 1 (plus Coulomb-viscous, eq. 1).
DEMO_MODELS = ("coulomb_viscous", "stribeck", "msk", "vlt")

#: The BAS-RBFNN paper's Table 1 ("Velocity", "Velocity-load", "Velocity-temperature-load").
#: Its RMSE has no stated unit and its scale does not match its Table 3 (N m); we print it as is.
PAPER_TABLE1 = {
    "stribeck": {"fitness": 0.8732, "rmse": 35.25, "rmspe": 0.1792},
    "msk": {"fitness": 0.9418, "rmse": 24.16, "rmspe": 0.1077},
    "vlt": {"fitness": 0.9783, "rmse": 6.103, "rmspe": 0.02312},
}


@dataclass
class DemoResult:
    """What the demo produced: the table, the fitted models, the extraction and timings."""

    table: pd.DataFrame
    models: dict[str, FittedModel]
    extraction: ExtractionResult
    true_gravity: tuple[float, float]
    seconds: dict[str, float]
    out: Path


def run_demo(
    out: str | Path = "fricid-demo",
    *,
    size: str = "reduced",
    seed: int = 0,
    method: str = "lm",
    progress: Callable[[str], None] | None = None,
) -> DemoResult:
    """Run the chain and write samples, models and a summary into ``out``."""
    say = progress or (lambda _msg: None)
    out = Path(out)
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
                "rmspe": fitted.metrics["rmspe"],
                "max_abs_error_mNm": 1e3 * fitted.metrics["max_abs_error"],
                "paper_fitness": paper.get("fitness", np.nan),
                "paper_rmse": paper.get("rmse", np.nan),
                "paper_rmspe": paper.get("rmspe", np.nan),
            }
        )
    table = pd.DataFrame(rows)

    out.mkdir(parents=True, exist_ok=True)
    write_samples(samples, out / "samples.csv")
    write_samples(result.by_direction, out / "samples_by_direction.csv")
    for name, fitted in models.items():
        fitted.save(out / f"{name}.json")
    with atomic_write(out / "table1.csv", "w") as fh:
        table.to_csv(fh, index=False)
    truth = true_gravity(scenario)
    with atomic_write(out / "summary.md", "w") as fh:
        fh.write(summary_markdown(table, result, truth, seconds))
    return DemoResult(table, models, result, truth, seconds, out)


def summary_markdown(
    table: pd.DataFrame,
    result: ExtractionResult,
    truth: tuple[float, float],
    seconds: dict[str, float],
) -> str:
    """The demo's summary as Markdown."""
    lines = ["# fricid demo: virtual joint, paper1 preset", "", "## Extraction", ""]
    lines += [f"    {line}" for line in result.summary().splitlines()]
    lines += [
        "",
        f"True gravity coefficients: p_x = {truth[0]:.5g}, p_y = {truth[1]:.5g} N m.",
        "",
        "## Table 1 (BAS-RBFNN paper), ours beside the paper's",
        "",
    ]
    lines.append(
        table.to_markdown(index=False, floatfmt=".4g")
        if _has_tabulate()
        else "```\n" + table.to_string(index=False) + "\n```"
    )
    lines += [
        "",
        "The paper's RMSE has no stated unit and a scale unlike its Table 3 (N m); "
        "compare fitness and RMSPE, and the ordering.",
        "",
        "## Time",
        "",
    ]
    lines += [f"- {k}: {v:.2f} s" for k, v in seconds.items()]
    return "\n".join(lines) + "\n"


def _has_tabulate() -> bool:
    try:
        import tabulate  # noqa: F401
    except ImportError:
        return False
    return True
